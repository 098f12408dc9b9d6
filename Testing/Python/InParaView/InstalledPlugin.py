"""pvbatch script for TestInstall.py: the installed plugin must have been auto-loaded (from
PV_PLUGIN_PATH or PV_PLUGIN_CONFIG_FILE, no LoadPlugin here) and must work."""

import sys

from paraview import simple

missing = [name for name in ("RGMarchingCubes", "RegionGrowingMarchingCubes", "SeamRepair", "CTPhantom",
                             "DecimateSurface", "RGDecimate")
           if not hasattr(simple, name)]
if missing:
    print("FAILED: not auto-loaded: %s" % ", ".join(missing))
    sys.exit(1)
phantom = simple.CTPhantom(Dimensions=[48, 48, 48])
skull = simple.RGMarchingCubes(Input=phantom, ContourBy=["POINTS", "HU"], Isovalue=400, SeedPoints=[0, 0, 105])
repaired = simple.SeamRepair(Input=skull)
repaired.UpdatePipeline()
triangles = repaired.GetDataInformation().GetNumberOfCells()
decimated = simple.DecimateSurface(Input=repaired, TargetReduction=0.5)
decimated.UpdatePipeline()
kept = decimated.GetDataInformation().GetNumberOfCells()
print("installed plugin: %d triangles, %d decimated" % (triangles, kept))
sys.exit(0 if triangles > 0 and abs(kept - triangles / 2) <= 0.01 * triangles else 1)
