"""Rewrites pydicom's real MR_small.dcm (explicit VR little endian) with structures real scanners
write, for TestDICOMFiles; run with Debian's python3 (python3-pydicom):

  python3 dicom_quirks.py PYDICOM_TEST_FILES OUTPUT_DIR

- undefined-length.dcm: a private sequence of undefined length whose items have undefined
  length, one of them holding a nested undefined-length sequence;
- odd-length.dcm: a private LO element of odd length (5 bytes), which DICOM forbids and
  scanners still write;
each with the original's pixel data.
"""

import os
import sys

import pydicom
from pydicom.dataset import Dataset
from pydicom.sequence import Sequence


def main():
    source, output = sys.argv[1], sys.argv[2]
    os.makedirs(output, exist_ok=True)
    original = os.path.join(source, "MR_small.dcm")

    ds = pydicom.dcmread(original)
    block = ds.private_block(0x0009, "RGMC QUIRKS", create=True)
    inner = Dataset()
    inner.add_new(0x00100020, "LO", "NESTED")
    inner.is_undefined_length_sequence_item = True
    nested = Sequence([inner])
    items = []
    for n in range(2):
        item = Dataset()
        item.add_new(0x00080100, "SH", "CODE%d" % n)
        if n == 1:
            item.add_new(0x00400260, "SQ", nested)
        item.is_undefined_length_sequence_item = True
        items.append(item)
    sequence = Sequence(items)
    block.add_new(0x10, "SQ", sequence)
    # (The length is the element's: set on what the data set holds.)
    ds[block.get_tag(0x10)].is_undefined_length = True
    ds[block.get_tag(0x10)].value[1][0x00400260].is_undefined_length = True
    path = os.path.join(output, "undefined-length.dcm")
    ds.save_as(path)
    data = open(path, "rb").read()
    if data.count(b"\xfe\xff\xdd\xe0\x00\x00\x00\x00") != 2 or data.count(b"\xfe\xff\x0d\xe0") != 3:
        raise RuntimeError("the sequences or items were not written with undefined length")

    ds = pydicom.dcmread(original)
    block = ds.private_block(0x0009, "RGMC QUIRKS", create=True)
    block.add_new(0x11, "LO", "ABCDEF")
    path = os.path.join(output, "odd-length.dcm")
    ds.save_as(path)
    data = open(path, "rb").read()
    even = b"\x09\x00\x11\x10LO\x06\x00ABCDEF"
    if data.count(even) != 1:
        raise RuntimeError("the placeholder element is not in the file once")
    with open(path, "wb") as out:
        out.write(data.replace(even, b"\x09\x00\x11\x10LO\x05\x00ABCDE"))
    print("written: %s" % output)


main()
