// Running out of memory in local work, turned into an error message (private to the module): a
// rank that fails must still make the collective calls of the others and agree with them on the
// error (rgmc::Ranks::Agree), so an allocation failure becomes a message instead of an exception.
#ifndef vtkRGOutOfMemory_h
#define vtkRGOutOfMemory_h

#include <new>
#include <stdexcept>
#include <string>
#include <utility>

namespace rgmc
{

/// Runs `work` (local work: no communication) unless `problem` is already set; returns whether
/// `problem` is (still) empty. Running out of memory becomes `problem`:
/// - std::bad_alloc: "not enough memory to <what>", then, with a `rank` (>= 0), " on rank <rank>"
///   and what `detail()` says (called after the failure: it can tell how far the work got);
/// - std::length_error (a size no container holds): the same without a `rank`; with one, the work
///   is the kernel's on one rank's part, whose counts have per-rank limits (its 32-bit indices),
///   and the message is "<the exception's message> on rank <rank>: run on more ranks".
template <typename Work, typename Detail>
bool TryLocally(std::string& problem, const char* what, int rank, Work&& work, Detail&& detail)
{
  if (!problem.empty())
  {
    return false;
  }
  auto onRank = [rank]() { return rank >= 0 ? " on rank " + std::to_string(rank) : std::string(); };
  try
  {
    work();
  }
  catch (const std::length_error& tooMany)
  {
    problem = rank >= 0 ? tooMany.what() + onRank() + ": run on more ranks"
                        : std::string("not enough memory to ") + what;
  }
  catch (const std::bad_alloc&)
  {
    problem = std::string("not enough memory to ") + what + onRank() + detail();
  }
  return problem.empty();
}

/// TryLocally on rank `rank`, with nothing after the rank.
template <typename Work>
bool TryLocally(std::string& problem, const char* what, int rank, Work&& work)
{
  return TryLocally(problem, what, rank, std::forward<Work>(work), []() { return std::string(); });
}

/// TryLocally naming no rank: "not enough memory to <what>" (an agreement gives every rank the
/// lowest failing rank's message).
template <typename Work>
bool TryLocally(std::string& problem, const char* what, Work&& work)
{
  return TryLocally(problem, what, -1, std::forward<Work>(work));
}

} // namespace rgmc

#endif
