"""The evaluation command at a quarter of its sizes (--quick, one repeat): it runs end to end in
one process set and its results hold what the report claims, checked against oracles rather
than timings (no time is judged here):

- on every case and rank count, the seeded surface has exactly the triangles of Contour +
  Connectivity (closest point region), ParaView's way to the same surface;
- the seeded surface on N ranks is the 1-rank surface: Hausdorff distance 0;
- seam repair + windowed sinc equals VTK's windowed sinc of the 1-rank surface (within 1e-5
  voxel); seam repair + Laplacian (Jacobi) stays within what 20 steps of 1% can move a vertex
  of VTK's Laplacian (Gauss-Seidel) of it: 2 x 20 x 0.01 x sqrt(3) voxel;
- the sphere of the sweep has the same triangles in every volume size;
- the report and the plots are written.

  python3 TestEvaluation.py --script rgmc_evaluate.py --binary rgmcEvaluation --workdir DIR
"""

import argparse
import json
import math
import os
import subprocess
import sys


def main():
    parser = argparse.ArgumentParser()
    for name in ("--script", "--binary", "--workdir"):
        parser.add_argument(name, required=True)
    args = parser.parse_args()
    command = [sys.executable, args.script, "--quick", "--repeats", "1", "--sweep-repeats", "1",
               "--binary", args.binary, "--output", args.workdir]
    print("+ " + " ".join(command), flush=True)
    result = subprocess.run(command, capture_output=True, text=True, timeout=1500)
    print(result.stdout[-4000:])
    print(result.stderr[-3000:], file=sys.stderr)
    if result.returncode != 0:
        print("FAILED: the evaluation command failed (status %d)" % result.returncode, file=sys.stderr)
        return 1
    rows = json.load(open(os.path.join(args.workdir, "results.json")))
    failures = []
    timings = [r for r in rows if "method" in r]
    cases = sorted(set(r["case"] for r in timings if not r["case"].startswith("sphere-sweep-")))
    if len(cases) < 4:
        failures.append("only cases %s were measured" % cases)
    for case in cases:
        seeded = {r["ranks"]: r["triangles"] for r in timings if r["case"] == case and r["method"] == "seeded"}
        pipeline = {r["ranks"]: r["triangles"] for r in timings
                    if r["case"] == case and r["method"] == "contour+connectivity"}
        if sorted(seeded) != [1, 2, 4] or seeded != pipeline or len(set(seeded.values())) != 1 or not seeded[1]:
            failures.append("%s: seeded triangles %s, Contour + Connectivity %s" % (case, seeded, pipeline))
        distances = [r for r in rows if r.get("case") == case and "distance" in r]
        if len(distances) != 9:
            failures.append("%s: %d distances, not 9" % (case, len(distances)))
        bound = 2 * 20 * 0.01 * math.sqrt(3)
        for d in distances:
            voxels = d["hausdorff"] / d["spacing"]
            limit = 0.0 if d["distance"].startswith("seeded") else (
                1e-5 if "windowed sinc" in d["distance"] else bound)
            if not 0 <= voxels <= limit:
                failures.append("%s on %d ranks: %s is %g voxel (at most %g)" % (
                    case, d["ranks"], d["distance"], voxels, limit))
    sweep = set(r["triangles"] for r in timings if r["case"].startswith("sphere-sweep-"))
    if len(sweep) != 1:
        failures.append("the sweep's sphere has %s triangles in different volumes" % sorted(sweep))
    for name in ("report.md", "time-vs-volume.png"):
        if not os.path.getsize(os.path.join(args.workdir, name)):
            failures.append("%s is empty" % name)
    for failure in failures:
        print("FAILED: " + failure, file=sys.stderr)
    if failures:
        return 1
    print("TestEvaluation: %d cases on 1, 2 and 4 ranks: seeded = Contour + Connectivity, N ranks = 1 rank, "
          "smoothing as VTK's" % len(cases))
    return 0


sys.exit(main())
