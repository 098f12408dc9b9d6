// What the benchmark programs share: a clock, and this process's memory from /proc/self/status.
#ifndef rgmcBenchmark_h
#define rgmcBenchmark_h

#include "rgmcTestData.h" // ProcessStatusKiB

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace rgmc_benchmark
{

/// Seconds on a steady clock.
inline double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// The smallest of `repeats` wall times of `run`.
template <typename Run>
double Fastest(int repeats, Run&& run)
{
  double best = 1e300;
  for (int r = 0; r < repeats; ++r)
  {
    const double start = Now();
    run();
    best = std::min(best, Now() - start);
  }
  return best;
}

/// The smallest of `repeats` wall times of a VTK algorithm's update (made to run every time).
template <typename Algorithm>
double FastestUpdate(int repeats, Algorithm* algorithm)
{
  return Fastest(repeats,
    [algorithm]()
    {
      algorithm->Modified();
      algorithm->Update();
    });
}

/// A comma-separated list of integers ("1,2").
inline std::vector<int> IntList(const std::string& text)
{
  std::vector<int> values;
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, ',');)
  {
    values.push_back(std::atoi(item.c_str()));
  }
  return values;
}

/// A line of /proc/self/status in MiB (VmHWM: the peak resident set; VmRSS: the current one).
inline double StatusMiB(const char* field)
{
  return rgmc_test::ProcessStatusKiB(field) / 1024.0;
}

} // namespace rgmc_benchmark

#endif
