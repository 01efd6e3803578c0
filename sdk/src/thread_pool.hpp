// A small persistent thread pool. parallelFor hands out task indices from an atomic counter;
// results never depend on which thread ran a task, so runs are identical on any thread count.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

#include "flurry/scheduler.hpp"

namespace flurry::detail {

class ThreadPool {
 public:
  /// `threads` counts the calling thread: 1 runs everything inline. Throws flurry::Error if
  /// the system cannot start them (no thread is left running).
  explicit ThreadPool(unsigned threads);
  /// Runs the work on a game's job system; its concurrency() (1 to 1024, read now) is the
  /// size. Throws InvalidArgument "scheduler" otherwise.
  explicit ThreadPool(std::shared_ptr<TaskScheduler> external);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned size() const { return external_ ? externalSize_ : unsigned(workers_.size()) + 1; }

  /// Runs f(i) for every i in [0, tasks) and returns when all are done. The first exception
  /// a task throws is rethrown here (the remaining tasks still finish or are skipped).
  /// One task (or one thread) runs on the calling thread: no worker is woken, no lock taken,
  /// nothing allocated, which is what keeps stepping a small group cheap.
  template <class F>
  void parallelFor(std::size_t tasks, F&& f) {
    if (tasks == 0) return;
    if (size() == 1 || tasks == 1) {
      for (std::size_t i = 0; i < tasks; ++i) f(i);
      return;
    }
    using Fn = std::remove_reference_t<F>;
    run(tasks, {const_cast<void*>(static_cast<const void*>(&f)),
                [](void* fn, std::size_t i) { (*static_cast<Fn*>(fn))(i); }});
  }

 private:
  // A borrowed callable, not a std::function: wrapping a lambda of many captures in one
  // would allocate on every call.
  struct Job {
    void* fn = nullptr;
    void (*call)(void*, std::size_t) = nullptr;
  };
  void run(std::size_t tasks, Job job);
  void runExternal(std::size_t tasks, Job job);
  void workerLoop();
  void stopWorkers();
  void runTasks();

  std::shared_ptr<TaskScheduler> external_;  // when set, no workers of its own
  unsigned externalSize_ = 1;
  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
  unsigned busy_ = 0;
  // The job in flight.
  Job job_;
  std::size_t tasks_ = 0;
  std::atomic<std::size_t> next_{0};
  std::exception_ptr error_;
  std::mutex errorMutex_;
};

}  // namespace flurry::detail
