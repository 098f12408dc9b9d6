"""The GUI's case, measured (not a test): how long a new isovalue takes to give the updated seeded
surface in a builtin ParaView session, as when a user drags the Isovalue slider with Auto Apply.

  pvpython Scripts/rgmc_slider.py --plugin PLUGIN [--size 512] [--changes 20]

Makes the CT phantom (CTPhantom, SIZE^3, int16 HU) once, extracts the skull from one seed at
400 HU once (the first run pays for loading), then sets Isovalue to each of CHANGES values
between 300 and 500 HU in turn and times `UpdatePipeline()` on the RGMarchingCubes proxy, the
same for ParaView's Contour for comparison. Prints one JSON object: the median and the range of
the times in seconds, the triangle counts, and how many threads vtkSMPTools had.
"""

import argparse
import json
import os
import statistics
import time

from paraview import simple, servermanager


def timed_changes(proxy, values):
    seconds = []
    for value in values:
        if proxy.GetXMLName() == "Contour":
            proxy.Isosurfaces = [value]
        else:
            proxy.Isovalue = value
        start = time.perf_counter()
        proxy.UpdatePipeline()
        seconds.append(time.perf_counter() - start)
    return seconds


def summary(seconds, proxy):
    data = servermanager.Fetch(proxy)
    return {"median_s": statistics.median(seconds), "min_s": min(seconds),
            "max_s": max(seconds), "last_triangles": data.GetNumberOfCells()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--changes", type=int, default=20)
    args = parser.parse_args()
    simple.LoadPlugin(os.path.abspath(args.plugin), ns=vars(simple))  # 5.13+: no relative path
    phantom = simple.CTPhantom(Dimensions=[args.size] * 3)
    phantom.UpdatePipeline()
    values = [300 + 200.0 * n / max(1, args.changes - 1) for n in range(args.changes)]
    surface = simple.RGMarchingCubes(Input=phantom, ContourBy=["POINTS", "HU"], Isovalue=400,
                                     SeedPoints=[0, 0, 105])
    surface.UpdatePipeline()
    rgmc = summary(timed_changes(surface, values), surface)
    contour = simple.Contour(Input=phantom, ContourBy=["POINTS", "HU"], Isosurfaces=[400],
                             ComputeNormals=1, ComputeScalars=0)
    contour.UpdatePipeline()
    paraview_contour = summary(timed_changes(contour, values), contour)
    from vtkmodules.vtkCommonCore import vtkSMPTools
    print(json.dumps({"size": args.size, "changes": args.changes,
                      "threads": vtkSMPTools.GetEstimatedNumberOfThreads(),
                      "backend": vtkSMPTools.GetBackend(),
                      "rgmc_seeded": rgmc, "paraview_contour": paraview_contour}))


if __name__ == "__main__":
    main()
