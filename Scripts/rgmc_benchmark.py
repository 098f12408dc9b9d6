"""RGMC's benchmark (not a test): times seeded region-growing marching cubes against
vtkFlyingEdges3D, vtkMarchingCubes and ParaView's Contour, on 1 and more MPI ranks, and writes
a Markdown report.

  python3 Scripts/rgmc_benchmark.py --size 512 --ranks 1,2 --repeats 5

Fields: the CT phantom (the skull from one seed, isovalue 400 HU) and a field with one small
sphere in empty space. On the phantom, the seam repair filter with 20 Laplacian iterations is
timed against ParaView's Smooth (vtkSmoothPolyDataFilter, 20 iterations) on the same pieces. Every time is the slowest rank's, the min and median of --repeats runs
of the build's rgmcBenchmark program (each rank makes its piece of the volume once; the times
do not include it).
"""

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rgmc_common  # noqa: E402

METHODS = {
    "phantom": ["seeded", "fe", "mc", "contour", "all", "repair", "smooth"],
    "sphere": ["seeded", "fe", "contour"],
}
NAMES = {
    "seeded": "Seeded RGMC (ours)", "all": "All components (ours)", "fe": "vtkFlyingEdges3D",
    "mc": "vtkMarchingCubes", "contour": "ParaView Contour",
    "repair": "Seam Repair + 20 Laplacian (ours)", "smooth": "ParaView Smooth, 20 it. (per piece)",
}


def machine():
    cpu = "unknown CPU"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    memory = ""
    try:
        kib = int(open("/proc/meminfo").readline().split()[1])
        memory = ", %.0f GiB" % (kib / 1024 / 1024)
    except (OSError, ValueError, IndexError):
        pass
    return "%s, %d cores%s, %s" % (cpu, os.cpu_count(), memory, platform.platform())


def run(binary, field, size, ranks, repeats, methods):
    command = [binary, "--field", field, "--size", str(size), "--repeats", str(repeats),
               "--methods", ",".join(methods)]
    if ranks > 1:
        command = rgmc_common.mpiexec_command(ranks) + command
    print("+ " + " ".join(command), flush=True)
    result = subprocess.run(command, capture_output=True, text=True, env=rgmc_common.mpi_environment())
    if result.returncode != 0:
        raise rgmc_common.UsageError("the benchmark run failed:\n" + result.stderr[-2000:])
    rows = [json.loads(line) for line in result.stdout.splitlines() if line.startswith("{")]
    for row in rows:
        print("  %-22s %8.4f s (median %8.4f)  %9d triangles" % (
            NAMES[row["method"]], row["min_seconds"], row["median_seconds"], row["triangles"]))
    return rows


def find(rows, field, ranks, method):
    for row in rows:
        if row["field"] == field and row["ranks"] == ranks and row["method"] == method:
            return row
    return None


def report(rows, args):
    lines = ["# RGMC benchmark", "",
             "Machine: %s. Date: %s. Size %d^3, %d repeats; times are the slowest rank's, "
             "min (median) in seconds. %s" % (
                 machine(), datetime.date.today().isoformat(), args.size, args.repeats,
                 "Ranks above the core count are oversubscribed." if max(args.ranks) > (os.cpu_count() or 1) else ""),
             ""]
    for field in args.fields:
        lines += ["## %s" % ("CT phantom, skull from one seed (400 HU)" if field == "phantom"
                             else "One small sphere in empty space"), "",
                  "| method | " + " | ".join("%d rank%s" % (r, "s" if r > 1 else "") for r in args.ranks) +
                  " | triangles |",
                  "|---|" + "---|" * len(args.ranks) + "---|"]
        for method in METHODS[field]:
            cells, triangles = [], ""
            for ranks in args.ranks:
                row = find(rows, field, ranks, method)
                cells.append("%.4f (%.4f)" % (row["min_seconds"], row["median_seconds"]) if row else "-")
                triangles = triangles or (str(row["triangles"]) if row else "")
            lines.append("| %s | %s | %s |" % (NAMES[method], " | ".join(cells), triangles))
        lines.append("")
        for ranks in args.ranks:
            seeded = find(rows, field, ranks, "seeded")
            if not seeded:
                continue
            parts = []
            for other in ("fe", "contour"):
                row = find(rows, field, ranks, other)
                if row:
                    parts.append("%.3fx %s" % (seeded["min_seconds"] / row["min_seconds"], NAMES[other]))
            share = seeded["busiest_rank_triangles"] / max(1, seeded["triangles"])
            lines.append("- %d rank%s: seeded = %s; the busiest rank makes %.0f%% of the triangles "
                         "(an even split: %.0f%%)." % (ranks, "s" if ranks > 1 else "", ", ".join(parts),
                                                        100 * share, 100.0 / ranks))
        for ranks in args.ranks:
            repair, smooth = find(rows, field, ranks, "repair"), find(rows, field, ranks, "smooth")
            if repair and smooth:
                lines.append("- %d rank%s: Seam Repair with smoothing takes %.2fx the time of ParaView's "
                             "Smooth, which smooths each piece alone and leaves the seams open." % (
                                 ranks, "s" if ranks > 1 else "", repair["min_seconds"] / smooth["min_seconds"]))
        one = find(rows, field, 1, "seeded")
        for ranks in args.ranks[1:]:
            many = find(rows, field, ranks, "seeded")
            if one and many:
                share = many["busiest_rank_triangles"] / max(1, many["triangles"])
                lines.append("- Seeded speedup at %d ranks: %.2f (the busiest rank's share of the "
                             "surface bounds it at about %.2f)." % (
                                 ranks, one["min_seconds"] / many["min_seconds"], 1 / share))
        lines.append("")
    return "\n".join(lines) + "\n"


def main(argv):
    parser = argparse.ArgumentParser(prog="rgmc_benchmark.py", description=__doc__.split("\n")[0])
    parser.add_argument("--size", type=int, default=512, help="volume size N (N^3), default 512")
    parser.add_argument("--ranks", default="1,2", help="rank counts, default 1,2")
    parser.add_argument("--repeats", type=int, default=5, help="runs per method, default 5")
    parser.add_argument("--fields", default="phantom,sphere", help="phantom,sphere")
    parser.add_argument("--binary", default=os.path.join(rgmc_common.ROOT, "build", "bin", "rgmcBenchmark"))
    parser.add_argument("--output", default=os.path.join(rgmc_common.ROOT, "build", "benchmark"),
                        help="folder for report.md and results.json")
    args = parser.parse_args(argv)
    args.ranks = [int(r) for r in args.ranks.split(",")]
    args.fields = args.fields.split(",")
    if not os.path.isfile(args.binary):
        raise rgmc_common.UsageError("no benchmark program at %s: build first (./rgmc build)" % args.binary)
    rows = []
    for field in args.fields:
        for ranks in args.ranks:
            methods = [m for m in METHODS[field] if not (m == "mc" and ranks > 1)]
            rows += run(args.binary, field, args.size, ranks, args.repeats, methods)
    os.makedirs(args.output, exist_ok=True)
    text = report(rows, args)
    with open(os.path.join(args.output, "report.md"), "w") as out:
        out.write(text)
    with open(os.path.join(args.output, "results.json"), "w") as out:
        json.dump(rows, out, indent=1)
    print("\n" + text)
    print("written: %s" % os.path.join(args.output, "report.md"))
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except rgmc_common.UsageError as error:
        print("rgmc_benchmark: error: %s" % error, file=sys.stderr)
        sys.exit(2)
