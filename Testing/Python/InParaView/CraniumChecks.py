"""Run by TestCranium.py with pvbatch under mpiexec: the real head CT (InVesalius's Cranium.inv3
written as a DICOM series) read by the plugin's DICOM reader on every rank, then

- the skull seeded at the top of the head at 299.5 HU, against vtkMarchingCubes + closest-point
  connectivity of the whole volume (on rank 0), and the head holder's two pieces (the other
  components that span most of the scan's height) against it;
- Seam Repair's measures of the seeded skull;
- All Components at InVesalius's threshold (225.5: voxels of 226 HU and more inside), with
  Seam Repair's 20 Laplacian iterations, against InVesalius's own bone surface: the distances
  both ways (vtkDistancePolyDataFilter) and the volumes.

Prints the results as JSON (and writes them to --out).

  mpiexec -n 2 pvbatch --mpi CraniumChecks.py --plugin P --scripts Scripts/ --project Cranium.inv3 \
      --series DIR [--invesalius-vtp V] --out J
"""

import argparse
import json
import sys

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkStaticPointLocator
from vtkmodules.vtkFiltersCore import (vtkMarchingCubes, vtkPolyDataConnectivityFilter,
                                       vtkTriangleFilter)
from vtkmodules.vtkFiltersGeneral import vtkDistancePolyDataFilter
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

SEED = (126.3, 103.4, 155.8)  # the top of the skull (mm)
BONE = 299.5
INVESALIUS_THRESHOLD = 225.5
MEASURES = ["SurfaceArea", "EnclosedVolume", "BorderCapArea", "SurfaceAreaBeforeSmoothing",
            "EnclosedVolumeBeforeSmoothing"]


def field(data, name):
    return data.GetFieldData().GetArray(name).GetValue(0)


def nearest_distances(points, surface):
    """Distance from each of `points` (n x 3) to the nearest vertex of `surface`."""
    locator = vtkStaticPointLocator()
    locator.SetDataSet(surface)
    locator.BuildLocator()
    vertices = vtk_to_numpy(surface.GetPoints().GetData()).astype(np.float64)
    return np.array([np.linalg.norm(vertices[locator.FindClosestPoint(p)] - p) for p in points])


def distances(ours, theirs):
    """Point-to-surface distances of each surface's vertices to the other."""
    d = vtkDistancePolyDataFilter()
    d.SetInputData(0, ours)
    d.SetInputData(1, theirs)
    d.SignedDistanceOff()
    d.ComputeSecondDistanceOn()
    d.Update()
    a = vtk_to_numpy(d.GetOutput().GetPointData().GetArray("Distance"))
    b = vtk_to_numpy(d.GetSecondDistanceOutput().GetPointData().GetArray("Distance"))
    both = np.concatenate([a, b])
    return {"mean": float(both.mean()), "hausdorff": float(both.max()),
            "p99": float(np.percentile(both, 99)),
            "ours_to_theirs_mean": float(a.mean()), "theirs_to_ours_mean": float(b.mean()),
            "over_1mm": float((both > 1.0).mean())}


def invesalius_surface(path):
    """InVesalius's surface as triangles, in the volume's coordinates (y flipped back)."""
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(path)
    triangles = vtkTriangleFilter()
    triangles.SetInputConnection(reader.GetOutputPort())
    triangles.Update()
    surface = triangles.GetOutput()
    xyz = vtk_to_numpy(surface.GetPoints().GetData()).astype(np.float64)
    xyz[:, 1] = -xyz[:, 1]
    points = vtkPoints()
    points.SetData(numpy_to_vtk(xyz, deep=1))
    surface.SetPoints(points)
    return surface


def main():
    parser = argparse.ArgumentParser()
    for name in ("--plugin", "--scripts", "--project", "--series", "--out"):
        parser.add_argument(name, required=True)
    parser.add_argument("--invesalius-vtp", help="also compare with this InVesalius surface")
    args = parser.parse_args()
    simple.LoadPlugin(args.plugin, ns=vars(simple))
    ranks = servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()
    result = {"ranks": ranks}
    reader = simple.OpenDataFile(args.series)
    # The oracle's volume straight from the project (not through the series and its reader).
    sys.path.insert(0, args.scripts)
    import rgmc_inv3
    project = rgmc_inv3.Project(args.project)
    image = vtkImageData()
    nz, ny, nx = project.shape
    image.SetDimensions(nx, ny, nz)
    image.SetSpacing(*project.spacing)
    values = numpy_to_vtk(project.volume().ravel(), deep=1)
    values.SetName("HU")
    image.GetPointData().SetScalars(values)

    # The seeded skull against vtkMarchingCubes + closest-point connectivity.
    skull = simple.RGMarchingCubes(Input=reader, ContourBy=["POINTS", "HU"], Isovalue=BONE,
                                   SeedPoints=list(SEED))
    ours = servermanager.Fetch(skull)
    mc = vtkMarchingCubes()
    mc.SetInputData(image)
    mc.SetValue(0, BONE)
    mc.ComputeNormalsOff()
    regions = vtkPolyDataConnectivityFilter()
    regions.SetInputConnection(mc.GetOutputPort())
    regions.SetExtractionModeToClosestPointRegion()
    regions.SetClosestPoint(*SEED)
    regions.Update()
    oracle = regions.GetOutput()
    result["seeded"] = {"triangles": ours.GetNumberOfCells(), "points": ours.GetNumberOfPoints(),
                        "oracle_triangles": oracle.GetNumberOfCells(),
                        "oracle_points": oracle.GetNumberOfPoints()}
    ours_xyz = vtk_to_numpy(ours.GetPoints().GetData()).astype(np.float64)
    result["seeded"]["largest_vertex_distance"] = float(
        nearest_distances(ours_xyz, oracle).max()) if len(ours_xyz) else None

    # The head holder: the components other than the skull spanning most of the scan's height.
    every = vtkPolyDataConnectivityFilter()
    every.SetInputConnection(mc.GetOutputPort())
    every.SetExtractionModeToAllRegions()
    every.ColorRegionsOn()
    every.Update()
    labelled = every.GetOutput()
    region = vtk_to_numpy(labelled.GetPointData().GetArray("RegionId"))
    xyz = vtk_to_numpy(labelled.GetPoints().GetData()).astype(np.float64)
    bounds = image.GetBounds()
    seeded_region = region[np.argmin(np.linalg.norm(xyz - np.array(SEED), axis=1))]
    holder = []
    for r in range(every.GetNumberOfExtractedRegions()):
        piece = xyz[region == r]
        if r == seeded_region:
            continue
        if len(piece) and np.ptp(piece[:, 2]) > 0.6 * (bounds[5] - bounds[4]):
            gap = nearest_distances(piece[::10], ours).min()
            holder.append({"points": int(len(piece)), "bounds": piece.min(0).tolist() +
                           piece.max(0).tolist(), "distance_to_seeded": float(gap)})
    result["holder"] = holder

    # The seeded skull's measures, smoothed as the pipeline does.
    repair = simple.RGSeamRepair(Input=skull)
    repaired = servermanager.Fetch(repair)
    result["seeded"]["measures"] = {name: field(repaired, name) for name in MEASURES}
    # The real skull decimated to a tenth (cut by the scan's lowest slice: open there).
    decimated = servermanager.Fetch(simple.RGDecimate(Input=repair, TargetReduction=0.9))
    names = ("Triangles", "TrianglesBeforeDecimation", "BoundaryEdges", "VolumeBorderEdges",
             "NonManifoldEdges", "EulerCharacteristic", "SurfaceArea", "EnclosedVolume")
    result["seeded"]["decimated"] = {name: field(decimated, name) for name in names}
    result["seeded"]["decimated"]["input"] = {
        name: field(repaired, name) for name in ("Triangles", "VolumeBorderEdges", "EulerCharacteristic")}

    if not args.invesalius_vtp:
        write(result, args.out)
        return
    # Against InVesalius's bone surface, at its threshold.
    bone = simple.RGMarchingCubes(Input=reader, ContourBy=["POINTS", "HU"],
                                  Isovalue=INVESALIUS_THRESHOLD, ExtractionMode="All Components")
    smoothed = servermanager.Fetch(simple.RGSeamRepair(Input=bone))
    result["invesalius"] = {name: field(smoothed, name) for name in MEASURES}
    result["invesalius"]["distances"] = distances(smoothed, invesalius_surface(args.invesalius_vtp))
    result["invesalius"]["closed"] = field(smoothed, "Closed")

    write(result, args.out)


def write(result, path):
    with open(path, "w") as out:
        json.dump(result, out, indent=2)
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
