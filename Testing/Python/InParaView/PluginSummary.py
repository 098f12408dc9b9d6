"""pvbatch script (serial or under mpiexec), or pvpython client of a pvserver: runs the plugin's
filters through their proxies on ParaView's own decomposition of the CT phantom and writes a
summary of the results (gathered on the first rank, or fetched to the client) to JSON, so that
runs on different rank counts, and in client-server mode, can be compared exactly.

  [mpiexec -n N] pvbatch [--mpi] PluginSummary.py --plugin RGMarchingCubes.so --output s.json
  pvpython PluginSummary.py --connect HOST:PORT --plugin RGMarchingCubes.so --output s.json
"""

import argparse
import hashlib
import json
import os
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


def repaired_summary(polydata):
    """The repaired mesh by global point id: positions and normals (float bits), triangles as
    sorted id triples; copies of a vertex must agree, and exactly one must be its owner."""
    ids = polydata.GetPointData().GetArray("GlobalPointIds")
    ghosts = polydata.GetPointData().GetArray("vtkGhostType")
    normals = polydata.GetPointData().GetNormals()
    vertices, owners = {}, {}
    for p in range(polydata.GetNumberOfPoints()):
        bits = struct.pack("<6f", *(polydata.GetPoint(p) + normals.GetTuple3(p)))
        gid = ids.GetValue(p)
        if vertices.setdefault(gid, bits) != bits:
            raise RuntimeError("the copies of vertex %d differ" % gid)
        owners[gid] = owners.get(gid, 0) + (ghosts.GetValue(p) == 0)
    if any(count != 1 for count in owners.values()):
        raise RuntimeError("a vertex has not exactly one owner")
    triangles = sorted(tuple(sorted(ids.GetValue(polydata.GetCell(t).GetPointId(v)) for v in range(3)))
                       for t in range(polydata.GetNumberOfCells()))
    digest = hashlib.sha256()
    for gid in sorted(vertices):
        digest.update(struct.pack("<q", gid) + vertices[gid])
    for tri in triangles:
        digest.update(struct.pack("<3q", *tri))
    return {"vertices": len(vertices), "max_gid": max(vertices), "triangles": len(triangles),
            "digest": digest.hexdigest()}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--output", required=True)
    parser.add_argument("--connect", help="HOST:PORT of a pvserver to run on")
    args = parser.parse_args()
    if args.connect:
        host, port = args.connect.rsplit(":", 1)
        if simple.Connect(host, int(port)) is None:
            raise RuntimeError("cannot connect to %s" % args.connect)
        # On the client (its GUI parts, if any) and on the server (the filters).
        simple.LoadPlugin(args.plugin, remote=False, ns=globals())
        simple.LoadPlugin(args.plugin, remote=True, ns=globals())
        ranks = servermanager.ActiveConnection.GetNumberOfDataPartitions()
    else:
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
    # Seam repair and smoothing through the proxies, and the merged writer.
    skull = RGMarchingCubes(Input=phantom, ContourBy=["POINTS", "HU"], Isovalue=400,  # noqa: F821
                            SeedPoints=[0, 0, 105])
    for method in ("Laplacian", "Windowed Sinc"):
        repaired = RGSeamRepair(Input=skull, SmoothingMethod=method)  # noqa: F821
        repaired.UpdatePipeline()
        data_information = repaired.GetDataInformation()  # keep it alive while reading it
        info = data_information.DataInformation.GetFieldDataInformation()
        checks = {name: int(info.GetArrayInformation(name).GetComponentRange(0)[0])
                  for name in ("UniquePoints", "Closed", "EulerCharacteristic")}
        summary_ = repaired_summary(servermanager.Fetch(repaired))
        summary_.update(checks)
        ply = os.path.splitext(args.output)[0] + "-" + method.replace(" ", "") + ".ply"
        simple.SaveData(ply, proxy=repaired)
        with open(ply, "rb") as f:
            summary_["ply_vertices"] = next(int(l.split()[2]) for l in f if l.startswith(b"element vertex"))
        results["repaired " + method] = summary_
    with open(args.output, "w") as out:
        json.dump(results, out, indent=1)
    print("summary written to %s on %d ranks%s" % (args.output, ranks, " of a pvserver" if args.connect else ""))


main()
