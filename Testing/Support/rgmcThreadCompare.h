// Threads in the tests: a test run with `--threads N` updates the project's filters under
// vtkSMPTools with the STDThread backend and N threads, and also with 1 thread, and checks that
// the two outputs are bitwise identical (every array of the output, in order), as is the output
// of a run under the work/span profile (vtkRGSpan.h); its own checks then run on the N-thread
// output. Without --threads, filters update as configured.
#ifndef rgmcThreadCompare_h
#define rgmcThreadCompare_h

#include "rgmcCheck.h"
#include "vtkRGSpan.h"

#include "vtkAbstractArray.h"
#include "vtkAlgorithm.h"
#include "vtkAlgorithmOutput.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataObject.h"
#include "vtkDataSetAttributes.h"
#include "vtkFieldData.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"

#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>

namespace rgmc_test
{

/// The thread count of this run (1 unless --threads N was given).
inline int& ThreadCount()
{
  static int threads = 1;
  return threads;
}

/// The threads vtkSMPTools runs when asked for `threads` of STDThread.
inline int ThreadsGiven(int threads)
{
  int given = 0;
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
    [&]() { given = vtkSMPTools::GetEstimatedNumberOfThreads(); });
  return given;
}

/// Lets vtkSMPTools run up to `threads` threads however many cores this machine has (see
/// rgmcTestCores.cxx), and checks that it does.
inline void AllowThreads(int threads)
{
  ::setenv("RGMC_TEST_CORES", std::to_string(threads).c_str(), 1);
  const int given = ThreadsGiven(threads);
  RGMC_CHECK(given == threads,
    "vtkSMPTools runs " << given << " threads when asked for " << threads
                        << " (is rgmcTestCores.cxx linked into the test?)");
}

/// Takes `--threads N` out of the arguments, and lets vtkSMPTools run N threads.
inline void ParseThreads(int& argc, char** argv)
{
  for (int a = 1; a + 1 < argc; ++a)
  {
    if (std::string(argv[a]) == "--threads")
    {
      ThreadCount() = std::atoi(argv[a + 1]);
      AllowThreads(ThreadCount());
      for (int b = a; b + 2 <= argc; ++b)
      {
        argv[b] = argv[b + 2];
      }
      argc -= 2;
      return;
    }
  }
}

/// Whether two arrays hold the same bytes (same type, tuples and components).
inline bool SameBits(vtkAbstractArray* a, vtkAbstractArray* b)
{
  if (!a || !b) // no array and an empty array are the same
  {
    return (!a || a->GetNumberOfTuples() == 0) && (!b || b->GetNumberOfTuples() == 0);
  }
  if (a->GetDataType() != b->GetDataType() || a->GetNumberOfTuples() != b->GetNumberOfTuples() ||
    a->GetNumberOfComponents() != b->GetNumberOfComponents())
  {
    return false;
  }
  const vtkIdType bytes = a->GetNumberOfValues() * a->GetDataTypeSize();
  return bytes == 0 || std::memcmp(a->GetVoidPointer(0), b->GetVoidPointer(0), bytes) == 0;
}

inline std::string DifferentArray(vtkFieldData* a, vtkFieldData* b, const char* where)
{
  if (a->GetNumberOfArrays() != b->GetNumberOfArrays())
  {
    return std::string("the number of ") + where + " arrays";
  }
  for (int i = 0; i < a->GetNumberOfArrays(); ++i)
  {
    vtkAbstractArray* x = a->GetAbstractArray(i);
    vtkAbstractArray* y = x->GetName() ? b->GetAbstractArray(x->GetName()) : b->GetAbstractArray(i);
    if (!SameBits(x, y))
    {
      return std::string(where) + " array " + (x->GetName() ? x->GetName() : "(unnamed)");
    }
  }
  return std::string();
}

/// What differs between two outputs ("" when bitwise the same).
inline std::string Difference(vtkDataObject* a, vtkDataObject* b)
{
  vtkPolyData* pa = vtkPolyData::SafeDownCast(a);
  vtkPolyData* pb = vtkPolyData::SafeDownCast(b);
  if (!pa || !pb)
  {
    return pa == pb ? "" : "the output type";
  }
  if (!SameBits(pa->GetPoints() ? pa->GetPoints()->GetData() : nullptr,
        pb->GetPoints() ? pb->GetPoints()->GetData() : nullptr))
  {
    return "the points";
  }
  if (!SameBits(pa->GetPolys()->GetConnectivityArray(), pb->GetPolys()->GetConnectivityArray()) ||
    !SameBits(pa->GetPolys()->GetOffsetsArray(), pb->GetPolys()->GetOffsetsArray()))
  {
    return "the triangles";
  }
  std::string d = DifferentArray(pa->GetPointData(), pb->GetPointData(), "point");
  if (d.empty())
  {
    d = DifferentArray(pa->GetCellData(), pb->GetCellData(), "cell");
  }
  if (d.empty())
  {
    d = DifferentArray(pa->GetFieldData(), pb->GetFieldData(), "field");
  }
  return d;
}

/// Marks `algorithm` and everything upstream of it modified, so that all of it runs again.
inline void ModifiedUpstream(vtkAlgorithm* algorithm)
{
  algorithm->Modified();
  for (int port = 0; port < algorithm->GetNumberOfInputPorts(); ++port)
  {
    for (int c = 0; c < algorithm->GetNumberOfInputConnections(port); ++c)
    {
      ModifiedUpstream(algorithm->GetInputConnection(port, c)->GetProducer());
    }
  }
}

/// Updates `algorithm` (its output port 0) at ThreadCount() threads; with more than 1, first
/// on 1 thread, and checks that both outputs are bitwise identical. `what` names the case;
/// `between` runs between the two updates (to forget the first run's messages).
inline void UpdateAtThreads(
  vtkAlgorithm* algorithm, const std::string& what, const std::function<void()>& between = nullptr)
{
  const int threads = ThreadCount();
  if (threads <= 1)
  {
    algorithm->Update();
    return;
  }
  vtkSmartPointer<vtkDataObject> single;
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ 1, "STDThread", false },
    [&]()
    {
      ModifiedUpstream(algorithm);
      algorithm->Update();
      single.TakeReference(algorithm->GetOutputDataObject(0)->NewInstance());
      single->DeepCopy(algorithm->GetOutputDataObject(0));
    });
  // The work/span profile's run takes the paths of several threads, its tasks one by one: the
  // same output, so that the profile measures the computation the threads do.
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ 1, "STDThread", false },
    [&]()
    {
      if (between)
      {
        between();
      }
      rgmc::SpanRecorder recorder;
      ModifiedUpstream(algorithm);
      recorder.Start();
      algorithm->Update();
      recorder.Stop();
    });
  const std::string profiled = Difference(single, algorithm->GetOutputDataObject(0));
  RGMC_CHECK(profiled.empty(),
    what << ": " << profiled << " differ between 1 thread and the work/span profile's run");
  if (between)
  {
    between();
  }
  int given = 0;
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
    [&]()
    {
      given = vtkSMPTools::GetEstimatedNumberOfThreads();
      ModifiedUpstream(algorithm);
      algorithm->Update();
    });
  RGMC_CHECK(
    given == threads, what << ": vtkSMPTools ran " << given << " threads, not " << threads);
  const std::string d = Difference(single, algorithm->GetOutputDataObject(0));
  RGMC_CHECK(d.empty(), what << ": " << d << " differ between 1 and " << threads << " threads");
}

} // namespace rgmc_test

#endif
