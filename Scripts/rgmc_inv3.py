"""Reads InVesalius 3 projects (.inv3): the volume and InVesalius's own surfaces.

  /usr/bin/python3 Scripts/rgmc_inv3.py Cranium.inv3                # what the project holds
  /usr/bin/python3 Scripts/rgmc_inv3.py Cranium.inv3 --volume hu.npy --surface 0 --vtp bone.vtp

A project is a gzip'ed tar of one folder: main.plist (an XML property list: name, modality,
spacing, and the volume's file, dtype and shape [slices, rows, columns]), the volume as raw
little-endian samples (matrix.dat), and per mask and surface a .plist (a surface's records the
enclosed volume InVesalius computed) with its data (mask_N.dat, surface_N.vtp). Only Debian's
python3 and python3-numpy are needed.

Geometry: voxel (i, j, k) (numpy [k, j, i]) lies at (i sx, j sy, k sz), k the slice. InVesalius
writes its surfaces with the y axis flipped, at (x, -y, z): `to_volume_coordinates` maps their
points back (measured on Debian's Cranium.inv3: InVesalius's bone surface lies 0.2 mm on average
from Flying Edges' surface of the volume at its threshold after the flip, 117 mm without it).
"""

import argparse
import json
import os
import plistlib
import sys
import tarfile

import numpy as np

DTYPES = {"int16", "uint16", "int8", "uint8", "int32", "uint32", "float32", "float64"}


class ProjectError(Exception):
    """A file that is not an InVesalius 3 project this reader understands."""


class Project:
    """An .inv3 project: its metadata, volume (numpy [k, j, i]) and surfaces."""

    def __init__(self, path):
        self.path = path
        try:
            self._tar = tarfile.open(path, "r:*")
            self._members = {m.name: m for m in self._tar.getmembers() if m.isfile()}
        except (OSError, tarfile.TarError) as error:
            raise ProjectError("%s is not an InVesalius 3 project (a gzip'ed tar): %s"
                               % (path, error))
        mains = [n for n in self._members if os.path.basename(n) == "main.plist"]
        if len(mains) != 1:
            raise ProjectError("%s holds %d main.plist files, not one" % (path, len(mains)))
        self._folder = os.path.dirname(mains[0])
        self.main = self._plist("main.plist")
        matrix = self.main.get("matrix")
        try:
            self.dtype = str(matrix["dtype"])
            self.shape = [int(n) for n in matrix["shape"]]
            self._matrix_file = str(matrix["filename"])
            self.spacing = [float(s) for s in self.main["spacing"]]
        except (TypeError, KeyError, ValueError) as error:
            raise ProjectError("%s: main.plist lacks the volume's dtype, shape, filename or "
                               "spacing (%s)" % (path, error))
        if self.dtype not in DTYPES:
            raise ProjectError("%s: the volume's dtype %r is not one of %s"
                               % (path, self.dtype, ", ".join(sorted(DTYPES))))
        if len(self.shape) != 3 or min(self.shape) < 1:
            raise ProjectError("%s: the volume's shape %s is not 3 positive sizes"
                               % (path, self.shape))
        if len(self.spacing) != 3 or not all(s > 0 and np.isfinite(s) for s in self.spacing):
            raise ProjectError("%s: the spacing %s is not 3 positive numbers"
                               % (path, self.spacing))
        self.name = str(self.main.get("name", ""))
        self.modality = str(self.main.get("modality", ""))
        self.surfaces = []
        for index, plist in sorted(self.main.get("surfaces", {}).items(), key=lambda i: int(i[0])):
            surface = self._plist(plist)
            self.surfaces.append({
                "index": int(index), "name": str(surface.get("name", "")),
                "file": str(surface.get("polydata", "")),
                "volume_mm3": float(surface["volume"]) if "volume" in surface else None})
        self.masks = []
        for index, plist in sorted(self.main.get("masks", {}).items(), key=lambda i: int(i[0])):
            mask = self._plist(plist)
            self.masks.append({"index": int(index), "name": str(mask.get("name", "")),
                               "threshold_range": [float(t) for t in
                                                   mask.get("threshold_range", [])]})

    def _member(self, name):
        member = self._members.get(os.path.join(self._folder, name))
        if member is None:
            raise ProjectError("%s lacks %s" % (self.path, name))
        return self._tar.extractfile(member)

    def _plist(self, name):
        try:
            return plistlib.load(self._member(name))
        except (plistlib.InvalidFileException, ValueError, OSError) as error:
            raise ProjectError("%s: %s is not a property list (%s)" % (self.path, name, error))

    def volume(self):
        """The samples, numpy [k, j, i] in the project's dtype."""
        data = self._member(self._matrix_file).read()
        dtype = np.dtype(self.dtype).newbyteorder("<")
        expected = int(np.prod(self.shape)) * dtype.itemsize
        if len(data) != expected:
            raise ProjectError("%s: %s holds %d bytes, not the %d of a %s %s volume" % (
                self.path, self._matrix_file, len(data), expected, self.dtype,
                "x".join(str(n) for n in self.shape)))
        return np.frombuffer(data, dtype=dtype).reshape(self.shape).astype(self.dtype)

    def extract_surface(self, index, destination):
        """Writes surface `index`'s .vtp to `destination`."""
        files = [s["file"] for s in self.surfaces if s["index"] == index]
        if not files:
            raise ProjectError("%s has no surface %d (it has %s)" % (
                self.path, index, [s["index"] for s in self.surfaces]))
        with open(destination, "wb") as out:
            out.write(self._member(files[0]).read())

    def summary(self):
        return {"name": self.name, "modality": self.modality, "dtype": self.dtype,
                "dimensions": self.shape[::-1], "spacing": self.spacing,
                "surfaces": self.surfaces, "masks": self.masks}


def to_volume_coordinates(points):
    """InVesalius's surface points (n x 3) in the volume's coordinates: y flipped back."""
    points = np.array(points, dtype=np.float64)
    points[:, 1] = -points[:, 1]
    return points


def main(argv):
    parser = argparse.ArgumentParser(prog="rgmc_inv3.py", description=__doc__.split("\n")[0])
    parser.add_argument("project", help="an InVesalius 3 project (.inv3)")
    parser.add_argument("--volume", metavar="NPY", help="write the volume as a .npy [k, j, i]")
    parser.add_argument("--surface", type=int, metavar="N", help="the surface --vtp writes")
    parser.add_argument("--vtp", help="write InVesalius's surface N here (as stored: y flipped)")
    args = parser.parse_args(argv)
    if (args.surface is None) != (args.vtp is None):
        parser.error("--surface and --vtp go together")
    try:
        project = Project(args.project)
        if args.volume:
            np.save(args.volume, project.volume())
        if args.vtp:
            project.extract_surface(args.surface, args.vtp)
    except ProjectError as error:
        print("rgmc_inv3: error: %s" % error, file=sys.stderr)
        return 1
    print(json.dumps(project.summary(), indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
