// A small persistent thread pool. parallelFor hands out task indices from an atomic counter;
// results never depend on which thread ran a task, so runs are identical on any thread count.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace flurry::detail {

class ThreadPool {
 public:
  /// `threads` counts the calling thread: 1 runs everything inline. Throws flurry::Error if
  /// the system cannot start them (no thread is left running).
  explicit ThreadPool(unsigned threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned size() const { return unsigned(workers_.size()) + 1; }

  /// Runs f(i) for every i in [0, tasks) and returns when all are done. The first exception
  /// a task throws is rethrown here (the remaining tasks still finish or are skipped).
  void parallelFor(std::size_t tasks, const std::function<void(std::size_t)>& f);

 private:
  void workerLoop();
  void stopWorkers();
  void runTasks();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
  unsigned busy_ = 0;
  // The job in flight.
  const std::function<void(std::size_t)>* job_ = nullptr;
  std::size_t tasks_ = 0;
  std::atomic<std::size_t> next_{0};
  std::exception_ptr error_;
  std::mutex errorMutex_;
};

}  // namespace flurry::detail
