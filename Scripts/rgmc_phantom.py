"""Writes RGMC's synthetic CT head phantom (int16 Hounsfield units) as a VTK image file.

  pvbatch Scripts/rgmc_phantom.py --size 256 --output ct-phantom-256.vti

The phantom is deterministic: the same size, noise and seed give the same file. Useful seeds
(world coordinates, mm): the skull (0, 0, 105); the mandible (0, 65, -75); the lowest vertebra
(0, -20, -96); bone is above about 300 HU, skin at about -300 HU.
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rgmc_common  # noqa: E402


def main(argv):
    parser = argparse.ArgumentParser(prog="pvbatch rgmc_phantom.py", description=__doc__.split("\n")[0])
    parser.add_argument("--size", type=int, default=256, help="samples per axis (default 256)")
    parser.add_argument("--noise", type=float, default=12.0,
                        help="noise standard deviation in HU (default 12)")
    parser.add_argument("--random-seed", type=int, default=1, help="noise seed (default 1)")
    parser.add_argument("--output", required=True, help="the .vti file to write")
    parser.add_argument("--plugin", help="the plugin library (default: found in $RGMC_BUILD_DIR or build/)")
    args = parser.parse_args(argv)
    if args.size < 2:
        parser.error("--size must be at least 2")
    if not args.output.endswith(".vti"):
        parser.error("--output must end in .vti")

    from paraview import simple
    rgmc_common.load_plugin(args.plugin)
    phantom = simple.CTPhantom(Dimensions=[args.size] * 3, NoiseLevel=args.noise,
                               RandomSeed=args.random_seed)
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    # Inline binary: Debian 12's expat cannot read VTK's appended XML data back.
    simple.SaveData(args.output, proxy=phantom, DataMode="Binary")
    print("written: %s (%d^3, int16 HU)" % (args.output, args.size))
    return 0


if __name__ == "__main__":
    rgmc_common.run(main, "rgmc_phantom")
