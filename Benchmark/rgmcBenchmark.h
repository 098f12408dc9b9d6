// What the benchmark programs share: a clock, and this process's memory from /proc/self/status.
#ifndef rgmcBenchmark_h
#define rgmcBenchmark_h

#include "rgmcTestData.h" // ProcessStatusKiB

#include <chrono>

namespace rgmc_benchmark
{

/// Seconds on a steady clock.
inline double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// A line of /proc/self/status in MiB (VmHWM: the peak resident set; VmRSS: the current one).
inline double StatusMiB(const char* field)
{
  return rgmc_test::ProcessStatusKiB(field) / 1024.0;
}

} // namespace rgmc_benchmark

#endif
