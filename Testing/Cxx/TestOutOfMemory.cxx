// Running out of memory, on 1 rank (vtkDummyController) and under mpiexec: extraction, Seam Repair
// and the merged writer under an address-space limit (setrlimit(RLIMIT_AS)) on the last rank.
// Every run either gives the unlimited run's result or an error on every rank that says memory
// ran out, with an empty output and no file: never a crash, a hang, or a partial result.
//
// For each stage in turn, the limit is set when the stage starts, from just above the memory in
// use to more than the stage needs, so that allocations fail at different points of each stage
// (the test prints which stage failed at each limit, and requires a failure in every stage and a
// complete run once the limit is high enough). With --seeded, the extraction runs in Seeded mode
// (its growth in rounds between the ranks) and only its stage is swept. Not built with the
// sanitizers: AddressSanitizer
// reserves terabytes of address space, so an address-space limit cannot work there.
#include "rgmcCheck.h"
#include "rgmcDistributedData.h" // GyroidPiece, SameOnAllRanks
#include "rgmcTestController.h"
#include "rgmcTestData.h" // MakeImage, MarkGhostCells, MessageCatcher

#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkPolyData.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGMergedSurfaceWriter.h"
#include "vtkRGSeamRepair.h"

#include <malloc.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

namespace
{

/// A "Vm..." line of /proc/self/status in bytes.
long long StatusBytes(const char* field)
{
  return rgmc_test::ProcessStatusKiB(field) * 1024;
}

/// What one run of the job gave on this rank.
struct Run
{
  int FailedStage = 0; // 0: none; 1 extraction, 2 Seam Repair, 3 writer (agreed over ranks)
  std::string Errors;  // this rank's error messages
  long long Triangles = 0, UniquePoints = 0, Cells = 0;
  bool File = false;
  long long Peak[3] = { 0, 0, 0 }; // this rank's VmPeak after each stage
};

/// Runs the job; the last rank's address space is limited from the start of stage `limitStage`
/// (0: never) to `headroom` bytes beyond what it uses then.
Run RunJob(vtkMultiProcessController* controller, vtkImageData* volume, const std::string& file,
  bool seeded, int limitStage = 0, long long headroom = 0)
{
  const int ranks = controller->GetNumberOfProcesses();
  const bool limited = controller->GetLocalProcessId() == ranks - 1;
  struct rlimit saved;
  ::getrlimit(RLIMIT_AS, &saved);
  // The heap keeps what earlier runs freed: small blocks would come from there, not from new
  // address space, and the limit would not bind (measured on Debian sid, whose extraction and
  // writer then never failed). So the free heap is filled first (a balloon of small blocks,
  // freed after the run), and a stage's every allocation needs address space under the limit.
  std::vector<void*> balloon;
  auto limit = [&](int stage)
  {
    if (limited && stage == limitStage)
    {
      // Free chunks inside the heap (not its top, which grows the address space when used).
      auto loose = []()
      {
        const struct mallinfo2 m = mallinfo2();
        return m.fordblks - m.keepcost;
      };
      for (std::size_t block = 64 * 1024; block >= 64;)
      {
        const std::size_t before = loose();
        void* p = std::malloc(block);
        if (p && loose() < before)
        {
          balloon.push_back(p); // filled a hole
          continue;
        }
        std::free(p); // no hole of this size left: smaller blocks
        block /= 2;
      }
      struct rlimit l = saved;
      l.rlim_cur = static_cast<rlim_t>(StatusBytes("VmSize:") + headroom);
      ::setrlimit(RLIMIT_AS, &l);
    }
  };
  struct Restore
  {
    bool Limited;
    struct rlimit Saved;
    std::vector<void*>& Balloon;
    ~Restore()
    {
      if (this->Limited)
      {
        ::setrlimit(RLIMIT_AS, &this->Saved);
      }
      for (void* p : this->Balloon)
      {
        std::free(p);
      }
    }
  } restore{ limited, saved, balloon };
  Run run;
  auto agreed = [&](rgmc_test::MessageCatcher* catcher, int stage)
  {
    // Either every rank failed or none did; the errors must say why.
    int failed = catcher->Errors.empty() ? 0 : 1, sum = 0;
    controller->AllReduce(&failed, &sum, 1, vtkCommunicator::SUM_OP);
    RGMC_CHECK(sum == 0 || sum == ranks,
      "stage " << stage << " failed on " << sum << " of " << ranks
               << " ranks: " << catcher->Errors);
    if (sum > 0)
    {
      run.FailedStage = stage;
      run.Errors = catcher->Errors;
      RGMC_CHECK(catcher->Errors.find("memory") != std::string::npos,
        "stage " << stage << ": the error does not say memory ran out: " << catcher->Errors);
    }
    run.Peak[stage - 1] = StatusBytes("VmPeak:");
    return sum == 0;
  };

  vtkNew<rgmc_test::MessageCatcher> extractErrors, repairErrors, writerErrors;
  vtkNew<vtkRGMarchingCubes> extract;
  extractErrors->Watch(extract);
  extract->SetController(controller);
  extract->SetInputData(volume);
  extract->SetIsovalue(0.0);
  if (seeded)
  {
    extract->SetExtractionMode(vtkRGMarchingCubes::SEEDED);
    extract->AddSeedPoint(48.3, 48.1, 47.9);
  }
  else
  {
    extract->SetExtractionMode(vtkRGMarchingCubes::ALL_COMPONENTS);
  }
  limit(1);
  extract->Update();
  run.Cells = extract->GetOutput()->GetNumberOfCells();
  if (!agreed(extractErrors, 1))
  {
    return run;
  }
  vtkNew<vtkRGSeamRepair> repair;
  repairErrors->Watch(repair);
  repair->SetController(controller);
  repair->SetInputData(extract->GetOutput());
  repair->SetSmoothingMethod(vtkRGSeamRepair::LAPLACIAN);
  repair->SetNumberOfIterations(5);
  limit(2);
  repair->Update();
  run.Cells = repair->GetOutput()->GetNumberOfCells();
  if (!agreed(repairErrors, 2))
  {
    return run;
  }
  auto count = [&](const char* name)
  {
    vtkIdTypeArray* a =
      vtkIdTypeArray::SafeDownCast(repair->GetOutput()->GetFieldData()->GetArray(name));
    return a ? static_cast<long long>(a->GetValue(0)) : -1LL;
  };
  run.Triangles = count("Triangles");
  run.UniquePoints = count("UniquePoints");
  vtkNew<vtkRGMergedSurfaceWriter> writer;
  writerErrors->Watch(writer);
  writer->SetController(controller);
  writer->SetInputData(repair->GetOutput());
  writer->SetFileName(file.c_str());
  limit(3);
  writer->Write();
  controller->Barrier();
  struct stat s;
  run.File = ::stat(file.c_str(), &s) == 0;
  agreed(writerErrors, 3);
  return run;
}

} // namespace

int main(int argc, char* argv[])
{
  // Large blocks always from mmap and back to the system when freed (a fixed threshold: glibc
  // otherwise raises it as blocks are freed), so that a stage's large buffers always need new
  // address space, rather than heap left free by an earlier stage.
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  mallopt(M_TRIM_THRESHOLD, 128 * 1024);
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  bool seeded = false;
  for (int a = 1; a < argc; ++a)
  {
    seeded = seeded || std::string(argv[a]) == "--seeded";
  }
  const std::string file =
    "TestOutOfMemory-" + std::string(seeded ? "seeded-" : "") + std::to_string(ranks) + ".ply";

  // This rank's piece of a gyroid (one surface through the whole volume, on every seam).
  vtkSmartPointer<vtkImageData> volume = rgmc_test::GyroidPiece(96, 12.0, rank, ranks);

  // The unlimited run: the expected result, and how much address space each stage needs.
  const long long base = StatusBytes("VmSize:");
  const Run reference = RunJob(controller, volume, file, seeded);
  RGMC_CHECK(reference.FailedStage == 0 && reference.File && reference.Triangles > 0,
    "the unlimited run failed: " << reference.Errors);
  ::unlink(file.c_str());
  long long growth = reference.Peak[2] - base, growthMax = 0;
  controller->AllReduce(&growth, &growthMax, 1, vtkCommunicator::MAX_OP);
  if (rank == 0)
  {
    std::cout << "unlimited: " << reference.Triangles << " triangles, " << reference.UniquePoints
              << " unique points; the job's address space grows by up to " << (growthMax >> 20)
              << " MiB on a rank\n";
  }

  // The sweep: from each stage on, the last rank may grow by `headroom` beyond what it uses when
  // the stage starts.
  for (int stage = 1; stage <= (seeded ? 1 : 3); ++stage)
  {
    int failedHere = 0, complete = 0;
    for (long long headroom = 0; !complete; headroom = headroom ? headroom * 3 / 2 : 256 << 10)
    {
      const Run run = RunJob(controller, volume, file, seeded, stage, headroom);
      if (rank == 0)
      {
        std::cout << "limit from stage " << stage << ", headroom " << (headroom >> 10) << " KiB: "
                  << (run.FailedStage == 0
                         ? std::string("complete")
                         : "stage " + std::to_string(run.FailedStage) + " failed: " +
                           run.Errors.substr(run.Errors.find("): ") + 3,
                             run.Errors.find('\n', run.Errors.find("): ")) -
                               run.Errors.find("): ") - 3))
                  << "\n";
      }
      failedHere += run.FailedStage == stage;
      complete = run.FailedStage == 0;
      RGMC_CHECK(run.FailedStage == 0 || run.FailedStage >= stage,
        "stage " << run.FailedStage << " failed before the limit was set");
      if (run.FailedStage == 0)
      {
        RGMC_CHECK(
          run.Triangles == reference.Triangles && run.UniquePoints == reference.UniquePoints,
          "headroom " << headroom << ": " << run.Triangles << " triangles, " << run.UniquePoints
                      << " unique points instead of " << reference.Triangles << ", "
                      << reference.UniquePoints);
        RGMC_CHECK(run.File, "headroom " << headroom << ": no file");
      }
      else
      {
        RGMC_CHECK(run.Cells == 0 || run.FailedStage == 3,
          "headroom " << headroom << ": stage " << run.FailedStage << " failed but its output has "
                      << run.Cells << " cells");
        RGMC_CHECK(
          rgmc_test::SameOnAllRanks(controller, run.Errors.substr(run.Errors.find("): ") + 1)),
          "headroom " << headroom << ": the ranks' messages differ");
        RGMC_CHECK(!run.File, "headroom " << headroom << ": a failed run left its file");
      }
      ::unlink(file.c_str());
      controller->Barrier();
      if (headroom > 4 * growthMax + (256 << 20))
      {
        RGMC_CHECK(false, "stage " << stage << " never completed under a limit");
        break;
      }
    }
    RGMC_CHECK(failedHere > 0, "no allocation failed in stage " << stage);
  }
  return rgmc_test::Finish(controller, seeded ? "TestOutOfMemory --seeded" : "TestOutOfMemory");
}
