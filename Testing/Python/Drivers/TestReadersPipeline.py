"""The readers as a user meets them, through ParaView (pvbatch):

- the generator writes the CT phantom as a DICOM series (pvbatch, --phantom); the pipeline
  command on that directory, on 1 and 2 ranks, gives exactly the surface it gives on the phantom
  source itself (same triangles, points, Euler characteristic): geometry and HU are right;
- the pipeline command extracts the brain of Debian's mricron ch2bet.nii.gz (largest component
  at 40.5, between the integer samples, so that no vertex sits on a sample): a closed surface
  of a brain's size where the brain is, the same mesh checks on 1, 2 and 3 ranks;
- under mpiexec, File > Open (OpenDataFile) picks the plugin's readers for a directory and a
  .nii.gz, and rank 0 decodes only the files of its own slab (with one ghost slice).

  python3 TestReadersPipeline.py --pvbatch pvbatch --mpiexec mpiexec --scripts Scripts/ \
      --plugin RGMarchingCubes.so --mricron /usr/share/mricron/templates --workdir DIR \
      --xvfb-run xvfb-run
"""

import argparse
import json
import os
import shutil
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
from rgmc_testing import check, failures, in_paraview, mpiexec_command, run  # noqa: E402


def stl_bounds(path):
    with open(path, "rb") as f:
        f.seek(80)
        count = struct.unpack("<I", f.read(4))[0]
        lo, hi = [1e30] * 3, [-1e30] * 3
        for _ in range(count):
            record = f.read(50)
            for v in range(3):
                p = struct.unpack("<3f", record[12 + 12 * v:24 + 12 * v])
                lo = [min(a, b) for a, b in zip(lo, p)]
                hi = [max(a, b) for a, b in zip(hi, p)]
    return lo, hi


def main():
    parser = argparse.ArgumentParser()
    for name in ("--pvbatch", "--mpiexec", "--scripts", "--plugin", "--mricron", "--workdir",
                 "--xvfb-run"):
        parser.add_argument(name, required=True)
    args = parser.parse_args()
    if os.path.isdir(args.workdir):
        shutil.rmtree(args.workdir)
    os.makedirs(args.workdir)
    pipeline = [args.pvbatch, os.path.join(args.scripts, "rgmc_pipeline.py"), "--plugin",
                args.plugin]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")

    # The phantom as a DICOM series, written by the generator as the demo writes it.
    series = os.path.join(args.workdir, "phantom-dicom")
    result = run([args.pvbatch, os.path.join(args.scripts, "rgmc_dicom_series.py"), "--plugin",
                  args.plugin, "--phantom", "96", "--output", series])
    check(result.returncode == 0 and len(os.listdir(series)) == 96, "the generator wrote 96 files")

    def surface(name, inputs, extra, ranks):
        prefix = os.path.join(args.workdir, "%s-%d" % (name, ranks))
        result = run(pipeline + inputs + extra + ["--ranks", str(ranks), "--output", prefix,
                                                  "--formats", "stl"], env=env)
        check(result.returncode == 0, "%s on %d ranks: exit %d" % (name, ranks, result.returncode))
        try:
            with open(prefix + ".json") as f:
                return json.load(f), prefix
        except OSError:
            return {"checks": {}}, prefix

    reference, _ = surface("phantom-source", ["--input", "phantom:96"],
                           ["--isovalue", "400", "--seed", "0,0,105"], 1)
    for ranks in (1, 2):
        report, _ = surface("phantom-dicom", ["--input", series],
                            ["--isovalue", "400", "--seed", "0,0,105"], ranks)
        check(report.get("checks") == reference.get("checks") and
              report.get("triangles") == reference.get("triangles"),
              "the DICOM series on %d ranks gives the phantom's surface: %s vs %s" % (
                  ranks, report.get("checks"), reference.get("checks")))
        check("DICOM series" in report.get("reader", ""), "the pipeline used the DICOM reader")

    # A brain from a real MRI volume.
    brain = os.path.join(args.mricron, "ch2bet.nii.gz")
    # On 1, 2 and 3 ranks (slabs of slices; this volume's longest side is y, so VTK's own split
    # would differ): the same closed surface.
    briefs = {}
    for ranks in (1, 2, 3):
        report, prefix = surface("brain", ["--input", brain],
                                 ["--isovalue", "40.5", "--mode", "largest"], ranks)
        checks = report.get("checks", {})
        briefs[ranks] = checks
        check(checks.get("Closed") == 1 and checks.get("Triangles", 0) > 100000,
              "ch2bet brain on %d ranks: a closed surface of %s triangles" % (ranks, checks.get("Triangles")))
        check(checks == briefs[1], "ch2bet brain on %d ranks: %s, on 1 rank %s" % (ranks, checks, briefs[1]))
        if ranks == 1 and os.path.exists(prefix + ".stl"):
            lo, hi = stl_bounds(prefix + ".stl")
            size = [h - l for l, h in zip(lo, hi)]
            centre = [(h + l) / 2 for l, h in zip(lo, hi)]
            # An adult brain with its cerebellum and brainstem, in MNI space (LPS here): about
            # 140 mm wide, 175 long, 150 high, centred near the origin.
            check(120 < size[0] < 170 and 150 < size[1] < 200 and 110 < size[2] < 170 and
                  max(abs(c) for c in centre) < 40,
                  "the brain is %.0f x %.0f x %.0f mm around (%.0f, %.0f, %.0f)"
                  % tuple(size + centre))

    # File > Open under mpiexec: the plugin's readers, a slab per rank.
    out = os.path.join(args.workdir, "mpi.json")
    result = run(mpiexec_command(args.mpiexec, 2) + [args.pvbatch, "--mpi",
                  in_paraview("ReadersMPI.py"),
                  "--plugin", args.plugin, "--dicom", series, "--nifti",
                  os.path.join(args.mricron, "ch2.nii.gz"), "--out", out], env=env)
    check(result.returncode == 0, "ReadersMPI.py under mpiexec -n 2")
    try:
        with open(out) as f:
            mpi = json.load(f)
    except OSError:
        mpi = {}
    dicom, nifti = mpi.get("dicom", {}), mpi.get("nifti", {})
    check(dicom.get("xml_name") in ("DICOMSeries", "RGDICOMSeriesReader"),
          "OpenDataFile(directory) makes %s" % dicom.get("xml_name"))
    check(nifti.get("xml_name") in ("NIfTIVolume", "RGNIfTIReader"),
          "OpenDataFile(.nii.gz) makes %s" % nifti.get("xml_name"))
    check(dicom.get("extent") == [0, 95, 0, 95, 0, 95] and nifti.get("extent") ==
          [0, 180, 0, 216, 0, 180], "whole extents %s, %s" % (dicom.get("extent"),
                                                               nifti.get("extent")))
    # 95 cells along z in 2 slabs: 47 cells (48 slices) for rank 0, and the ghost slice the
    # extraction needs, read with the rest from the first request.
    check(dicom.get("files_read_rank0") == 49,
          "rank 0 of 2 decoded %s of 96 files (its slab, 48, and the ghost slice)"
          % dicom.get("files_read_rank0"))
    # The extraction asks again with one ghost level: the piece has it, and is not read again.
    check(dicom.get("read_again_rank0") is False,
          "the extraction's request for a ghost level read rank 0's piece again (%s)"
          % dicom.get("read_again_rank0"))
    check(dicom.get("triangles") == reference.get("triangles"),
          "RGMarchingCubes on the opened series, 2 ranks: %s triangles, %s on the phantom" % (
              dicom.get("triangles"), reference.get("triangles")))
    print("%d failures" % len(failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
