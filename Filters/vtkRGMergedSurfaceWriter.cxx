// Writes a distributed surface as one mesh: gathered on the first rank, points merged by
// global id.
#include "vtkRGMergedSurfaceWriter.h"

#include "vtkRGCollective.h"

#include "vtkAppendPolyData.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDummyController.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPLYWriter.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSTLWriter.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkXMLPolyDataWriter.h"

#include <string>
#include <unordered_map>

vtkStandardNewMacro(vtkRGMergedSurfaceWriter);
vtkCxxSetObjectMacro(vtkRGMergedSurfaceWriter, Controller, vtkMultiProcessController);

//------------------------------------------------------------------------------
vtkRGMergedSurfaceWriter::vtkRGMergedSurfaceWriter()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

//------------------------------------------------------------------------------
vtkRGMergedSurfaceWriter::~vtkRGMergedSurfaceWriter()
{
  this->SetFileName(nullptr);
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------
int vtkRGMergedSurfaceWriter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  return 1;
}

//------------------------------------------------------------------------------
vtkTypeBool vtkRGMergedSurfaceWriter::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (request->Has(vtkStreamingDemandDrivenPipeline::REQUEST_UPDATE_EXTENT()) && this->Controller)
  {
    // Each rank writes its own piece into the gathered file.
    vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(),
      this->Controller->GetLocalProcessId());
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(),
      this->Controller->GetNumberOfProcesses());
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
    return 1;
  }
  return this->Superclass::ProcessRequest(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkPolyData> vtkRGMergedSurfaceWriter::Merge(
  const std::vector<vtkSmartPointer<vtkDataObject>>& pieces)
{
  vtkNew<vtkAppendPolyData> append;
  bool keyed = true;
  int inputs = 0;
  for (const auto& piece : pieces)
  {
    vtkPolyData* pd = vtkPolyData::SafeDownCast(piece);
    if (pd && pd->GetNumberOfPoints() > 0)
    {
      keyed = keyed && vtkIdTypeArray::SafeDownCast(pd->GetPointData()->GetGlobalIds()) != nullptr;
      append->AddInputData(pd);
      ++inputs;
    }
  }
  auto merged = vtkSmartPointer<vtkPolyData>::New();
  if (inputs == 0)
  {
    return merged;
  }
  append->Update();
  vtkPolyData* all = append->GetOutput();
  vtkIdTypeArray* ids = vtkIdTypeArray::SafeDownCast(all->GetPointData()->GetGlobalIds());
  if (!keyed || !ids)
  {
    merged->ShallowCopy(all);
    return merged;
  }
  // One point per global id: the first copy.
  const vtkIdType n = all->GetNumberOfPoints();
  std::unordered_map<vtkIdType, vtkIdType> first;
  first.reserve(static_cast<std::size_t>(n));
  std::vector<vtkIdType> newId(static_cast<std::size_t>(n));
  std::vector<vtkIdType> kept;
  for (vtkIdType p = 0; p < n; ++p)
  {
    auto inserted = first.emplace(ids->GetValue(p), static_cast<vtkIdType>(kept.size()));
    if (inserted.second)
    {
      kept.push_back(p);
    }
    newId[p] = inserted.first->second;
  }
  vtkNew<vtkPoints> points;
  points->SetDataType(all->GetPoints()->GetDataType());
  points->SetNumberOfPoints(static_cast<vtkIdType>(kept.size()));
  vtkPointData* pd = merged->GetPointData();
  pd->CopyAllocate(all->GetPointData(), static_cast<vtkIdType>(kept.size()));
  for (vtkIdType k = 0; k < static_cast<vtkIdType>(kept.size()); ++k)
  {
    points->SetPoint(k, all->GetPoint(kept[k]));
    pd->CopyData(all->GetPointData(), kept[k], k);
  }
  pd->RemoveArray(vtkDataSetAttributes::GhostArrayName()); // one file has no duplicates
  vtkNew<vtkCellArray> polys;
  vtkCellArray* in = all->GetPolys();
  polys->AllocateExact(in->GetNumberOfCells(), in->GetNumberOfConnectivityIds());
  vtkIdType npts;
  const vtkIdType* pts;
  std::vector<vtkIdType> cell;
  for (in->InitTraversal(); in->GetNextCell(npts, pts);)
  {
    cell.assign(pts, pts + npts);
    for (vtkIdType& id : cell)
    {
      id = newId[id];
    }
    polys->InsertNextCell(npts, cell.data());
  }
  merged->SetPoints(points);
  merged->SetPolys(polys);
  merged->GetCellData()->ShallowCopy(all->GetCellData());
  return merged;
}

//------------------------------------------------------------------------------
void vtkRGMergedSurfaceWriter::WriteData()
{
  vtkNew<vtkDummyController> single;
  rgmc::Ranks ranks(this->Controller ? this->Controller : single.Get());
  vtkPolyData* input = vtkPolyData::SafeDownCast(this->GetInput());

  std::string problem;
  const std::string name = this->FileName ? this->FileName : "";
  const std::size_t dot = name.find_last_of('.');
  const std::string extension = dot == std::string::npos ? "" : name.substr(dot + 1);
  if (name.empty())
  {
    problem = "no file name is set";
  }
  else if (extension != "stl" && extension != "ply" && extension != "vtp")
  {
    problem = "the file name " + name + " must end in .stl, .ply or .vtp";
  }
  if (!ranks.Agree(problem.empty(), problem))
  {
    vtkErrorMacro(<< "Cannot write the surface: " << problem << ".");
    this->SetErrorCode(1);
    return;
  }

  std::vector<vtkSmartPointer<vtkDataObject>> pieces;
  vtkNew<vtkPolyData> mine;
  if (input)
  {
    mine->ShallowCopy(input);
  }
  ranks.C->Gather(mine, pieces, 0);
  bool ok = true;
  if (ranks.Rank == 0)
  {
    vtkSmartPointer<vtkPolyData> merged = Merge(pieces);
    if (extension == "stl")
    {
      vtkNew<vtkSTLWriter> stl;
      stl->SetFileType(this->FileType);
      stl->SetFileName(name.c_str());
      stl->SetInputData(merged);
      ok = stl->Write() != 0 && stl->GetErrorCode() == 0;
    }
    else if (extension == "ply")
    {
      vtkNew<vtkPLYWriter> ply;
      ply->SetFileType(this->FileType);
      ply->SetFileName(name.c_str());
      ply->SetInputData(merged);
      ok = ply->Write() != 0 && ply->GetErrorCode() == 0;
    }
    else
    {
      vtkNew<vtkXMLPolyDataWriter> vtp;
      if (this->FileType == VTK_ASCII)
      {
        vtp->SetDataModeToAscii();
      }
      else
      {
        vtp->SetDataModeToBinary(); // inline: appended data does not load on Debian 12
      }
      vtp->SetFileName(name.c_str());
      vtp->SetInputData(merged);
      ok = vtp->Write() != 0 && vtp->GetErrorCode() == 0;
    }
    if (!ok)
    {
      problem = "could not write " + name;
    }
  }
  if (!ranks.Agree(ok, problem))
  {
    vtkErrorMacro(<< "Cannot write the surface: " << problem << ".");
    this->SetErrorCode(1);
  }
}

//------------------------------------------------------------------------------
void vtkRGMergedSurfaceWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "FileType: " << this->FileType << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
}
