"""ParaView opens what a program writes: run a scene, read its XDMF with
ParaView's own reader (by absolute path), and check times, topology and fields.

usage: pvpython paraview_opens.py PROGRAM SCENE WORKDIR XDMF_NAME FIELDS [--set ...]...
FIELDS is a comma-separated list of the point and cell arrays expected.
"""
import os
import subprocess
import sys

from paraview.simple import XDMFReader, servermanager

program, scene, workdir, xdmf_name, fields = sys.argv[1:6]
out = os.path.abspath(os.path.join(workdir, "out"))
subprocess.run([program, scene, "--quiet", "-o", out, "--overwrite"] + sys.argv[6:], check=True)
reader = XDMFReader(FileNames=[os.path.join(out, xdmf_name)])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
assert len(times) >= 2 and times[0] == 0.0, times
reader.UpdatePipeline(times[-1])
data = servermanager.Fetch(reader)
points = data.GetPointData()
cells = data.GetCellData()
names = sorted([points.GetArrayName(i) for i in range(points.GetNumberOfArrays())] +
               [cells.GetArrayName(i) for i in range(cells.GetNumberOfArrays())])
assert names == sorted(fields.split(",")), names
assert data.GetNumberOfPoints() > 0 and data.GetNumberOfCells() > 0, "empty grid"
for i in range(points.GetNumberOfArrays()):
    low, high = points.GetArray(i).GetRange(-1)
    assert low == low and high == high, f"NaN in {points.GetArrayName(i)}"
print(f"ParaView read {len(times)} times, {data.GetNumberOfPoints()} points, "
      f"{data.GetNumberOfCells()} cells, fields {names}")
