"""pvbatch script (serial or under mpiexec): runs the plugin's filter through its proxy on
ParaView's own decomposition of the CT phantom and writes a summary of the result (gathered on
the first rank) to JSON, so that runs on different rank counts can be compared exactly.

  [mpiexec -n N] pvbatch [--mpi] PluginSummary.py --plugin RGMarchingCubes.so --output s.json
"""

import argparse
import hashlib
import json
import struct

from paraview import servermanager, simple


def summary(polydata):
    """Triangles as sorted vertex-key triples with their component, and each key's coordinates
    and normal (as float bits): hashed, so two runs compare exactly."""
    keys = polydata.GetPointData().GetGlobalIds()
    normals = polydata.GetPointData().GetNormals()
    comps = polydata.GetCellData().GetArray("ComponentId")
    ranks = polydata.GetCellData().GetArray("RankId")
    vertices = {}
    for p in range(polydata.GetNumberOfPoints()):
        bits = struct.pack("<6f", *(polydata.GetPoint(p) + normals.GetTuple3(p)))
        key = keys.GetValue(p)
        if vertices.setdefault(key, bits) != bits:
            raise RuntimeError("vertex %d differs between ranks" % key)
    triangles = []
    for t in range(polydata.GetNumberOfCells()):
        ids = polydata.GetCell(t).GetPointIds()
        triangles.append((tuple(sorted(keys.GetValue(ids.GetId(v)) for v in range(3))), int(comps.GetValue(t))))
    if len(set(tri for tri, _ in triangles)) != len(triangles):
        raise RuntimeError("a triangle appears twice")
    digest = hashlib.sha256()
    for tri, comp in sorted(triangles):
        digest.update(struct.pack("<3qi", *tri, comp))
    for key in sorted(vertices):
        digest.update(struct.pack("<q", key) + vertices[key])
    return {
        "triangles": len(triangles), "vertices": len(vertices), "digest": digest.hexdigest(),
        "ranks_with_triangles": sorted(set(int(ranks.GetValue(t)) for t in range(polydata.GetNumberOfCells()))),
    }


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output", required=True)
    args = parser.parse_args()
    simple.LoadPlugin(args.plugin, ns=globals())
    ranks = servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()

    phantom = CTPhantom(Dimensions=[64, 64, 64])  # noqa: F821 (defined by the plugin)
    results = {"ranks": ranks}
    runs = {
        "skull": dict(SeedPoints=[0, 0, 105]),
        "skull+jaw+vertebra": dict(SeedPoints=[0, 0, 105, 0, 65, -75, 0, -20, -96]),
        "largest": dict(ExtractionMode="Largest Component"),
        "all": dict(ExtractionMode="All Components"),
    }
    for name, properties in runs.items():
        surface = RGMarchingCubes(Input=phantom, ContourBy=["POINTS", "HU"], Isovalue=400,  # noqa: F821
                                  **properties)
        surface.UpdatePipeline()
        # The global count every rank reports, gathered by ParaView's data information (read
        # before Fetch: Fetch's append drops field data).
        data_information = surface.GetDataInformation()  # keep it alive while reading it
        info = data_information.DataInformation.GetFieldDataInformation()
        low, high = info.GetArrayInformation("NumberOfTriangles").GetComponentRange(0)
        results[name] = summary(servermanager.Fetch(surface))
        results[name]["number_of_triangles_field"] = [int(low), int(high)]
        simple.Delete(surface)
    with open(args.output, "w") as out:
        json.dump(results, out, indent=1)
    print("summary written to %s on %d ranks" % (args.output, ranks))


main()
