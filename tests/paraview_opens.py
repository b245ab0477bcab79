"""ParaView opens what seepage-fe writes: run a scene, read its XDMF with
ParaView's own reader (by absolute path), and check times, mesh and fields.

usage: pvpython paraview_opens.py SEEPAGE_FE SCENE WORKDIR
"""
import os
import subprocess
import sys

from paraview.simple import XDMFReader, servermanager

program, scene, workdir = sys.argv[1:4]
out = os.path.abspath(os.path.join(workdir, "out"))
subprocess.run([program, scene, "--quiet", "-o", out,
                "--set", 'scene.end_time="3 d"', "--set", 'output.interval="1 d"'],
               check=True)
reader = XDMFReader(FileNames=[os.path.join(out, "seepage.xdmf")])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
assert times == [0.0, 86400.0, 172800.0, 259200.0], times
reader.UpdatePipeline(times[-1])
data = servermanager.Fetch(reader)
points = data.GetPointData()
cells = data.GetCellData()
names = sorted([points.GetArrayName(i) for i in range(points.GetNumberOfArrays())] +
               [cells.GetArrayName(i) for i in range(cells.GetNumberOfArrays())])
assert names == ["P", "flux", "lambda", "p", "region"], names
assert data.GetNumberOfCells() > 0
low, high = points.GetArray("p").GetRange()
assert abs(low - 1e5) < 1 and 1e5 < high <= 3e6 * (1 + 1e-12), (low, high)
assert cells.GetArray("flux").GetNumberOfComponents() == 3
print(f"ParaView read {len(times)} times, {data.GetNumberOfPoints()} points, "
      f"{data.GetNumberOfCells()} cells, fields {names}, p in [{low:.4g}, {high:.4g}] Pa")
