// A minimal check macro for the C++ tests: reports the failed expression with its location and
// keeps going, so one run shows every broken property; main returns Failures() != 0.
#ifndef rgmcCheck_h
#define rgmcCheck_h

#include <iostream>

namespace rgmc_test
{
inline int& Failures()
{
  static int count = 0;
  return count;
}
inline int Result(const char* name)
{
  if (Failures())
  {
    std::cerr << name << ": " << Failures() << " check(s) failed\n";
    return 1;
  }
  std::cout << name << ": all checks passed\n";
  return 0;
}
} // namespace rgmc_test

#define RGMC_CHECK(cond, what)                                                                     \
  do                                                                                               \
  {                                                                                                \
    if (!(cond))                                                                                   \
    {                                                                                              \
      ++rgmc_test::Failures();                                                                     \
      std::cerr << __FILE__ << ":" << __LINE__ << ": FAILED " #cond " -- " << what << "\n";        \
    }                                                                                              \
  } while (false)

#endif
