"""A fingerprint of every output the filters make, to prove a refactoring changed none of them.

Run with pvbatch --symmetric, on any number of ranks; each rank writes DIR/fingerprint.R-of-N.txt,
one line per output with the SHA-256 of its piece (points, cells, every point, cell and field
array, in order), rank 0 also the SHA-256 of each file the Merged Surface Writer wrote:

  mpiexec -n 3 pvbatch --symmetric Scripts/rgmc_fingerprint.py --plugin PLUGIN --out DIR
  sort DIR/fingerprint.*-of-3.txt

Compare those lines of two builds for the same rank count: equal lines, equal outputs. Covers the three extraction modes, Seam Repair without smoothing, with Laplacian and
windowed sinc smoothing, on vertex keys and on exact coordinates (ParaView's Contour), in float
and double points, and the writer's STL, PLY and VTP.
"""

import argparse
import hashlib
import os

from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy


def digest_array(h, array):
    if array is None:
        h.update(b"none")
        return
    h.update(("%s:%d:%d:%d" % (array.GetName(), array.GetDataType(), array.GetNumberOfTuples(),
                                array.GetNumberOfComponents())).encode())
    if array.GetNumberOfTuples() and array.IsNumeric():
        h.update(vtk_to_numpy(array).tobytes())


def digest_polydata(data, ignore=()):
    h = hashlib.sha256()
    points = data.GetPoints()
    digest_array(h, points.GetData() if points else None)
    polys = data.GetPolys()
    h.update(b"polys:%d" % data.GetNumberOfPolys())
    if data.GetNumberOfPolys():
        digest_array(h, polys.GetOffsetsArray())
        digest_array(h, polys.GetConnectivityArray())
    for attributes in (data.GetPointData(), data.GetCellData(), data.GetFieldData()):
        for i in range(attributes.GetNumberOfArrays()):
            if attributes.GetAbstractArray(i).GetName() not in ignore:
                digest_array(h, attributes.GetAbstractArray(i))
    return h.hexdigest()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--size", type=int, default=96)
    parser.add_argument("--ignore", default="",
                        help="comma-separated arrays left out of the digests (to compare with a "
                        "build that did not make them)")
    args = parser.parse_args()
    simple.LoadPlugin(os.path.abspath(args.plugin), ns=vars(simple))  # 5.13+: no relative path
    controller = servermanager.vtkProcessModule.GetProcessModule().GetGlobalController()
    rank, ranks = controller.GetLocalProcessId(), controller.GetNumberOfProcesses()
    os.makedirs(args.out, exist_ok=True)

    phantom = simple.CTPhantom(Dimensions=[args.size] * 3)
    lines = []

    def record(name, proxy):
        proxy.UpdatePipeline()
        data = proxy.GetClientSideObject().GetOutputDataObject(0)
        lines.append("%s rank %d of %d: %d points %d triangles %s" % (
            name, rank, ranks, data.GetNumberOfPoints(), data.GetNumberOfPolys(),
            digest_polydata(data, args.ignore.split(","))))

    surfaces = {}
    for mode in ("Seeded", "Largest Component", "All Components"):
        for points in ("Float", "Double"):
            surface = simple.RGMarchingCubes(
                Input=phantom, ContourBy=["POINTS", "HU"], Isovalue=400,
                SeedPoints=[0, 0, 105], ExtractionMode=mode)
            if points == "Double":
                surface.OutputPointsPrecision = "Double"
            record("extract %s %s" % (mode, points), surface)
            surfaces[(mode, points)] = surface
    contour = simple.Contour(Input=phantom, ContourBy=["POINTS", "HU"],
                             Isosurfaces=[400])
    record("contour", contour)
    inputs = dict(surfaces)
    inputs[("contour", "Float")] = contour
    # Points repeated within a rank's piece: the merging path.
    inputs[("appended", "Float")] = simple.AppendGeometry(Input=[contour, surfaces[("Seeded", "Float")]])
    repaired = None
    for (mode, points), surface in sorted(inputs.items()):
        for smoothing in ("None", "Laplacian", "Windowed Sinc"):
            if mode == "Largest Component" or (points == "Double" and smoothing == "None"):
                continue
            repair = simple.RGSeamRepair(Input=surface, SmoothingMethod=smoothing,
                                         NumberOfIterations=20)
            record("repair %s %s %s" % (mode, points, smoothing), repair)
            if (mode, points, smoothing) == ("Seeded", "Float", "Laplacian"):
                repaired = repair
    for extension in ("stl", "ply", "vtp"):
        path = os.path.join(args.out, "seeded-%d.%s" % (ranks, extension))
        simple.SaveData(path, proxy=repaired, FileType="Binary")
        controller.Barrier()
        if rank == 0:
            with open(path, "rb") as f:
                lines.append("file %s: %s" % (extension, hashlib.sha256(f.read()).hexdigest()))
    # One file per rank (the ranks' standard outputs interleave), and the lines on stdout.
    with open(os.path.join(args.out, "fingerprint.%d-of-%d.txt" % (rank, ranks)), "w") as f:
        f.write("".join(line + "\n" for line in lines))


if __name__ == "__main__":
    main()
