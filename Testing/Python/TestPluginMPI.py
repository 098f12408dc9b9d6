"""The plugin under MPI through ParaView's proxies: PluginSummary.py runs with pvbatch on 1 rank
and under mpiexec on several; every run must give exactly the 1-rank surfaces.

  python3 TestPluginMPI.py --pvbatch pvbatch --mpiexec mpiexec --plugin RGMarchingCubes.so \
      --workdir DIR --ranks 2,3
"""

import argparse
import json
import os
import subprocess
import sys


def main():
    parser = argparse.ArgumentParser()
    for name in ("--pvbatch", "--mpiexec", "--plugin", "--workdir"):
        parser.add_argument(name, required=True)
    parser.add_argument("--ranks", default="2,3")
    args = parser.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "PluginSummary.py")
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    version = subprocess.run([args.mpiexec, "--version"], capture_output=True, text=True).stdout
    oversubscribe = ["--oversubscribe"] if "Open MPI" in version or "OpenRTE" in version else []

    summaries = {}
    for ranks in [1] + [int(r) for r in args.ranks.split(",")]:
        output = os.path.join(args.workdir, "summary-%d.json" % ranks)
        command = [args.pvbatch, script, "--plugin", args.plugin, "--output", output]
        if ranks > 1:
            command = [args.mpiexec, "-n", str(ranks)] + oversubscribe + [args.pvbatch, "--mpi"] + command[1:]
        print("+ " + " ".join(command), flush=True)
        result = subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
        print(result.stdout)
        print(result.stderr[-3000:], file=sys.stderr)
        if result.returncode != 0:
            print("FAILED: the run on %d ranks exited with %d" % (ranks, result.returncode), file=sys.stderr)
            return 1
        summaries[ranks] = json.load(open(output))

    failures = 0
    reference = summaries[1]
    for ranks, summary in summaries.items():
        if summary["ranks"] != ranks:
            print("FAILED: pvbatch ran on %d ranks, not %d" % (summary["ranks"], ranks), file=sys.stderr)
            failures += 1
        for run in ("skull", "skull+jaw+vertebra", "largest", "all"):
            ours, theirs = summary[run], reference[run]
            for field in ("triangles", "vertices", "digest", "number_of_triangles_field"):
                if ours[field] != theirs[field]:
                    print("FAILED: %s on %d ranks: %s %s, on 1 rank %s" % (
                        run, ranks, field, ours[field], theirs[field]), file=sys.stderr)
                    failures += 1
            if ours["number_of_triangles_field"] != [theirs["triangles"]] * 2:
                print("FAILED: %s on %d ranks: NumberOfTriangles %s" % (
                    run, ranks, ours["number_of_triangles_field"]), file=sys.stderr)
                failures += 1
            if ranks > 1 and len(ours["ranks_with_triangles"]) < 2:
                print("FAILED: %s on %d ranks: only ranks %s made triangles" % (
                    run, ranks, ours["ranks_with_triangles"]), file=sys.stderr)
                failures += 1
        for run in ("repaired Laplacian", "repaired Windowed Sinc"):
            ours, theirs = summary[run], reference[run]
            if ours != theirs:
                print("FAILED: %s on %d ranks differs from 1 rank: %s vs %s" % (run, ranks, ours, theirs),
                      file=sys.stderr)
                failures += 1
            if ours["Closed"] != 1 or ours["EulerCharacteristic"] != -6:
                print("FAILED: %s on %d ranks: not a closed skull: %s" % (run, ranks, ours), file=sys.stderr)
                failures += 1
            if not (ours["ply_vertices"] == ours["UniquePoints"] == ours["vertices"] == ours["max_gid"] + 1):
                print("FAILED: %s on %d ranks: PLY vertices %d, unique points %d, global ids %d" % (
                    run, ranks, ours["ply_vertices"], ours["UniquePoints"], ours["vertices"]), file=sys.stderr)
                failures += 1
    if failures:
        return 1
    print("TestPluginMPI: runs on %s ranks equal the 1-rank run exactly" % sorted(summaries))
    return 0


sys.exit(main())
