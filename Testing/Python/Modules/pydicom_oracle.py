"""The oracle of TestDICOMFiles: decodes every DICOM file of a directory with pydicom (Debian's
python3-pydicom, with numpy, its RLE decoder and Pillow's JPEG and JPEG 2000 decoders; GDCM's
Python bindings are not used, so the oracle is independent of the reader under test) and writes,
per file, the samples after the modality LUT (RescaleSlope * stored + RescaleIntercept) as
little-endian float64 in the reader's order (frame, row, column, sample), and a manifest:

  name <TAB> status <TAB> transfer syntax <TAB> frames rows columns samples <TAB> note

status is "decoded", "twin" (pydicom cannot decode it, but it is a lossless copy of a file it
decodes, named in note, whose samples were written), "cannot-decode" (pydicom lacks the codec or
the file is broken: note says why), "no-pixels" or "unreadable" (not a DICOM file to pydicom).

  /usr/bin/python3 pydicom_oracle.py DIRECTORY OUTPUT_DIRECTORY
"""

import os
import sys
import warnings

import numpy as np
import pydicom

try:  # pydicom 3 (Debian sid)
    from pydicom.pixels import apply_modality_lut
except ImportError:  # pydicom 2 (Debian 12 and 13)
    from pydicom.pixel_data_handlers.util import apply_modality_lut

# Lossless copies of one image in pydicom's test files: the JPEG-LS file holds MR_small's pixels.
TWINS = {"MR_small_jpeg_ls_lossless.dcm": "MR_small.dcm"}


def samples(ds):
    """pydicom's pixels as (frames, rows, columns, samples) float64 after the modality LUT, in
    the file's own colour space (as the reader gives them, and pydicom 2 did: pydicom 3 converts
    YBR to RGB unless told not to)."""
    if hasattr(ds, "pixel_array_options"):
        ds.pixel_array_options(as_rgb=False)
    array = ds.pixel_array
    frames = int(ds.get("NumberOfFrames", 1) or 1)
    spp = int(ds.get("SamplesPerPixel", 1))
    if spp == 1:
        array = apply_modality_lut(array, ds)
    return np.asarray(array, dtype=np.float64).reshape(frames, int(ds.Rows), int(ds.Columns), spp)


def main(source, output):
    warnings.simplefilter("ignore")
    os.makedirs(output, exist_ok=True)
    lines = []
    names = sorted(n for n in os.listdir(source) if n.endswith(".dcm"))
    for name in names:
        path = os.path.join(source, name)
        try:
            ds = pydicom.dcmread(path)
        except Exception as error:  # pydicom's own verdict is the oracle's
            lines.append([name, "unreadable", "-", "0 0 0 0", type(error).__name__])
            continue
        ts = str(getattr(getattr(ds, "file_meta", None), "TransferSyntaxUID", "") or "-")
        if "PixelData" not in ds:
            lines.append([name, "no-pixels", ts, "0 0 0 0", ""])
            continue
        status, note = "decoded", ""
        try:
            values = samples(ds)
        except Exception as error:
            values = None
            status, note = "cannot-decode", "%s: %s" % (type(error).__name__,
                                                        str(error).splitlines()[0][:120])
            twin = TWINS.get(name)
            if twin:
                values = samples(pydicom.dcmread(os.path.join(source, twin)))
                status, note = "twin", twin
        if values is not None:
            values.astype("<f8").tofile(os.path.join(output, name + ".f64"))
            shape = " ".join(str(v) for v in values.shape)
        else:
            shape = "0 0 0 0"
        lines.append([name, status, ts, shape, note.replace("\t", " ")])
    with open(os.path.join(output, "manifest.tsv"), "w") as out:
        for line in lines:
            out.write("\t".join(line) + "\n")
    print("pydicom %s: %d files, %d decoded" % (pydicom.__version__, len(lines),
                                                sum(1 for l in lines if l[1] == "decoded")))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
