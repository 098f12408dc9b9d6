"""Writes a CT volume as a DICOM series with known geometry: RGMC's phantom, a real CT from an
InVesalius project, or any int volume.

  pvbatch Scripts/rgmc_dicom_series.py --phantom 256 --output ct-phantom-dicom/
  /usr/bin/python3 Scripts/rgmc_dicom_series.py --inv3 Cranium.inv3 --output cranium-dicom/
  /usr/bin/python3 Scripts/rgmc_dicom_series.py --volume hu.npy --spacing 1,1,1 \\
      --origin=-128,-128,-128 --output series/

One file per slice (CT Image Storage), with shuffled file names and InstanceNumbers that count
down as the slice position goes up (instance 1 is the last slice along the normal, as scanners
that number from the head write them: a reader must sort by ImagePositionPatient; dcm2niix, which
stacks by InstanceNumber, converts the series right), a rescale that reproduces every value
exactly (the default, RescaleSlope 0.5 and RescaleIntercept -1024, stores 2 (HU + 1024)), and,
with --oblique, an ImageOrientationPatient rotated about the axis --axis through the first voxel.
Voxel (i, j, k) of the volume (numpy order [k, j, i]) lies at origin + R (i sx, j sy, k sz) in
LPS patient coordinates, R the rotation; the phantom's origin and spacing are its own, so the
series lands where the phantom's .vti does. --phantom needs ParaView (run with pvbatch);
--volume and --inv3 (an InVesalius 3 project's volume, its spacing, origin 0: Scripts/rgmc_inv3.py)
need only Debian's python3 with python3-numpy and python3-pydicom.

--defect writes a broken series on purpose, for the reader's error tests (see --help).
"""

import argparse
import math
import os
import random
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

DEFECTS = {
    "orientation": "one file's ImageOrientationPatient differs",
    "pixel-spacing": "one file's PixelSpacing differs",
    "duplicate-position": "two files at the same ImagePositionPatient",
    "irregular-spacing": "one slice moved by 0.3 slice spacings (an error: not evenly spaced)",
    "slightly-irregular-spacing": "one slice moved by 0.005 slice spacings (read: within rounding)",
    "rounded-positions": "ImagePositionPatient written with one decimal, as some scanners do (an "
                         "oblique stack's gaps then jitter: read, with a warning above 1%)",
    "missing-slice": "the middle slice left out (an error: a gap of 2 spacings)",
    "wide-gap": "the slices from the middle on moved by half a spacing (an error: a gap of 1.5)",
    "drift": "gaps growing steadily from 0.95 to 1.05 spacings (an error: a variable spacing)",
    "image-size": "one file has one column fewer",
    "no-position": "one file lacks ImagePositionPatient",
    "second-series": "a second series of 3 files in the same directory (a warning)",
    "gantry-tilt": "slices sheared along their column direction by tan(12 degrees) per spacing (a warning)",
    "localizer": "two sagittal localizers of another size in the same series (a warning)",
    "transfer-syntax": "one file declares MPEG-2 (which GDCM does not decode)",
}
TRANSFER_SYNTAXES = ["explicit-little", "implicit-little", "explicit-big", "rle"]


def parse_triple(text, name):
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) == 1:
        values *= 3
    if len(values) != 3:
        raise argparse.ArgumentTypeError("%s takes x,y,z, not %r" % (name, text))
    return values


def rotation(axis, degrees):
    """The rotation matrix about unit axis `axis` by `degrees` (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    a /= np.linalg.norm(a)
    t = math.radians(degrees)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * (k @ k)


def phantom_volume(size, noise, seed, plugin):
    """The phantom (numpy [k, j, i], int16 HU), its origin and spacing, through ParaView."""
    import rgmc_common
    from paraview import simple, servermanager
    from vtkmodules.util.numpy_support import vtk_to_numpy
    rgmc_common.load_plugin(plugin)
    source = simple.CTPhantom(Dimensions=[size] * 3, NoiseLevel=noise, RandomSeed=seed)
    image = servermanager.Fetch(source)
    dims = image.GetDimensions()
    values = vtk_to_numpy(image.GetPointData().GetArray("HU")).reshape(dims[2], dims[1], dims[0])
    return values.copy(), list(image.GetOrigin()), list(image.GetSpacing())


def stored_values(volume, slope, intercept):
    """The integers that slope * stored + intercept maps exactly to the volume, and their dtype
    and bits stored."""
    stored = (volume.astype(np.float64) - intercept) / slope
    rounded = np.round(stored)
    if not np.array_equal(stored, rounded):
        raise SystemExit("rgmc_dicom_series: error: slope %g and intercept %g cannot store these "
                         "values exactly (choose a slope that divides every value - intercept)"
                         % (slope, intercept))
    lo, hi = int(rounded.min()), int(rounded.max())
    if lo >= 0 and hi < 65536:
        bits = max(8, int(hi).bit_length())
        return rounded.astype(np.uint16), bits, 0
    if lo >= -32768 and hi < 32768:
        bits = max(8, max(int(-lo - 1).bit_length(), int(hi).bit_length()) + 1)
        return rounded.astype(np.int16), bits, 1
    raise SystemExit("rgmc_dicom_series: error: stored values %d..%d do not fit 16 bits" % (lo, hi))


def number(value):
    """A DS value: 16 characters at most, as precise as they allow."""
    for digits in range(15, 0, -1):
        text = "%.*g" % (digits, value)
        if len(text) <= 16:
            return text
    return "0"


def write_series(args, volume, origin, spacing):
    import pydicom
    from pydicom.dataset import Dataset, FileMetaDataset
    from pydicom.uid import (ExplicitVRBigEndian, ExplicitVRLittleEndian, ImplicitVRLittleEndian,
                             RLELossless, generate_uid)

    nz, ny, nx = volume.shape
    stored, bits, signed = stored_values(volume, args.slope, args.intercept)
    r = rotation(args.axis, args.oblique)
    row, col, normal = r[:, 0], r[:, 1], r[:, 2]
    rng = random.Random(args.random_seed)
    entropy = ["rgmc", str(args.random_seed), str(volume.shape)]
    study = generate_uid(entropy_srcs=entropy + ["study"])
    series = generate_uid(entropy_srcs=entropy + ["series"])
    frame = generate_uid(entropy_srcs=entropy + ["frame"])
    os.makedirs(args.output, exist_ok=True)
    ts = {"explicit-little": ExplicitVRLittleEndian, "implicit-little": ImplicitVRLittleEndian,
          "explicit-big": ExplicitVRBigEndian, "rle": RLELossless}[args.transfer_syntax]
    defect_slice = nz // 2

    def dataset(k, series_uid, rows, columns, pixels, position):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"  # CT Image Storage
        meta.MediaStorageSOPInstanceUID = generate_uid(
            entropy_srcs=entropy + [series_uid, "instance", str(k)])
        meta.TransferSyntaxUID = ExplicitVRLittleEndian if ts == RLELossless else ts
        ds = Dataset()
        ds.file_meta = meta
        ds.SOPClassUID = meta.MediaStorageSOPClassUID
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.Modality = "CT"
        ds.PatientName = args.patient_name
        ds.PatientID = args.patient_id
        ds.StudyInstanceUID = study
        ds.SeriesInstanceUID = series_uid
        ds.FrameOfReferenceUID = frame
        ds.SeriesDescription = args.description
        ds.SeriesNumber = 1
        ds.InstanceNumber = nz - k if k < nz else k + 1
        ds.ImagePositionPatient = [number(v) for v in position]
        ds.ImageOrientationPatient = [number(v) for v in list(row) + list(col)]
        ds.PixelSpacing = [number(spacing[1]), number(spacing[0])]  # row spacing, column spacing
        ds.SliceThickness = number(spacing[2])
        ds.Rows, ds.Columns = rows, columns
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated = 16
        ds.BitsStored = bits
        ds.HighBit = bits - 1
        ds.PixelRepresentation = signed
        ds.RescaleSlope = number(args.slope)
        ds.RescaleIntercept = number(args.intercept)
        ds.RescaleType = "HU"
        ds.is_little_endian = ts != ExplicitVRBigEndian
        ds.is_implicit_VR = ts == ImplicitVRLittleEndian
        data = np.ascontiguousarray(pixels)
        if ts == ExplicitVRBigEndian:
            data = data.byteswap()
        ds.PixelData = data.tobytes()
        if ts == RLELossless:
            ds.compress(RLELossless, np.ascontiguousarray(pixels))
            # An empty Basic Offset Table, as dcmtk and GDCM write one frame, instead of
            # pydicom's single 0 offset (both valid; dcm2niix 1.0.20250506, Debian sid's,
            # cannot decode the second: "RLE header corrupted").
            one_offset = b"\xfe\xff\x00\xe0\x04\x00\x00\x00\x00\x00\x00\x00"
            if ds.PixelData.startswith(one_offset):
                ds.PixelData = b"\xfe\xff\x00\xe0\x00\x00\x00\x00" + ds.PixelData[12:]
        return ds

    written = []
    for k in range(nz):
        position = np.asarray(origin) + k * spacing[2] * normal
        rows, columns, pixels = ny, nx, stored[k]
        if args.defect == "irregular-spacing" and k == defect_slice:
            position = position + 0.3 * spacing[2] * normal
        if args.defect == "gantry-tilt":
            position = position + k * spacing[2] * math.tan(math.radians(12.0)) * col
        if args.defect == "slightly-irregular-spacing" and k == defect_slice:
            position = position + 0.005 * spacing[2] * normal
        if args.defect == "wide-gap" and k >= defect_slice:
            position = position + 0.5 * spacing[2] * normal
        if args.defect == "drift":
            position = position + 0.05 * spacing[2] * (k * k / (nz - 1.0) - k) * normal
        if args.defect == "missing-slice" and k == defect_slice:
            continue
        if args.defect == "duplicate-position" and k == defect_slice:
            position = np.asarray(origin) + (k - 1) * spacing[2] * normal
        if args.defect == "image-size" and k == defect_slice:
            columns, pixels = nx - 1, stored[k][:, :-1]
        ds = dataset(k, series, rows, columns, pixels, position)
        if args.defect == "orientation" and k == defect_slice:
            tilted = rotation(args.axis, args.oblique + 5.0)
            ds.ImageOrientationPatient = [number(v) for v in
                                          list(tilted[:, 0]) + list(tilted[:, 1])]
        if args.defect == "pixel-spacing" and k == defect_slice:
            ds.PixelSpacing = [number(spacing[1] * 1.5), number(spacing[0])]
        if args.defect == "rounded-positions":
            ds.ImagePositionPatient = ["%.1f" % v for v in position]
        if args.defect == "no-position" and k == defect_slice:
            del ds.ImagePositionPatient
        if args.defect == "transfer-syntax" and k == defect_slice:
            from pydicom.encaps import encapsulate
            ds.file_meta.TransferSyntaxUID = "1.2.840.10008.1.2.4.100"  # MPEG-2 main profile
            ds.PixelData = encapsulate([b"\x00\x00\x01\xb3" + b"\x00" * 60])
            ds["PixelData"].VR = "OB"
            ds.is_little_endian, ds.is_implicit_VR = True, False
        name = os.path.join(args.output, "IM%06d" % rng.randrange(1000000))
        while name in written:
            name = os.path.join(args.output, "IM%06d" % rng.randrange(1000000))
        ds.save_as(name, write_like_original=False)
        written.append(name)
    if args.defect == "localizer":
        # Sagittal images (rows along the head-foot axis) through the middle of the volume.
        for k in range(2):
            column = nx // 2 + k
            position = np.asarray(origin) + column * spacing[0] * np.array([1.0, 0.0, 0.0])
            ds = dataset(nz + k, series, nz, ny, np.ascontiguousarray(stored[:, :, column]), position)
            ds.ImageOrientationPatient = ["0", "1", "0", "0", "0", "-1"]
            ds.SeriesDescription = "RGMC localizer"
            ds.save_as(os.path.join(args.output, "LOC%d" % k), write_like_original=False)
    if args.defect == "second-series":
        other = generate_uid(entropy_srcs=entropy + ["other series"])
        for k in range(min(3, nz)):
            position = np.asarray(origin) + k * spacing[2] * normal
            ds = dataset(k + nz, other, ny, nx, stored[k], position)
            ds.SeriesDescription = "RGMC scout"
            ds.save_as(os.path.join(args.output, "SCOUT%d" % k), write_like_original=False)
    print("written: %s (%d files, %d x %d x %d, spacing %s mm, slope %g, intercept %g, %s%s%s)"
          % (args.output, len(written), nx, ny, nz, ",".join(number(s) for s in spacing), args.slope,
             args.intercept, args.transfer_syntax,
             ", oblique %g degrees" % args.oblique if args.oblique else "",
             ", defect " + args.defect if args.defect else ""))
    print("series: %s" % series)
    return 0


def main(argv):
    parser = argparse.ArgumentParser(
        prog="rgmc_dicom_series.py", description=__doc__.split("\n")[0],
        epilog="defects: " + "; ".join("%s: %s" % item for item in DEFECTS.items()))
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--phantom", type=int, metavar="N",
                        help="the CT phantom at N^3 (needs pvbatch and the plugin)")
    source.add_argument("--volume", help="a .npy array [k, j, i] of integers")
    source.add_argument("--inv3", metavar="PROJECT",
                        help="the volume of an InVesalius 3 project (.inv3), with its spacing")
    parser.add_argument("--output", required=True, help="the directory to write")
    parser.add_argument("--spacing", type=lambda t: parse_triple(t, "--spacing"),
                        help="x,y,z voxel spacing in mm (--volume; default 1,1,1)")
    parser.add_argument("--origin", type=lambda t: parse_triple(t, "--origin"),
                        help="the first voxel's position, x,y,z in mm (--volume; default 0)")
    parser.add_argument("--slope", type=float, default=0.5, help="RescaleSlope (default 0.5)")
    parser.add_argument("--intercept", type=float, default=-1024.0,
                        help="RescaleIntercept (default -1024)")
    parser.add_argument("--oblique", type=float, default=0.0, metavar="DEGREES",
                        help="rotate the orientation by this angle about --axis (default 0)")
    parser.add_argument("--axis", type=lambda t: parse_triple(t, "--axis"), default=[1, 2, 3],
                        help="the rotation axis of --oblique (default 1,2,3)")
    parser.add_argument("--transfer-syntax", choices=TRANSFER_SYNTAXES, default="explicit-little")
    parser.add_argument("--noise", type=float, default=12.0, help="phantom noise in HU")
    parser.add_argument("--random-seed", type=int, default=1,
                        help="seeds the phantom's noise, the UIDs and the file name shuffle")
    parser.add_argument("--defect", choices=sorted(DEFECTS), help="write a broken series")
    parser.add_argument("--plugin", help="the plugin library (--phantom; default: found in $RGMC_BUILD_DIR or build/)")
    args = parser.parse_args(argv)
    if args.slope == 0:
        parser.error("--slope must not be 0")
    args.patient_name, args.patient_id = "RGMC^Phantom", "RGMC-PHANTOM"
    args.description = "RGMC CT phantom"
    if args.inv3:
        import rgmc_inv3
        try:
            project = rgmc_inv3.Project(args.inv3)
            volume = project.volume()
        except rgmc_inv3.ProjectError as error:
            parser.error(str(error))
        if volume.dtype.kind not in "iu":
            parser.error("%s holds %s samples, not integers" % (args.inv3, volume.dtype))
        origin = args.origin or [0.0, 0.0, 0.0]
        spacing = args.spacing or project.spacing
        args.patient_name = args.patient_id = project.name or "InVesalius project"
        args.description = "%s %s (InVesalius project %s)" % (
            project.name, project.modality, os.path.basename(args.inv3))
        return write_series(args, volume, origin, spacing)
    if args.phantom is not None:
        if args.phantom < 2:
            parser.error("--phantom must be at least 2")
        volume, origin, spacing = phantom_volume(args.phantom, args.noise, args.random_seed,
                                                 args.plugin)
    else:
        volume = np.load(args.volume)
        if volume.ndim != 3 or volume.dtype.kind not in "iu":
            parser.error("--volume must hold a 3-D integer array, not %s %s"
                         % (volume.dtype, volume.shape))
        origin = args.origin or [0.0, 0.0, 0.0]
        spacing = args.spacing or [1.0, 1.0, 1.0]
    if args.spacing and args.phantom is not None:
        spacing = args.spacing
    if args.origin and args.phantom is not None:
        origin = args.origin
    return write_series(args, volume, origin, spacing)


if __name__ == "__main__":
    code = main(sys.argv[1:])
    if code:
        sys.exit(code)
