// The distributed reading shared by the plugin's volume readers: one header scan on rank 0,
// broadcast; each rank reads its own slab; every status agreed over all ranks.
#include "vtkRGVolumeReader.h"

#include "vtkRGArrays.h"
#include "vtkRGCollective.h"
#include "vtkRGMessage.h"
#include "vtkRGPieces.h"
#include "vtkRGRunController.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkPointData.h"
#include "vtkShortArray.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

//------------------------------------------------------------------------------
vtkRGVolumeReader::vtkRGVolumeReader()
{
  this->SetNumberOfInputPorts(0);
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

//------------------------------------------------------------------------------
vtkRGVolumeReader::~vtkRGVolumeReader()
{
  this->SetFileName(nullptr);
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------
void vtkRGVolumeReader::SetController(vtkMultiProcessController* controller)
{
  if (this->Controller == controller)
  {
    return;
  }
  if (this->Controller)
  {
    this->Controller->UnRegister(this);
  }
  this->Controller = controller;
  if (controller)
  {
    controller->Register(this);
  }
  this->Modified();
}

//------------------------------------------------------------------------------
int vtkRGVolumeReader::ChooseScalarType(bool integral, double lo, double hi, bool wide)
{
  if (integral && lo >= VTK_SHORT_MIN && hi <= VTK_SHORT_MAX)
  {
    return VTK_SHORT;
  }
  return wide ? VTK_DOUBLE : VTK_FLOAT;
}

//------------------------------------------------------------------------------
void vtkRGVolumeReader::Store(
  vtkDataArray* scalars, vtkIdType at, const double* values, std::size_t count)
{
  // Every value is exact in the output type (ChooseScalarType), so a plain conversion is exact.
  switch (scalars->GetDataType())
  {
    vtkTemplateMacro(
      std::transform(values, values + count, static_cast<VTK_TT*>(scalars->GetVoidPointer(0)) + at,
        [](double v) { return static_cast<VTK_TT>(v); }));
  }
}

//------------------------------------------------------------------------------
int vtkRGVolumeReader::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  rgmc::RunController controller(this->Controller);
  rgmc::Ranks ranks(controller);

  // PASS 1: the header scan, on rank 0, only when a property changed since the last one. Every
  // rank takes the same branch: they all saw the same property changes.
  if (this->GetMTime() > this->ScanTime || this->OutputScalarType == 0)
  {
    this->OutputScalarType = 0;
    std::vector<vtkIdType> header;
    std::string message;
    bool ok = true;
    if (ranks.Rank == 0)
    {
      if (!this->FileName || !*this->FileName)
      {
        ok = false;
        message = "no file name is set";
      }
      else
      {
        try
        {
          ok = this->Scan(header, message);
        }
        catch (const std::exception& e)
        {
          ok = false;
          message = std::string(this->FileName) + ": " + e.what();
        }
      }
    }
    if (!ranks.Agree(ok, message))
    {
      vtkErrorMacro(<< "Cannot read " << (this->FileName ? this->FileName : "(no file name)")
                    << ": " << message);
      return 0;
    }
    // PASS 2: every rank learns the slice list and geometry from rank 0.
    ranks.Broadcast(header, 0);
    this->Warnings.clear();
    if (!this->Parse(header, message))
    {
      // The same header gives the same result on every rank: no agreement needed.
      vtkErrorMacro(<< "Cannot read " << this->FileName << ": " << message);
      return 0;
    }
    std::istringstream warnings(this->Warnings);
    for (std::string line; std::getline(warnings, line);)
    {
      vtkWarningMacro(<< line);
    }
    this->ScanTime.Modified();
  }

  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  const int whole[6] = { 0, this->Dimensions[0] - 1, 0, this->Dimensions[1] - 1, 0,
    this->Dimensions[2] - 1 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
  outInfo->Set(vtkDataObject::SPACING(), this->Spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), this->Origin, 3);
  outInfo->Set(vtkDataObject::DIRECTION(), this->Direction, 9);
  vtkDataObject::SetPointDataActiveScalarInfo(
    outInfo, this->OutputScalarType, this->NumberOfComponents);
  // Pieces are slabs of whole slices, so that a rank reads only the files (or the bytes) of its
  // slices; the reader splits the volume itself (rgmc::SlabPiece says why).
  outInfo->Remove(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT());
  outInfo->Set(vtkAlgorithm::CAN_HANDLE_PIECE_REQUEST(), 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkRGVolumeReader::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  rgmc::RunController controller(this->Controller);
  rgmc::Ranks ranks(controller);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkImageData* output = vtkImageData::GetData(outInfo);

  int extent[6] = { 0, -1, 0, -1, 0, -1 }, owned[6] = { 0, -1, 0, -1, 0, -1 };
  const int whole[6] = { 0, this->Dimensions[0] - 1, 0, this->Dimensions[1] - 1, 0,
    this->Dimensions[2] - 1 };
  const bool empty = !rgmc::SlabPiece(outInfo, whole, extent, owned);
  if (this->OutputScalarType == 0)
  {
    // The header scan failed on every rank (its status was agreed): no collective here, since
    // the pipeline may not call this on the ranks whose piece is then empty.
    output->Initialize();
    vtkErrorMacro(<< "Cannot read " << (this->FileName ? this->FileName : "(no file name)")
                  << ": its header was not read (see the error before).");
    return 0;
  }
  std::string message;
  bool ok = true;
  // The piece read last, when nothing has changed since: ParaView reads a piece without ghost
  // layers first and asks again with them once a filter needs them (RG Marching Cubes does), so
  // the slices the two share are copied instead of read and decoded again. Until the new piece
  // is complete both are in memory.
  vtkSmartPointer<vtkDataArray> previous;
  if (this->ReadTime > this->GetMTime() && this->ReadTime > this->ScanTime)
  {
    previous = this->LastPiece;
  }
  this->LastPiece = nullptr;
  vtkSmartPointer<vtkDataArray> scalars;
  output->Initialize();
  output->SetSpacing(this->Spacing);
  output->SetOrigin(this->Origin);
  output->SetDirectionMatrix(this->Direction);
  if (!empty)
  {
    output->SetExtent(extent);
    scalars.TakeReference(vtkDataArray::CreateDataArray(this->OutputScalarType));
    scalars->SetName(this->ArrayName.c_str());
    scalars->SetNumberOfComponents(this->NumberOfComponents);
    scalars->SetNumberOfTuples(output->GetNumberOfPoints());
    try
    {
      ok = this->ReadReusing(extent, scalars, previous, this->LastExtent, message);
    }
    catch (const std::exception& e)
    {
      ok = false;
      message = std::string(this->FileName) + ": " + e.what();
    }
  }
  // A rank's read error (a truncated or undecodable file in its slab) fails every rank.
  if (!ranks.Agree(ok, message))
  {
    output->Initialize();
    vtkErrorMacro(<< "Cannot read " << (this->FileName ? this->FileName : "(no file name)") << ": "
                  << message);
    return 0;
  }
  if (!empty)
  {
    this->LastPiece = scalars;
    std::copy(extent, extent + 6, this->LastExtent);
    this->ReadTime.Modified();
    rgmc::CacheRanges(scalars);
    output->GetPointData()->SetScalars(scalars);
    // Mark the ghost layers the pipeline asked for, as ParaView's image sources do, so that
    // filters know which cells this rank owns.
    rgmc::MarkGhosts(output, owned);
  }
  return 1;
}

//------------------------------------------------------------------------------
bool vtkRGVolumeReader::ReadReusing(const int extent[6], vtkDataArray* scalars,
  vtkDataArray* previous, const int previousExtent[6], std::string& message)
{
  int lo, hi;
  if (!previous || previous->GetDataType() != scalars->GetDataType() ||
    previous->GetNumberOfComponents() != scalars->GetNumberOfComponents() ||
    !rgmc::SharedSlices(extent, previousExtent, lo, hi))
  {
    return this->ReadExtent(extent, scalars, message);
  }
  const vtkIdType slicePoints =
    vtkIdType(extent[1] - extent[0] + 1) * vtkIdType(extent[3] - extent[2] + 1);
  const std::size_t sliceBytes = static_cast<std::size_t>(slicePoints) *
    static_cast<std::size_t>(scalars->GetNumberOfComponents() * scalars->GetDataTypeSize());
  auto* to = static_cast<unsigned char*>(scalars->GetVoidPointer(0));
  const auto* from = static_cast<const unsigned char*>(previous->GetVoidPointer(0));
  std::memcpy(to + (lo - extent[4]) * sliceBytes, from + (lo - previousExtent[4]) * sliceBytes,
    static_cast<std::size_t>(hi - lo + 1) * sliceBytes);
  // The slices before and after the shared ones, each run read on its own and copied in.
  const int runs[2][2] = { { extent[4], lo - 1 }, { hi + 1, extent[5] } };
  for (const auto& run : runs)
  {
    if (run[0] > run[1])
    {
      continue;
    }
    const int part[6] = { extent[0], extent[1], extent[2], extent[3], run[0], run[1] };
    vtkSmartPointer<vtkDataArray> read;
    read.TakeReference(vtkDataArray::CreateDataArray(scalars->GetDataType()));
    read->SetNumberOfComponents(scalars->GetNumberOfComponents());
    read->SetNumberOfTuples(slicePoints * (run[1] - run[0] + 1));
    if (!this->ReadExtent(part, read, message))
    {
      return false;
    }
    std::memcpy(to + (run[0] - extent[4]) * sliceBytes, read->GetVoidPointer(0),
      static_cast<std::size_t>(run[1] - run[0] + 1) * sliceBytes);
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkRGVolumeReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
  os << indent << "Dimensions: " << this->Dimensions[0] << " " << this->Dimensions[1] << " "
     << this->Dimensions[2] << "\n";
  os << indent << "Origin: " << this->Origin[0] << " " << this->Origin[1] << " " << this->Origin[2]
     << "\n";
  os << indent << "Spacing: " << this->Spacing[0] << " " << this->Spacing[1] << " "
     << this->Spacing[2] << "\n";
  os << indent << "Direction:";
  for (double d : this->Direction)
  {
    os << " " << d;
  }
  os << "\n";
  os << indent << "OutputScalarType: " << this->OutputScalarType << "\n";
  os << indent << "NumberOfComponents: " << this->NumberOfComponents << "\n";
  os << indent << "ArrayName: " << this->ArrayName << "\n";
  os << indent << "Summary: " << this->Summary << "\n";
  os << indent << "Warnings: " << this->Warnings << "\n";
}

//------------------------------------------------------------------------------
void vtkRGVolumeReader::PackGeometry(rgmc::MessageWriter& p, const int dimensions[3],
  const double spacing[3], const double origin[3], const double direction[9], int scalarType)
{
  for (int a = 0; a < 3; ++a)
  {
    p.Int(dimensions[a]);
  }
  for (int a = 0; a < 3; ++a)
  {
    p.Real(spacing[a]);
  }
  for (int a = 0; a < 3; ++a)
  {
    p.Real(origin[a]);
  }
  for (int i = 0; i < 9; ++i)
  {
    p.Real(direction[i]);
  }
  p.Int(scalarType);
}

//------------------------------------------------------------------------------
void vtkRGVolumeReader::UnpackGeometry(rgmc::MessageReader& u)
{
  for (int a = 0; a < 3; ++a)
  {
    this->Dimensions[a] = static_cast<int>(u.Int());
  }
  for (int a = 0; a < 3; ++a)
  {
    this->Spacing[a] = u.Real();
  }
  for (int a = 0; a < 3; ++a)
  {
    this->Origin[a] = u.Real();
  }
  for (double& d : this->Direction)
  {
    d = u.Real();
  }
  this->OutputScalarType = static_cast<int>(u.Int());
}
