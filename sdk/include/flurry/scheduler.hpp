// A game's own job system, for the Context's parallel work (ContextOptions::scheduler).
#pragma once

#include <cstddef>

namespace flurry {

/// One parallel loop's body, borrowed for the length of a TaskScheduler::parallelFor call:
/// a pointer and a function, not a std::function, so that handing it over allocates nothing.
/// Call it with each index. It never throws: the Context catches what its work throws and
/// rethrows it from the call that asked for the work (Context::step, ...).
struct TaskRef {
  void* context = nullptr;
  void (*call)(void* context, std::size_t index) = nullptr;
  void operator()(std::size_t index) const { call(context, index); }
};

/// Runs the Context's parallel loops on a game's job system instead of the Context's own
/// threads (the built-in pool is the default). The Context asks from the thread that called
/// it (Context::step, prewarm, ...), never from inside a task, and only for two tasks or more;
/// the results are bitwise the same whatever the order, the threads and the concurrency,
/// because each task writes only its own part.
class TaskScheduler {
 public:
  virtual ~TaskScheduler() = default;
  /// How many tasks it may run at once, the calling thread counted (1 to 1024). Read once,
  /// when the Context is made: it sizes the work, as ContextOptions::threads does.
  virtual unsigned concurrency() const = 0;
  /// Runs task(i) exactly once for every i in [0, count), on any threads and in any order,
  /// and returns when all have returned. The calling thread may run some of them itself
  /// (it should: it would otherwise wait idle). The tasks refer to the caller's stack: a
  /// parallelFor that returns or throws while one still runs is undefined behaviour (one
  /// that returns having skipped some is caught: the call fails with an Error).
  virtual void parallelFor(std::size_t count, TaskRef task) = 0;
};

}  // namespace flurry
