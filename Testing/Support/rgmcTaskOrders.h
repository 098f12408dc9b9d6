// The kernels' parallel(count, task) as the unit tests run it, to show a result does not depend
// on the order or the threads of its tasks: task(i) for i in [0, count) in order, in reverse,
// and on std::threads taking one index at a time. No VTK.
#ifndef rgmcTaskOrders_h
#define rgmcTaskOrders_h

#include <atomic>
#include <cstdint>
#include <functional>
#include <thread>
#include <vector>

namespace rgmc_test
{

using Task = std::function<void(std::int64_t)>;

inline void TasksInOrder(std::int64_t count, const Task& task)
{
  for (std::int64_t i = 0; i < count; ++i)
  {
    task(i);
  }
}

inline void TasksReversed(std::int64_t count, const Task& task)
{
  for (std::int64_t i = count - 1; i >= 0; --i)
  {
    task(i);
  }
}

/// On 4 threads, each taking the next index until none is left.
inline void TasksOnThreads(std::int64_t count, const Task& task)
{
  std::atomic<std::int64_t> next{ 0 };
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
  {
    threads.emplace_back(
      [&]()
      {
        for (std::int64_t i = next++; i < count; i = next++)
        {
          task(i);
        }
      });
  }
  for (std::thread& t : threads)
  {
    t.join();
  }
}

} // namespace rgmc_test

#endif
