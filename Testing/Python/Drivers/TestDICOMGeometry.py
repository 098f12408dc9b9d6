"""The DICOM Series reader's geometry against an oracle the project did not write: Debian's
dcm2niix converts the same files to NIfTI, Debian's nibabel reads the NIfTI's affine (sform, in
RAS), and the reader's origin, spacing and direction (LPS) must give the same position, within
1e-4 mm, to every corner of every rank's piece, on 1 to 4 ranks.

Files: the series the generator writes for the tests (Scripts/rgmc_dicom_series.py: axial,
oblique, sagittal, coronal with RLE, big endian, implicit VR), and pydicom's real multi-frame
RT dose files (rtdose.dcm: explicit little endian; rtdose_expb.dcm: big endian; rtdose_rle.dcm).

dcm2niix may store the voxels in another index order (it flips rows so that NIfTI's j axis goes
up). The order is found from the samples, not from the geometry under test: of the 48 axis
permutations and flips, exactly one must make dcm2niix's samples (after nibabel applies
scl_slope and scl_inter) equal to the reader's piece; the NIfTI affine is then expressed in the
reader's index order. For RT dose, dcm2niix says "Unable to determine slice thickness" (it does
not read GridFrameOffsetVector) and writes a slice spacing of 1: there the slice axis keeps
dcm2niix's direction and takes its spacing from the offsets as pydicom reads them, and the test
checks that dcm2niix still says so (if a later dcm2niix reads the offsets, its spacing is used).

  /usr/bin/python3 TestDICOMGeometry.py --pvbatch pvbatch --mpiexec mpiexec --dcm2niix dcm2niix \
      --plugin RGMarchingCubes.so --scripts Scripts/ --pydicom-data DIR --workdir DIR
"""

import argparse
import itertools
import json
import os
import shutil
import sys

import nibabel
import numpy as np
import pydicom

try:  # pydicom 3 (Debian sid)
    from pydicom.pixels import apply_modality_lut
except ImportError:  # pydicom 2 (Debian 12 and 13)
    from pydicom.pixel_data_handlers.util import apply_modality_lut

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "Modules"))
from rgmc_testing import check, failures, in_paraview, mpiexec_command, run  # noqa: E402

TOLERANCE_MM = 1e-4
SPACING = "0.7,0.8,1.25"
ORIGIN = "-100.5,37.25,12"
# name, generator options: every orientation and transfer syntax the tests' series use.
GENERATED = [
    ("axial", "--slope 1 --intercept -1024"),
    ("oblique", "--slope 0.5 --intercept -1024 --oblique 30 --axis 1,2,3 "
                "--transfer-syntax implicit-little"),
    ("sagittal", "--slope 1 --intercept -1024 --oblique 90 --axis 0,1,0"),
    ("bigendian", "--slope 0.25 --intercept -2048.5 --transfer-syntax explicit-big"),
    ("coronal-rle", "--slope 1 --intercept -1024 --oblique 90 --axis 1,0,0 --transfer-syntax rle"),
    ("rounded-positions", "--slope 1 --intercept -1024 --oblique 30 --axis 1,2,3 "
                          "--defect rounded-positions"),
]
# An oblique stack whose positions are written with one decimal, as some scanners do: each
# coordinate is off by up to 0.05 mm, so the slices jitter about an evenly spaced stack. The
# reader fits the spacing to every slice (least squares) along the normal of the orientation;
# dcm2niix takes its slice axis from the first and last slices' rounded positions (whose
# difference is off by up to 2 x 0.05 x sqrt(3) = 0.17 mm, direction included). The two agree
# within that and the fit's own error (at most 0.1 mm here), not to 1e-4 mm; the reader's
# spacing against the unrounded positions is checked in TestDICOMSeries.
CORNER_TOLERANCE_MM = {"rounded-positions": 0.3}
REAL = ["rtdose.dcm", "rtdose_expb.dcm", "rtdose_rle.dcm"]
TWINS = {"rtdose_rle": "rtdose"}  # pydicom decodes both to the same samples
NO_SLICE_SPACING = "Unable to determine slice thickness"


def volume(path):
    """A 40 x 36 x 30 integer volume (numpy order [k, j, i]) without symmetries: smooth waves
    plus fixed noise, so that only one index order matches it."""
    rng = np.random.default_rng(13)
    k, j, i = np.mgrid[0:30, 0:36, 0:40]
    v = 200 * np.sin(i / 5.0) + 150 * np.cos(j / 4.0) + 100 * np.sin(k / 3.0 + 0.4)
    v = np.round(v + rng.integers(-40, 40, v.shape)).astype(np.int16)
    np.save(path, v)


def reorder(nifti, p, f):
    """The NIfTI samples [i', j', k'] in the reader's index order: n[a] = m[p[a]], or
    N[a] - 1 - m[p[a]] where f[a]."""
    flipped = nifti[tuple(slice(None, None, -1) if f[a] else slice(None) for a in range(3))]
    return np.transpose(flipped, np.argsort(p))


def orders():
    return [(p, f) for p in itertools.permutations(range(3))
            for f in itertools.product((False, True), repeat=3)]


def index_map(nifti_shape, ours_shape, nifti, ours):
    """The index orders (permutation p, flips f) that make the NIfTI samples, as an array
    [i', j', k'], equal the reader's whole volume `ours` ([i, j, k]): ours[m] ==
    nifti[n] with n[a] = m[p[a]] or N[a] - 1 - m[p[a]]."""
    found = []
    for p, f in orders():
        if tuple(nifti_shape[a] for a in range(3)) == tuple(ours_shape[p[a]] for a in range(3)):
            if np.array_equal(reorder(nifti, p, f), ours):
                found.append((p, f))
    return found


def twin_order(what, ours, pixels, twin):
    """When no index order makes dcm2niix's samples equal the reader's, for a real file with an
    uncompressed twin (TWINS): if pydicom decodes the file to the reader's samples and to the
    twin's, dcm2niix decoded it wrongly (its RLE of 32-bit samples, for rtdose_rle.dcm), and its
    index order is the twin's (dcm2niix orders voxels from the header, which the twins share)."""
    theirs = np.transpose(pixels, (2, 1, 0))
    same = theirs.shape == ours.shape and np.array_equal(theirs, ours)
    check(same, "%s: dcm2niix's samples differ from the reader's, and pydicom's too" % what)
    check(twin is not None and np.array_equal(pixels, twin[0]),
          "%s: pydicom decodes the file as its twin" % what)
    if not same or twin is None or not np.array_equal(pixels, twin[0]):
        return []
    print("%s: dcm2niix decodes the samples differently from pydicom and the reader (which "
          "agree, and equal the uncompressed twin's): the twin's index order" % what)
    return [twin[1]]


def affine_in_our_order(affine, nifti_shape, p, f):
    """The NIfTI's voxel-to-RAS affine as a function of the reader's index m."""
    t = np.zeros((4, 4))
    t[3, 3] = 1
    for a in range(3):  # n[a] = m[p[a]] or N[a] - 1 - m[p[a]]
        t[a, p[a]] = -1.0 if f[a] else 1.0
        t[a, 3] = nifti_shape[a] - 1 if f[a] else 0.0
    return affine @ t


def corners(extent):
    return [np.array([x, y, z], dtype=float) for x in extent[0:2] for y in extent[2:4]
            for z in extent[4:6]]


def position(geometry, m):
    """The reader's patient position (LPS) of index m: origin + D diag(spacing) m."""
    d = np.array(geometry["direction"])
    return np.array(geometry["origin"]) + d @ (np.array(geometry["spacing"]) * m)


def whole_volume(pieces, shape):
    """The reader's whole volume [i, j, k] from its pieces (checking that they agree where
    neighbouring pieces overlap)."""
    whole = np.full(shape, np.nan)
    for geometry, values in pieces:
        e = geometry["extent"]
        block = np.transpose(values, (2, 1, 0))
        target = whole[e[0]:e[1] + 1, e[2]:e[3] + 1, e[4]:e[5] + 1]
        overlap = ~np.isnan(target)
        check(np.array_equal(target[overlap], block[overlap]), "pieces agree where they overlap")
        target[...] = block
    check(not np.isnan(whole).any(), "the pieces cover the volume")
    return whole


def main():
    parser = argparse.ArgumentParser()
    for name in ("--pvbatch", "--mpiexec", "--dcm2niix", "--plugin", "--scripts",
                 "--pydicom-data", "--workdir"):
        parser.add_argument(name, required=True)
    parser.add_argument("--ranks", default="1,2,3,4")
    args = parser.parse_args()
    if os.path.isdir(args.workdir):
        shutil.rmtree(args.workdir)
    os.makedirs(args.workdir)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")

    # The series, and the real files each in a directory of its own.
    npy = os.path.join(args.workdir, "volume.npy")
    volume(npy)
    directories = {}
    for name, options in GENERATED:
        directory = os.path.join(args.workdir, "dicom", name)
        result = run([sys.executable, os.path.join(args.scripts, "rgmc_dicom_series.py"),
                      "--volume", npy, "--spacing=" + SPACING, "--origin=" + ORIGIN,
                      "--output", directory] + options.split())
        check(result.returncode == 0, "%s: the generator wrote the series" % name)
        directories[name] = directory
    frame_spacing = {}
    for name in REAL:
        directory = os.path.join(args.workdir, "dicom", os.path.splitext(name)[0])
        os.makedirs(directory)
        shutil.copy(os.path.join(args.pydicom_data, name), directory)
        directories[os.path.splitext(name)[0]] = directory
        offsets = [float(v) for v in pydicom.dcmread(os.path.join(directory, name))
                   .GridFrameOffsetVector]
        gaps = np.diff(offsets)
        check(np.ptp(gaps) < 1e-9, "%s: evenly spaced frames" % name)
        frame_spacing[os.path.splitext(name)[0]] = float(gaps.mean())

    # The oracle: dcm2niix's conversion, nibabel's affine and samples.
    oracle = {}
    for name, directory in directories.items():
        out = os.path.join(args.workdir, "nifti", name)
        os.makedirs(out)
        result = run([args.dcm2niix, "-b", "n", "-z", "n", "-f", "converted", "-o", out,
                      directory])
        path = os.path.join(out, "converted.nii")
        check(result.returncode == 0 and os.path.isfile(path),
              "%s: dcm2niix converted the series (exit %d)" % (name, result.returncode))
        if not os.path.isfile(path):
            continue
        image = nibabel.load(path)
        affine, code = image.header.get_sform(coded=True)
        check(code > 0, "%s: dcm2niix wrote an sform" % name)
        oracle[name] = {"affine": affine, "samples": np.asarray(image.get_fdata()),
                        "no_slice_spacing": NO_SLICE_SPACING in result.stdout + result.stderr,
                        "pydicom": None}
        if name in frame_spacing:  # one real multi-frame file: pydicom's samples too
            ds = pydicom.dcmread(os.path.join(directory, name + ".dcm"))
            oracle[name]["pydicom"] = np.asarray(apply_modality_lut(ds.pixel_array, ds),
                                                 dtype=np.float64)
        if name in frame_spacing:
            print("%s: dcm2niix %s" % (name, "cannot place the frames (no GridFrameOffsetVector"
                  " support): slice spacing from pydicom" if oracle[name]["no_slice_spacing"]
                  else "places the frames itself"))
        else:
            check(not oracle[name]["no_slice_spacing"],
                  "%s: dcm2niix determines the slice spacing" % name)

    # The reader, as File > Open gives it, on 1 to 4 ranks: each rank's piece.
    script = in_paraview("DICOMGeometryRead.py")
    series = ["%s=%s" % item for item in directories.items()]
    for ranks in [int(r) for r in args.ranks.split(",")]:
        out = os.path.join(args.workdir, "reader")
        os.makedirs(out, exist_ok=True)
        command = [args.pvbatch, "--symmetric", script, "--plugin", args.plugin, "--out", out]
        if ranks > 1:
            command = mpiexec_command(args.mpiexec, ranks) + [args.pvbatch, "--mpi"] + command[1:]
        result = run(command + series, env=env, tail=3000)
        check(result.returncode == 0, "%d ranks: the reader ran (exit %d)"
              % (ranks, result.returncode))
        if result.returncode != 0:
            continue
        found = {}
        for name in directories:
            if name not in oracle:
                continue
            pieces = []
            for rank in range(ranks):
                stem = os.path.join(out, "%s.%d-of-%d" % (name, rank, ranks))
                with open(stem + ".json") as f:
                    pieces.append((json.load(f), np.load(stem + ".npy")))
            twin = None
            if name in TWINS and TWINS[name] in found:
                twin = (oracle[TWINS[name]]["pydicom"], found[TWINS[name]])
            found[name] = compare(name, ranks, pieces, oracle[name], frame_spacing.get(name), twin)
    print("%d failed checks" % len(failures))
    for failure in failures:
        print("FAILED: " + failure)
    return 1 if failures else 0


def compare(name, ranks, pieces, oracle, frame_spacing, twin):
    """Checks one reading; returns the index order found (for a twin)."""
    what = "%s on %d ranks" % (name, ranks)
    top = [max(g["extent"][2 * a + 1] for g, _ in pieces) for a in range(3)]
    shape = tuple(t + 1 for t in top)
    ours = whole_volume(pieces, shape)
    nifti = oracle["samples"].reshape(oracle["samples"].shape[:3])
    maps = index_map(nifti.shape, shape, nifti, ours)
    if not maps and twin is not None:
        maps = twin_order(what, ours, oracle["pydicom"], twin)
    check(len(maps) == 1, "%s: %d index orders make dcm2niix's samples equal the reader's"
          % (what, len(maps)))
    if len(maps) != 1:
        return None
    p, f = maps[0]
    affine = affine_in_our_order(oracle["affine"], nifti.shape, p, f)
    lps = np.diag([-1.0, -1.0, 1.0, 1.0]) @ affine  # RAS to LPS
    if oracle["no_slice_spacing"] and frame_spacing is not None:
        # dcm2niix's slice axis has its direction and a length of 1: give it the offsets' gap.
        slice_axis = p[2]  # the NIfTI's third axis, in the reader's order
        column = lps[:3, slice_axis]
        check(abs(np.linalg.norm(column) - 1.0) < 1e-6, "%s: dcm2niix's unit slice axis" % what)
        lps[:3, slice_axis] = column / np.linalg.norm(column) * frame_spacing
    worst = 0.0
    for geometry, _ in pieces:
        for m in corners(geometry["extent"]):
            expected = lps[:3, :3] @ m + lps[:3, 3]
            worst = max(worst, float(np.abs(position(geometry, m) - expected).max()))
    tolerance = CORNER_TOLERANCE_MM.get(name, TOLERANCE_MM)
    check(worst <= tolerance, "%s: corners %.3g mm from dcm2niix's (tolerance %g mm)"
          % (what, worst, tolerance))
    spacing = np.linalg.norm(lps[:3, :3], axis=0)
    direction = lps[:3, :3] / spacing
    g = pieces[0][0]
    print("%s: largest corner distance %.2e mm; origin %s, spacing %s; direction differs by "
          "%.1e; index order (%s, flips %s)" % (
              what, worst, np.round(g["origin"], 6).tolist(), np.round(g["spacing"], 6).tolist(),
              float(np.abs(np.array(g["direction"]) - direction).max()), p, f))
    return p, f


if __name__ == "__main__":
    sys.exit(main())
