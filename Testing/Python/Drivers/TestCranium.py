"""A real patient: the head CT of Debian's invesalius-examples (Cranium.inv3, an InVesalius 3
project), as the demo runs it.

- Scripts/rgmc_inv3.py reads the project (its volume and spacing as main.plist says), and
  refuses broken copies of it (not a tar, no main.plist, a short volume, an unknown dtype, no
  spacing) with a message naming the problem;
- the generator writes it as a DICOM series (one file per slice, rescaled, shuffled names);
- on 1 to 4 ranks (pvbatch under mpiexec, InParaView/CraniumChecks.py), the plugin's reader
  reads the series and the skull seeded at the top of the head at 299.5 HU is exactly
  vtkMarchingCubes + closest-point connectivity of the project's own volume; the head holder's
  two pieces (tall components of their own, about 490 HU) are not in it; Seam Repair's area and
  volume of the skull are the same to the bit on every rank count;
- on 2 ranks, All Components at InVesalius's threshold (226 HU: isovalue 225.5), smoothed as the
  pipeline smooths, against InVesalius's own bone surface (surface_0.vtp): they lie within a
  tenth of a voxel of each other on average (both contour the same samples; InVesalius smooths
  its own way), and the enclosed volumes differ by less than that mean distance times the area.
  The figures are printed (README and the closing note quote them).

  python3 TestCranium.py --pvbatch pvbatch --mpiexec mpiexec --plugin P --scripts Scripts/ \\
      --cranium /usr/share/doc/invesalius-examples/examples/Cranium.inv3 --workdir DIR
"""

import argparse
import json
import os
import shutil
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
from rgmc_testing import (check, finish, in_paraview, mpi_environment, mpiexec_command,  # noqa: E402
                          run)

INVESALIUS_VOLUME = 657705.59515678  # mm^3, as surface_0.plist records it


def broken_projects(workdir, cranium, rgmc_inv3):
    """The project reader's errors: each broken copy of Cranium.inv3 is refused, naming why."""
    import io
    import tarfile
    with tarfile.open(cranium, "r:*") as tar:
        members = {m.name: tar.extractfile(m).read() for m in tar.getmembers() if m.isfile()}
    main_plist = [n for n in members if n.endswith("main.plist")][0]
    matrix = [n for n in members if n.endswith("matrix.dat")][0]

    def write(name, changed):
        path = os.path.join(workdir, name + ".inv3")
        with tarfile.open(path, "w:gz") as out:
            for member, data in changed.items():
                info = tarfile.TarInfo(member)
                info.size = len(data)
                out.addfile(info, io.BytesIO(data))
        return path

    text = members[main_plist]
    cases = [
        ("not-a-project", None, "is not an InVesalius 3 project"),
        ("no-main", {k: v for k, v in members.items() if k != main_plist}, "main.plist files, not one"),
        ("short-matrix", dict(members, **{matrix: members[matrix][:-2]}), "holds 14155774 bytes"),
        ("bad-dtype", dict(members, **{main_plist: text.replace(b"<string>int16</string>",
                                                                 b"<string>complex64</string>")}),
         "dtype 'complex64'"),
        ("no-spacing", dict(members, **{main_plist: text.replace(b"<key>spacing</key>",
                                                                  b"<key>spacings</key>")}),
         "lacks the volume's dtype, shape, filename or spacing"),
    ]
    for name, changed, message in cases:
        if changed is None:
            path = os.path.join(workdir, name + ".inv3")
            with open(path, "wb") as out:
                out.write(b"not a tar at all")
        else:
            path = write(name, changed)
        try:
            rgmc_inv3.Project(path).volume()
            check(False, "%s: read without an error" % name)
        except rgmc_inv3.ProjectError as error:
            check(message in str(error), "%s: the error %r does not say %r" % (name, str(error),
                                                                               message))


def main():
    parser = argparse.ArgumentParser()
    for name in ("--pvbatch", "--mpiexec", "--plugin", "--scripts", "--cranium", "--workdir"):
        parser.add_argument(name, required=True)
    parser.add_argument("--ranks", default="1,2,3,4")
    args = parser.parse_args()
    if not os.path.isfile(args.cranium):
        check(False, "missing %s: Debian's package invesalius-examples holds it (./rgmc deps "
              "installs it)" % args.cranium)
        return finish("TestCranium")
    if os.path.isdir(args.workdir):
        shutil.rmtree(args.workdir)
    os.makedirs(args.workdir)

    sys.path.insert(0, args.scripts)
    import rgmc_inv3
    project = rgmc_inv3.Project(args.cranium)
    summary = project.summary()
    check(summary["dimensions"] == [256, 256, 108] and summary["modality"] == "CT" and
          abs(summary["spacing"][0] - 0.9570312) < 1e-9 and summary["spacing"][2] == 1.5,
          "the project's volume: %s" % summary)
    check(summary["surfaces"][0]["volume_mm3"] == INVESALIUS_VOLUME,
          "InVesalius's bone surface records %s mm^3" % summary["surfaces"][0]["volume_mm3"])
    broken_projects(args.workdir, args.cranium, rgmc_inv3)
    vtp = os.path.join(args.workdir, "invesalius-bone.vtp")
    project.extract_surface(0, vtp)

    series = os.path.join(args.workdir, "cranium-dicom")
    result = run([sys.executable, os.path.join(args.scripts, "rgmc_dicom_series.py"), "--inv3",
                  args.cranium, "--output", series])
    check(result.returncode == 0 and len(os.listdir(series)) == 108, "the series: 108 files")

    reports = {}
    for ranks in [int(r) for r in args.ranks.split(",")]:
        out = os.path.join(args.workdir, "checks-%d.json" % ranks)
        command = mpiexec_command(args.mpiexec, ranks) + [
            args.pvbatch, "--mpi", in_paraview("CraniumChecks.py"), "--plugin", args.plugin,
            "--scripts", args.scripts, "--project", args.cranium, "--series", series,
            "--out", out]
        if ranks == 2:
            command += ["--invesalius-vtp", vtp]
        result = run(command, env=mpi_environment(), tail=6000)
        check(result.returncode == 0, "CraniumChecks.py on %d ranks" % ranks)
        try:
            with open(out) as f:
                reports[ranks] = json.load(f)
        except (OSError, ValueError):
            continue
        seeded = reports[ranks]["seeded"]
        check(seeded["triangles"] == seeded["oracle_triangles"] and seeded["triangles"] > 100000,
              "%d ranks: the seeded skull has %d triangles, vtkMarchingCubes + connectivity %d" % (
                  ranks, seeded["triangles"], seeded["oracle_triangles"]))
        # vtkMarchingCubes computes in float: its vertices carry float rounding (about 1e-5 mm
        # at 250 mm).
        check(seeded["largest_vertex_distance"] is not None and
              seeded["largest_vertex_distance"] < 1e-4,
              "%d ranks: a vertex %s mm from the oracle's nearest" % (
                  ranks, seeded["largest_vertex_distance"]))
        holder = reports[ranks]["holder"]
        check(len(holder) == 2 and all(piece["distance_to_seeded"] > 10.0 for piece in holder),
              "%d ranks: the head holder is two tall pieces, each over 10 mm from the seeded "
              "skull: %s" % (ranks, holder))
        small = seeded["decimated"]
        before = small["input"]
        check(abs(small["Triangles"] - 0.1 * before["Triangles"]) <= 0.01 * before["Triangles"]
              and small["TrianglesBeforeDecimation"] == before["Triangles"],
              "%d ranks: the decimated skull keeps a tenth of %d triangles: %d" % (
                  ranks, before["Triangles"], small["Triangles"]))
        check(small["BoundaryEdges"] == 0 and small["NonManifoldEdges"] == 0 and
              small["VolumeBorderEdges"] == before["VolumeBorderEdges"] and
              small["EulerCharacteristic"] == before["EulerCharacteristic"],
              "%d ranks: the decimated skull is closed but at the border, which is unchanged, "
              "with the same Euler characteristic: %s, before %s" % (ranks, small, before))
        check(abs(small["EnclosedVolume"] / seeded["measures"]["EnclosedVolume"] - 1) < 0.005,
              "%d ranks: decimation changes the skull's volume by less than 0.5%%: %s, before %s" % (
                  ranks, small["EnclosedVolume"], seeded["measures"]["EnclosedVolume"]))
        check(small == reports[min(reports)]["seeded"]["decimated"],
              "%d ranks: the decimated skull as on %d ranks" % (ranks, min(reports)))
        first = reports[min(reports)]["seeded"]["measures"]
        check(seeded["measures"] == first, "%d ranks: the skull's measures %s, on %d: %s" % (
            ranks, seeded["measures"], min(reports), first))

    if 2 in reports:
        theirs = reports[2]["invesalius"]
        d = theirs["distances"]
        voxel = summary["spacing"][0]
        print("InVesalius comparison (All Components at 225.5 HU, 20 Laplacian iterations): "
              "volume %.1f mm^3 (unsmoothed %.1f), InVesalius %.1f; area %.1f mm^2; distances "
              "mean %.3f mm, 99th percentile %.3f mm, Hausdorff %.2f mm, %.3f%% over 1 mm" % (
                  theirs["EnclosedVolume"], theirs["EnclosedVolumeBeforeSmoothing"],
                  INVESALIUS_VOLUME, theirs["SurfaceArea"], d["mean"], d["p99"], d["hausdorff"],
                  100 * d["over_1mm"]))
        check(theirs["closed"] == 1, "the bone surface at 225.5 is closed (cut by the border)")
        check(d["mean"] < 0.1 * voxel and d["p99"] < voxel,
              "InVesalius's surface: mean distance %.3f mm (a tenth of a voxel: %.3f), 99th "
              "percentile %.3f mm (a voxel)" % (d["mean"], 0.1 * voxel, d["p99"]))
        difference = abs(theirs["EnclosedVolume"] - INVESALIUS_VOLUME)
        bound = d["mean"] * theirs["SurfaceArea"]
        check(difference < bound, "the volumes differ by %.1f mm^3, more than the mean distance "
              "times the area (%.1f)" % (difference, bound))
    return finish("TestCranium")


if __name__ == "__main__":
    sys.exit(main())
