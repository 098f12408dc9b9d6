// The cores a test process sees. VTK's STDThread backend never runs more threads than
// std::thread::hardware_concurrency(), which asks glibc's get_nprocs(): on a 2-core machine
// vtkSMPTools::Initialize(64) gives 2 threads. The thread tests must run 16 and 64 (what a
// workstation gives a rank), so every test executable defines get_nprocs itself (the executable's
// definition comes first in the dynamic linker's lookup, for libstdc++ too) and answers
// RGMC_TEST_CORES when it is set (rgmc_test::AllowThreads sets it), the real count otherwise.
#include <cstdlib>
#include <dlfcn.h>

extern "C" int get_nprocs()
{
  if (const char* cores = std::getenv("RGMC_TEST_CORES"))
  {
    const int n = std::atoi(cores);
    if (n > 0)
    {
      return n;
    }
  }
  using Function = int (*)();
  static const Function real = reinterpret_cast<Function>(dlsym(RTLD_NEXT, "get_nprocs"));
  return real ? real() : 1;
}
