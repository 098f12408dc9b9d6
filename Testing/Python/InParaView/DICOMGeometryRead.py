"""Run by TestDICOMGeometry.py with pvbatch --symmetric (under mpiexec for several ranks): opens
each DICOM directory with the plugin's DICOM Series reader, as File > Open does, and writes what
this rank's piece holds: its extent, origin, spacing and direction (JSON) and its samples (.npy,
numpy order [k, j, i]).

  mpiexec -n 3 pvbatch --symmetric DICOMGeometryRead.py --plugin P --out DIR NAME=DIRECTORY...
"""

import argparse
import json
import os

import numpy as np
from paraview import servermanager, simple
from vtkmodules.util.numpy_support import vtk_to_numpy


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--plugin", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("series", nargs="+", help="NAME=DIRECTORY")
    args = parser.parse_args()
    simple.LoadPlugin(args.plugin, ns=vars(simple))
    controller = servermanager.vtkProcessModule.GetProcessModule().GetGlobalController()
    rank, ranks = controller.GetLocalProcessId(), controller.GetNumberOfProcesses()
    for entry in args.series:
        name, path = entry.split("=", 1)
        reader = simple.DICOMSeries(FileName=path)
        reader.UpdatePipeline()
        image = reader.GetClientSideObject().GetOutputDataObject(0)
        direction = image.GetDirectionMatrix()
        extent = list(image.GetExtent())
        scalars = image.GetPointData().GetScalars()
        dims = [extent[1] - extent[0] + 1, extent[3] - extent[2] + 1, extent[5] - extent[4] + 1]
        values = vtk_to_numpy(scalars).astype(np.float64).reshape(dims[2], dims[1], dims[0])
        stem = os.path.join(args.out, "%s.%d-of-%d" % (name, rank, ranks))
        np.save(stem + ".npy", values)
        with open(stem + ".json", "w") as out:
            json.dump({"extent": extent, "origin": list(image.GetOrigin()),
                       "spacing": list(image.GetSpacing()),
                       "direction": [[direction.GetElement(a, b) for b in range(3)]
                                     for a in range(3)]}, out)
        simple.Delete(reader)


if __name__ == "__main__":
    main()
