"""Run by TestReadersPipeline.py with pvbatch under mpiexec: opens a DICOM series directory and
a NIfTI file the way a user does (OpenDataFile, i.e. File > Open), and prints as JSON what the
readers and ParaView's data information say.

  mpiexec -n 2 pvbatch --mpi ReadersMPI.py --plugin P --dicom DIR --nifti FILE --out JSON
"""

import argparse
import json

from paraview import simple


def main():
    parser = argparse.ArgumentParser()
    for name in ("--plugin", "--dicom", "--nifti", "--out"):
        parser.add_argument(name, required=True)
    args = parser.parse_args()
    simple.LoadPlugin(args.plugin, ns=vars(simple))
    from paraview import servermanager
    ranks = servermanager.vtkProcessModule.GetProcessModule().GetNumberOfLocalPartitions()
    result = {"ranks": ranks}
    for key, path in (("dicom", args.dicom), ("nifti", args.nifti)):
        reader = simple.OpenDataFile(path)
        reader.UpdatePipeline()
        info = reader.GetDataInformation()
        reader.UpdatePropertyInformation()
        entry = {"xml_name": reader.GetXMLName(), "extent": list(info.GetExtent()),
                 "points": info.GetNumberOfPoints(), "summary": reader.GetPropertyValue("Summary"),
                 "arrays": list(reader.PointData.keys())}
        if key == "dicom":
            entry["files_read_rank0"] = reader.GetPropertyValue("NumberOfFilesRead")
            piece = reader.GetClientSideObject().GetOutputDataObject(0)
            made = piece.GetMTime()
            surface = simple.RGMarchingCubes(Input=reader, ContourBy=["POINTS", "HU"],
                                             Isovalue=400, SeedPoints=[0, 0, 105])
            surface.UpdatePipeline()
            entry["triangles"] = surface.GetDataInformation().GetNumberOfCells()
            # Whether the extraction's request for a ghost level made rank 0's piece again.
            entry["read_again_rank0"] = (
                reader.GetClientSideObject().GetOutputDataObject(0).GetMTime() != made)
        result[key] = entry
    with open(args.out, "w") as out:
        json.dump(result, out, indent=2)
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
