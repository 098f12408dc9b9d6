"""pvbatch test: loads the built plugin, drives the filter through its proxy as a user's script
does, and checks the numbers fetched from the server against VTK's own filters.

  pvbatch TestPluginPvbatch.py --plugin path/to/RGMarchingCubes.so
"""

import argparse
import math
import os
import sys

from paraview import servermanager, simple
from vtkmodules.vtkCommonDataModel import vtkStaticPointLocator
from vtkmodules.vtkFiltersCore import (vtkCleanPolyData, vtkMarchingCubes,
                                       vtkPolyDataConnectivityFilter)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
from rgmc_testing import check, failures  # noqa: E402


def marching_cubes(image, isovalue):
    mc = vtkMarchingCubes()
    mc.SetInputData(image)
    mc.SetValue(0, isovalue)
    clean = vtkCleanPolyData()  # drops the points of triangles marching cubes dropped
    clean.SetInputConnection(mc.GetOutputPort())
    clean.PointMergingOff()
    clean.Update()
    return clean.GetOutput()


def connectivity(mesh, mode, point=None):
    conn = vtkPolyDataConnectivityFilter()
    conn.SetInputData(mesh)
    if mode == "closest":
        conn.SetExtractionModeToClosestPointRegion()
        conn.SetClosestPoint(*point)
    elif mode == "largest":
        conn.SetExtractionModeToLargestRegion()
    else:
        conn.SetExtractionModeToAllRegions()
    conn.Update()
    return conn


def max_vertex_distance(ours, theirs):
    """The largest distance from one of our vertices to the nearest of theirs."""
    locator = vtkStaticPointLocator()
    locator.SetDataSet(theirs)
    locator.BuildLocator()
    worst = 0.0
    for i in range(ours.GetNumberOfPoints()):
        x = ours.GetPoint(i)
        worst = max(worst, math.dist(x, theirs.GetPoint(locator.FindClosestPoint(x))))
    return worst


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    args = parser.parse_args()
    simple.LoadPlugin(args.plugin, ns=globals())

    phantom = CTPhantom(Dimensions=[80, 80, 80])  # noqa: F821 (defined by the plugin)
    surface = RGMarchingCubes(Input=phantom, ContourBy=["POINTS", "HU"], Isovalue=400,  # noqa: F821
                              SeedPoints=[0, 0, 105])
    surface.UpdatePipeline()
    out = servermanager.Fetch(surface)
    image = servermanager.Fetch(phantom)

    # The skull: vtkMarchingCubes + closest-point connectivity give the same surface.
    mc = marching_cubes(image, 400)
    skull = connectivity(mc, "closest", (0, 0, 105)).GetOutput()
    check(out.GetNumberOfCells() == skull.GetNumberOfCells(),
          "seeded: %d triangles, oracle %d" % (out.GetNumberOfCells(), skull.GetNumberOfCells()))
    check(out.GetNumberOfPoints() == skull.GetNumberOfPoints(),
          "seeded: %d points, oracle %d" % (out.GetNumberOfPoints(), skull.GetNumberOfPoints()))
    # vtkMarchingCubes keeps index-space points in float before applying spacing and origin:
    # its vertices carry float rounding of coordinates near 100 mm (about 1e-5 mm).
    distance = max_vertex_distance(out, skull)
    check(distance < 1e-4, "seeded: a vertex is %g mm from the oracle's nearest" % distance)

    # An isovalue of 0 given at creation stays 0: ParaView resets a property whose value a
    # script sets equal to its XML default to the domain's default (here the middle of the data
    # range) after creation; Isovalue's XML default is a value no one types. Without an
    # Isovalue, the filter starts at the middle of the range, as Contour does.
    default = RGMarchingCubes(Input=phantom, ContourBy=["POINTS", "HU"])  # noqa: F821
    low, high = phantom.PointData["HU"].GetRange()
    check(default.Isovalue == (low + high) / 2, "without Isovalue: %s, not the middle of %s..%s"
          % (default.Isovalue, low, high))
    simple.Delete(default)
    water = RGMarchingCubes(Input=phantom, ContourBy=["POINTS", "HU"], Isovalue=0,  # noqa: F821
                            ExtractionMode="All Components")
    water.UpdatePipeline()
    check(water.Isovalue == 0, "Isovalue=0 at creation reads back %s" % water.Isovalue)
    everything = marching_cubes(image, 0).GetNumberOfCells()
    check(water.GetDataInformation().GetNumberOfCells() == everything,
          "All Components at 0 HU: %d triangles, vtkMarchingCubes %d" % (
              water.GetDataInformation().GetNumberOfCells(), everything))
    simple.Delete(water)

    # Arrays and field data a user reads.
    fd = out.GetFieldData()
    check(fd.GetArray("NumberOfTriangles").GetValue(0) == out.GetNumberOfCells(), "NumberOfTriangles")
    check(fd.GetArray("NumberOfComponents").GetValue(0) == 1, "one component selected")
    seed_point = fd.GetArray("SeedVertexPoints").GetTuple3(0)
    check(math.dist(seed_point, (0, 0, 105)) < 3.0, "the seed vertex %s is near the seed" % (seed_point,))
    normals = out.GetPointData().GetNormals()
    check(normals is not None and normals.GetName() == "Normals", "point normals")
    lengths = [math.sqrt(sum(c * c for c in normals.GetTuple3(i))) for i in range(0, out.GetNumberOfPoints(), 97)]
    check(all(abs(l - 1) < 1e-5 for l in lengths), "unit normals")
    keys = out.GetPointData().GetGlobalIds()
    check(keys is not None and keys.GetName() == "VertexKey", "vertex keys as global ids")
    check(keys.GetNumberOfTuples() == len(set(keys.GetValue(i) for i in range(keys.GetNumberOfTuples()))),
          "vertex keys are unique")
    for name in ("RankId", "ComponentId"):
        array = out.GetCellData().GetArray(name)
        check(array is not None and array.GetRange() == (0.0, 0.0), "%s is 0 on one rank" % name)

    # The two other modes.
    surface.ExtractionMode = "Largest Component"
    surface.UpdatePipeline()
    largest = connectivity(mc, "largest").GetOutput()
    check(servermanager.Fetch(surface).GetNumberOfCells() == largest.GetNumberOfCells(), "largest component")
    surface.ExtractionMode = "All Components"
    surface.UpdatePipeline()
    everything = servermanager.Fetch(surface)
    check(everything.GetNumberOfCells() == mc.GetNumberOfCells(),
          "all components: %d vs %d" % (everything.GetNumberOfCells(), mc.GetNumberOfCells()))
    regions = connectivity(mc, "all").GetNumberOfExtractedRegions()
    check(everything.GetFieldData().GetArray("NumberOfComponents").GetValue(0) == regions,
          "components: VTK finds %d" % regions)
    check(everything.GetCellData().GetArray("ComponentId").GetRange()[1] == regions - 1, "component ids")

    # Several seeds: the union of their surfaces (skull and mandible).
    surface.ExtractionMode = "Seeded"
    surface.SeedPoints = [0, 0, 105, 0, 65, -75]
    surface.UpdatePipeline()
    mandible = connectivity(mc, "closest", (0, 65, -75)).GetOutput()
    both = servermanager.Fetch(surface)
    check(both.GetNumberOfCells() == skull.GetNumberOfCells() + mandible.GetNumberOfCells(), "two seeds")
    check(both.GetFieldData().GetArray("NumberOfComponents").GetValue(0) == 2, "two components")

    # A seed outside the volume: a warning and an empty output, no exception.
    surface.SeedPoints = [0, 0, 1000]
    surface.UpdatePipeline()
    check(servermanager.Fetch(surface).GetNumberOfCells() == 0, "seed outside: empty output")

    # Every property of the proxies is documented.
    documented = 0
    for proxy in (surface, phantom):
        it = proxy.SMProxy.NewPropertyIterator()
        it.Begin()
        while not it.IsAtEnd():
            prop = it.GetProperty()
            if not prop.GetIsInternal() and prop.GetPanelVisibility() != "never":
                doc = prop.GetDocumentation()
                check(doc is not None and len(doc.GetDescription().strip()) > 20,
                      "documentation of %s.%s" % (proxy.GetXMLName(), it.GetKey()))
                documented += 1
            it.Next()
    check(documented >= 10, "documented properties: %d" % documented)

    if failures:
        raise RuntimeError("%d check(s) failed" % len(failures))
    print("TestPluginPvbatch: all checks passed")


main()
