// Threads within one rank for the plugin's VTK classes (private to the module): vtkSMPTools, so
// that ParaView's and VTK's settings govern them (VTK_SMP_BACKEND_IN_USE, VTK_SMP_MAX_THREADS),
// with an exception thrown on a worker thread (std::bad_alloc) carried back to the calling
// thread instead of terminating the process.
#ifndef vtkRGThreads_h
#define vtkRGThreads_h

#include "vtkSMPTools.h"
#include "vtkType.h"

#include <atomic>
#include <exception>
#include <mutex>

namespace rgmc
{

/// Calls body(begin, end) over ranges covering [0, count) exactly once, on vtkSMPTools'
/// threads, `grain` indices or more at a time. The first exception a range throws stops the
/// ranges not yet started and is thrown again here. Results must not depend on the ranges.
template <typename Body>
void ParallelFor(vtkIdType count, vtkIdType grain, Body&& body)
{
  std::exception_ptr failure;
  std::mutex failureMutex;
  std::atomic<bool> failed{ false };
  vtkSMPTools::For(vtkIdType(0), count, grain,
    [&](vtkIdType begin, vtkIdType end)
    {
      if (failed)
      {
        return;
      }
      try
      {
        body(begin, end);
      }
      catch (...)
      {
        std::lock_guard<std::mutex> lock(failureMutex);
        if (!failure)
        {
          failure = std::current_exception();
        }
        failed = true;
      }
    });
  if (failure)
  {
    std::rethrow_exception(failure);
  }
}

} // namespace rgmc

#endif
