"""Runs the pipeline command as a user does and checks what it writes and says.

  python3 TestPipelineCommand.py --pvbatch pvbatch --script Scripts/rgmc_pipeline.py \
      --phantom-script Scripts/rgmc_phantom.py --plugin RGMarchingCubes.so --workdir DIR \
      [--xvfb-run xvfb-run]
"""

import argparse
import glob
import hashlib
import json
import os
import re
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
from rgmc_testing import check, finish, run, xvfb_run  # noqa: E402


def stl_triangles(path):
    with open(path, "rb") as f:
        f.seek(80)
        count = struct.unpack("<I", f.read(4))[0]
    check(os.path.getsize(path) == 84 + 50 * count, "%s is a binary STL of %d triangles" % (path, count))
    return count


def ply_vertices(path):
    """The vertex count of a PLY file's header."""
    with open(path, "rb") as f:
        for line in f:
            if line.startswith(b"element vertex"):
                return int(line.split()[2])
            if line.startswith(b"end_header"):
                break
    return -1


def main():
    parser = argparse.ArgumentParser()
    for name in ("--pvbatch", "--script", "--phantom-script", "--plugin", "--workdir"):
        parser.add_argument(name, required=True)
    parser.add_argument("--xvfb-run")
    parser.add_argument("--admesh")
    args = parser.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    pipeline = [args.pvbatch, args.script, "--plugin", args.plugin]

    # --help works and names the options.
    result = run(pipeline + ["--help"])
    check(result.returncode == 0 and "--isovalue" in result.stdout and "--ranks" in result.stdout, "--help")

    # A volume file written by the phantom generator, then the main job on it (1 rank).
    volume = os.path.join(args.workdir, "phantom-72.vti")
    result = run([args.pvbatch, args.phantom_script, "--plugin", args.plugin, "--size", "72",
                  "--output", volume])
    check(result.returncode == 0 and os.path.isfile(volume), "the phantom is written")
    check(b'format="binary"' in open(volume, "rb").read(2000), "inline binary, not appended")
    prefix = os.path.join(args.workdir, "skull")
    command = pipeline + ["--input", volume, "--isovalue", "400", "--seed", "0,0,105", "--output", prefix]
    if args.xvfb_run:
        command = xvfb_run(args.xvfb_run, command + ["--screenshot", prefix + ".png"])
    result = run(command)
    check(result.returncode == 0, "the pipeline succeeds")
    for expected in ("input:", "72 x 72 x 72", "isovalue:   400", "seed:       (0, 0, 105)",
                     "triangles", "seconds:", "mesh:", "closed", "smoothing:  laplacian, 20",
                     "measures:   area", "before smoothing"):
        check(expected in result.stdout, "the summary says %r" % expected)
    report = json.load(open(prefix + ".json"))
    check(report["triangles"] > 10000, "the skull has many triangles: %d" % report["triangles"])
    # The extraction as the filter timed it: part of reading and extracting, never nothing.
    check(0 < report["extract_seconds"] <= report["total_seconds"],
          "the extraction's %s s within read and extract's %s s" % (
              report["extract_seconds"], report["total_seconds"]))
    check(stl_triangles(prefix + ".stl") == report["triangles"], "the STL holds every triangle")
    check(os.path.getsize(prefix + ".vtp") > 1000, "a VTP is written")
    if args.xvfb_run:
        png = open(prefix + ".png", "rb").read()
        check(png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20000, "a PNG picture is written")

    checks = report["checks"]
    check(checks["Closed"] == 1 and checks["BoundaryEdges"] == 0 and checks["NonManifoldEdges"] == 0,
          "the skull is closed: %s" % checks)
    check(checks["EulerCharacteristic"] == -6, "the skull (a shell with 5 holes) has Euler "
          "characteristic -6, not %d" % checks["EulerCharacteristic"])

    # The same on 2 ranks (the command starts mpiexec itself): the same surface, one mesh in
    # every format.
    result = run(pipeline + ["--input", volume, "--isovalue", "400", "--seed", "0,0,105",
                             "--output", prefix + "-2", "--ranks", "2", "--formats", "stl,ply,vtp"])
    check(result.returncode == 0, "the pipeline succeeds on 2 ranks")
    report2 = json.load(open(prefix + "-2.json"))
    check(0 < report2["extract_seconds"] <= report2["total_seconds"],
          "2 ranks: the extraction's %s s within read and extract's %s s" % (
              report2["extract_seconds"], report2["total_seconds"]))
    check(report2["ranks"] == 2 and report2["triangles"] == report["triangles"],
          "2 ranks give the same triangles: %d vs %d" % (report2["triangles"], report["triangles"]))
    check(report2["checks"] == checks, "2 ranks give the same mesh checks: %s" % report2["checks"])
    # The measures, to the bit (JSON keeps a double's every digit): smoothing shrank the skull.
    measures = report["measures"]
    check(report2["measures"] == measures, "2 ranks give the same measures: %s vs %s" % (
        report2["measures"], measures))
    check(measures["volume"] is not None and 0 < measures["volume"] < measures["volume_before_smoothing"]
          and measures["border_cap_area"] == 0,
          "the closed skull encloses a volume that Laplacian smoothing shrinks: %s" % measures)
    check(stl_triangles(prefix + "-2.stl") == report["triangles"], "the 2-rank STL holds every triangle")
    check(ply_vertices(prefix + "-2.ply") == checks["UniquePoints"],
          "the 2-rank PLY has no duplicate vertex: %d vs %d unique" % (
              ply_vertices(prefix + "-2.ply"), checks["UniquePoints"]))
    vtp_header = open(prefix + "-2.vtp", "rb").read(3000).decode("latin-1")
    check('NumberOfPoints="%d"' % checks["UniquePoints"] in vtp_header,
          "the 2-rank VTP has no duplicate vertex")
    if args.admesh:
        # An independent checker: every edge of the STL joins exactly two facets.
        out = run([args.admesh, prefix + "-2.stl"]).stdout
        for line in ("Facets with 1 disconnected edge", "Facets with 2 disconnected edges",
                     "Facets with 3 disconnected edges"):
            check(re.search(line + r"\s*:\s*0\s", out) is not None, "admesh: %s is not 0" % line)
        check(re.search(r"Number of parts\s*:\s*1\s", out) is not None, "admesh: one part")
        # admesh's volume of the STL (float facets, summed in float: about 1e-6 relative).
        found = re.search(r"Volume\s*:\s*([0-9.eE+-]+)", out)
        enclosed = report2["measures"]["volume"]
        check(found is not None and abs(float(found.group(1)) - enclosed) <= 1e-5 * enclosed,
              "admesh's volume %s, the report's %s" % (found and found.group(1), enclosed))

    # Decimated to a tenth on 1 and 3 ranks: the same file to the byte (one mesh, in one order),
    # closed for admesh too, with the report's distances and volume change.
    decimated = {}
    for ranks in (1, 3):
        out = "%s-decimated-%d" % (prefix, ranks)
        result = run(pipeline + ["--input", volume, "--isovalue", "400", "--seed", "0,0,105",
                                 "--output", out, "--ranks", str(ranks), "--decimate", "0.9",
                                 "--formats", "stl,ply"])
        check(result.returncode == 0, "the decimating pipeline succeeds on %d ranks" % ranks)
        check("decimated:" in result.stdout and "Hausdorff" in result.stdout,
              "the summary says what the decimation did")
        decimated[ranks] = json.load(open(out + ".json"))["decimation"]
        entry = decimated[ranks]
        check(abs(entry["triangles"] - 0.1 * entry["triangles_before"]) <= 0.01 * entry["triangles_before"],
              "a tenth of the triangles kept: %d of %d" % (entry["triangles"], entry["triangles_before"]))
        check(entry["checks"]["Closed"] == 1 and entry["checks"]["EulerCharacteristic"] == -6,
              "the decimated skull is closed, Euler characteristic -6: %s" % entry["checks"])
        check(stl_triangles(out + ".stl") == entry["triangles"], "the decimated STL holds every triangle")
        check(0 < entry["mean"] < entry["hausdorff"] < 1.0,
              "distances to the undecimated surface under a voxel (%.4g mm, mean %.4g)" % (
                  entry["hausdorff"], entry["mean"]))
        check(entry["volume_change_percent"] is not None and abs(entry["volume_change_percent"]) < 0.5,
              "the volume changes by less than 0.5%%: %s" % entry["volume_change_percent"])
        if args.admesh:
            text = run([args.admesh, out + ".stl"]).stdout
            for line in ("Facets with 1 disconnected edge", "Facets with 2 disconnected edges",
                         "Facets with 3 disconnected edges"):
                check(re.search(line + r"\s*:\s*0\s", text) is not None,
                      "admesh, decimated on %d ranks: %s is not 0" % (ranks, line))
            check(re.search(r"Number of parts\s*:\s*1\s", text) is not None,
                  "admesh, decimated on %d ranks: one part" % ranks)
    for extension in ("stl", "ply"):
        same = open("%s-decimated-1.%s" % (prefix, extension), "rb").read() == \
            open("%s-decimated-3.%s" % (prefix, extension), "rb").read()
        check(same, "the decimated %s is the same file on 1 and 3 ranks" % extension.upper())
    for key in ("checks", "triangles", "area", "volume", "hausdorff", "mean"):
        check(decimated[1][key] == decimated[3][key], "1 and 3 ranks: the same %s (%s, %s)" % (
            key, decimated[1][key], decimated[3][key]))

    # Threads: by default each rank takes its share of the machine's cores (with VTK_SMP_*
    # unset: Debian's VTK would run one thread), --threads N sets them (VTK runs at most as
    # many as the machine has cores); the files are the same to the byte on any.
    env = {k: v for k, v in os.environ.items() if not k.startswith("VTK_SMP_")}
    cores = len(os.sched_getaffinity(0))
    for threads, ranks, expected in ((None, 1, cores), (None, 2, max(1, cores // 2)),
                                     (3, 1, min(3, cores)), (2, 3, min(2, cores))):
        out = "%s-threads-%s-%d" % (prefix, threads, ranks)
        result = run(pipeline + ["--input", volume, "--isovalue", "400", "--seed", "0,0,105",
                                 "--output", out, "--ranks", str(ranks), "--decimate", "0.9",
                                 "--formats", "stl,ply"] +
                     (["--threads", str(threads)] if threads else []), env=env)
        what = "%d ranks, --threads %s" % (ranks, threads)
        check(result.returncode == 0, "%s: the pipeline succeeds" % what)
        report = json.load(open(out + ".json"))
        check(report["threads"] == expected and "threads: %d a rank" % expected in result.stdout,
              "%s: %s threads a rank, expected %d" % (what, report["threads"], expected))
        for extension in ("stl", "ply"):
            check(open("%s-decimated-1.%s" % (prefix, extension), "rb").read() ==
                  open("%s.%s" % (out, extension), "rb").read(),
                  "%s: the decimated %s is the one of 1 rank" % (what, extension.upper()))

    # A disk that fills up while writing over the earlier files (the case: a small
    # tmpfs, in a mount namespace of its own, so nothing outlives the test): a non-zero exit that
    # names the file and the cause, the earlier files byte for byte, nothing left beside them;
    # on 1 and 3 ranks. Mounting needs root (as in CI and the release matrix's chroots).
    earlier = {os.path.basename(p): hashlib.md5(open(p, "rb").read()).hexdigest()
               for p in glob.glob(prefix + ".*")}
    check(len(earlier) >= 3, "the earlier files: %s" % sorted(earlier))
    if os.geteuid() != 0:
        print("note: the full-disk case needs root (a tmpfs mount): not run")
    for ranks in ((1, 3) if os.geteuid() == 0 else ()):
        disk = os.path.join(args.workdir, "small-disk-%d" % ranks)
        os.makedirs(disk, exist_ok=True)
        size = sum(os.path.getsize(prefix + "." + name.split(".", 1)[1]) for name in earlier)
        shell = ('d="$1"; size="$2"; from="$3"; shift 3; mount -t tmpfs -o size="$size" tmpfs "$d" '
                 '&& cp "$from".* "$d"/ || exit 90; "$@"; rc=$?; '
                 '(cd "$d" && ls -A && md5sum -- *) > "$d.after"; exit $rc')
        result = run(["unshare", "--mount", "--propagation", "private", "sh", "-c", shell, "sh",
                      disk, str(size + (256 << 10)), prefix] + pipeline + [
                          "--input", "phantom:144", "--isovalue", "400", "--seed", "0,0,105",
                          "--output", os.path.join(disk, "skull"), "--ranks", str(ranks),
                          "--formats", "stl,ply,vtp"])
        check(result.returncode not in (0, 90), "a full disk on %d ranks: non-zero exit (%d)" % (
            ranks, result.returncode))
        check("cannot write %s/skull.stl" % disk in result.stderr and
              "No space left on device" in result.stderr,
              "a full disk on %d ranks: the error names the file and the cause" % ranks)
        after = open(disk + ".after").read().split()
        names = sorted(after[:len(earlier)])
        sums = dict(zip(after[len(earlier) + 1::2], after[len(earlier)::2]))
        check(names == sorted(earlier) and len(after) == 3 * len(earlier),
              "a full disk on %d ranks: nothing left beside the files: %s" % (ranks, after))
        for name, digest in earlier.items():
            check(sums.get(name) == digest,
                  "a full disk on %d ranks: the earlier %s is unchanged" % (ranks, name))

    # Bad input: clear messages and a non-zero exit, nothing written.
    cases = [
        (["--input", "/no/such/file.vti", "--isovalue", "1", "--seed", "0,0,0"], "no such file"),
        (["--input", volume, "--isovalue", "400"], "needs at least one --seed"),
        (["--input", volume, "--isovalue", "400", "--seed", "1,2"], "x,y,z"),
        (["--input", volume, "--isovalue", "400", "--seed", "0,0,105", "--array", "nope"], "no point array"),
        (["--input", volume, "--isovalue", "400", "--seed", "0,0,105", "--threads", "0"],
         "--threads must be at least 1"),
        (["--input", volume, "--isovalue", "9000", "--seed", "0,0,105"], "outside the data range"),
        (["--input", volume, "--isovalue", "400", "--seed", "0,0,900"], "lies outside the volume"),
        (["--input", volume, "--isovalue", "400", "--seed", "0,0,105", "--decimate", "1"],
         "--decimate takes the fraction"),
        (["--input", volume, "--isovalue", "400", "--seed", "0,0,105", "--max-error", "-1"],
         "--max-error takes a positive distance"),
    ]
    for extra, message in cases:
        result = run(pipeline + extra + ["--output", os.path.join(args.workdir, "bad")])
        check(result.returncode != 0, "%s: non-zero exit" % " ".join(extra))
        check(message in result.stdout + result.stderr, "%s: says %r" % (" ".join(extra), message))
    check(not os.path.exists(os.path.join(args.workdir, "bad.stl")), "nothing written on failure")

    return finish("TestPipelineCommand")


sys.exit(main())
