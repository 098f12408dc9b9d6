"""The plugin under MPI through ParaView's proxies: PluginSummary.py runs with pvbatch on 1 rank
and under mpiexec on several; every run must give exactly the 1-rank surfaces.

  python3 TestPluginMPI.py --pvbatch pvbatch --mpiexec mpiexec --plugin RGMarchingCubes.so \
      --workdir DIR --ranks 2,3
"""

import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
import SummaryCompare  # noqa: E402
import rgmc_testing  # noqa: E402


def main():
    args = rgmc_testing.mpi_driver_arguments("2,3")
    script = rgmc_testing.in_paraview("PluginSummary.py")
    env = rgmc_testing.mpi_environment()

    summaries = {}
    for ranks in [1] + [int(r) for r in args.ranks.split(",")]:
        output = os.path.join(args.workdir, "summary-%d.json" % ranks)
        command = [args.pvbatch, script, "--plugin", args.plugin, "--output", output]
        if ranks > 1:
            command = (rgmc_testing.mpiexec_command(args.mpiexec, ranks) + [args.pvbatch, "--mpi"] +
                       command[1:])
        print("+ " + " ".join(command), flush=True)
        result = subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
        print(result.stdout)
        print(result.stderr[-3000:], file=sys.stderr)
        if result.returncode != 0:
            print("FAILED: the run on %d ranks exited with %d" % (ranks, result.returncode), file=sys.stderr)
            return 1
        summaries[ranks] = json.load(open(output))

    failures = []
    for ranks, summary in summaries.items():
        failures += SummaryCompare.compare(summary, summaries[1], ranks, "pvbatch on %d ranks" % ranks)
    for failure in failures:
        print("FAILED: " + failure, file=sys.stderr)
    if failures:
        return 1
    print("TestPluginMPI: runs on %s ranks equal the 1-rank run exactly" % sorted(summaries))
    return 0


sys.exit(main())
