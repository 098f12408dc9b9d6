"""pvbatch script (serial or under mpiexec): the CT phantom's skull through Region-Growing
Marching Cubes and Seam Repair, written with the Merged Surface Writer as binary PLY files
(vertices in global-id order): the mesh before smoothing, and after Laplacian smoothing, with
single and double precision points. TestLaplacianOracle.py smooths the first with its own
Jacobi Laplacian and compares.

  [mpiexec -n N] pvbatch [--mpi] LaplacianMeshes.py --plugin RGMarchingCubes.so --prefix P \
      --iterations 20 --relaxation 0.1
"""

import argparse

from paraview import simple


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--prefix", required=True)
    parser.add_argument("--iterations", type=int, default=20)
    parser.add_argument("--relaxation", type=float, default=0.1)
    args = parser.parse_args()
    simple.LoadPlugin(args.plugin, ns=globals())
    # 96^3 over 150 mm, narrower than the head: the bones are cut by the volume's border, so the
    # mesh has boundary edges (two-neighbour and fixed vertices) besides closed parts, and the
    # seams of up to 4 ranks cross it.
    phantom = CTPhantom(Dimensions=[96, 96, 96], FieldOfView=150)  # noqa: F821 (defined by the plugin)
    phantom.UpdatePipeline()
    bounds = phantom.GetDataInformation().GetBounds()
    with open(args.prefix + "-spacing.txt", "w") as out:
        out.write("%.17g\n" % ((bounds[1] - bounds[0]) / 95.0))
    for precision in ("Single", "Double"):
        skull = RGMarchingCubes(Input=phantom, ContourBy=["POINTS", "HU"], Isovalue=400,  # noqa: F821
                                ExtractionMode="All Components", OutputPointsPrecision=precision)
        for method, name in (("None", "input"), ("Laplacian", "smoothed")):
            repaired = RGSeamRepair(Input=skull, SmoothingMethod=method,  # noqa: F821
                                    NumberOfIterations=args.iterations,
                                    RelaxationFactor=args.relaxation)
            simple.SaveData("%s-%s-%s.ply" % (args.prefix, precision.lower(), name), proxy=repaired)
            simple.Delete(repaired)
        simple.Delete(skull)


main()
