"""ParaView opens what a program writes: run a scene, read its XDMF with
ParaView's own reader (by absolute path), and check times, topology and fields.
With --hexahedra VOLUME every cell must be a hexahedron whose corners VTK
reads in its own order (a positive Jacobian at every corner: a mirrored or
scrambled order gives a negative or twisted one) and the cells must fill
VOLUME [m3].

With --odd-path the scene runs from a copy in a folder whose name holds the
bytes 0xff and 0x01, which the index must not carry raw (before: not XML,
and ParaView read no points).

usage: pvpython paraview_opens.py PROGRAM SCENE WORKDIR XDMF_NAME FIELDS [--hexahedra VOLUME] [--odd-path]
                                  [--set ...]...
FIELDS is a comma-separated list of the point and cell arrays expected.
"""
import math
import os
import shutil
import subprocess
import sys

from paraview.simple import CellSize, MeshQuality, XDMFReader, servermanager

VTK_HEXAHEDRON = 12

program, scene, workdir, xdmf_name, fields = sys.argv[1:6]
rest = sys.argv[6:]
volume = None
if rest[:1] == ["--hexahedra"]:
    volume = float(rest[1])
    rest = rest[2:]
if rest[:1] == ["--odd-path"]:
    rest = rest[1:]
    odd = os.path.join(os.fsencode(os.path.abspath(workdir)), b"sc\xff\x01ene")
    shutil.rmtree(odd, ignore_errors=True)
    os.makedirs(odd)
    shutil.copy(os.fsencode(scene), odd)
    scene = os.path.join(odd, os.fsencode(os.path.basename(scene)))
out = os.path.abspath(os.path.join(workdir, "out"))
shutil.rmtree(out, ignore_errors=True)
subprocess.run([program, scene, "--quiet", "-o", out] + rest, check=True)
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
if volume is not None:
    types = {data.GetCellType(i) for i in range(data.GetNumberOfCells())}
    assert types == {VTK_HEXAHEDRON}, f"cell types {types}, expected hexahedra ({VTK_HEXAHEDRON}) only"
    quality = MeshQuality(Input=reader)
    quality.HexQualityMeasure = "Jacobian"
    jacobians = servermanager.Fetch(quality).GetCellData().GetArray("Quality").GetRange()
    sizes = servermanager.Fetch(CellSize(Input=reader)).GetCellData().GetArray("Volume")
    total = math.fsum(sizes.GetValue(i) for i in range(sizes.GetNumberOfTuples()))
    print(f"  hexahedra only; smallest corner Jacobian {jacobians[0]:.4g}; cells fill {total:.12g} m3 "
          f"(expected {volume:g})")
    assert jacobians[0] > 0, f"a hexahedron VTK reads inside out (corner Jacobian {jacobians[0]})"
    assert abs(total - volume) <= 1e-9 * volume, f"the cells fill {total} m3, expected {volume}"
