#include "thread_pool.hpp"

#include <string>

#include "flurry/error.hpp"

namespace flurry::detail {

ThreadPool::ThreadPool(unsigned threads) {
  if (threads == 0) threads = 1;
  try {
    for (unsigned i = 1; i < threads; ++i) workers_.emplace_back([this] { workerLoop(); });
  } catch (const std::exception& e) {
    // The system refused a thread (std::system_error) or memory: the workers already started
    // must be joined, or destroying them terminates the program.
    stopWorkers();
    throw Error("cannot start " + std::to_string(threads) + " threads (" +
                std::to_string(workers_.size() + 1) + " started): " + e.what() +
                "; ask for fewer threads");
  }
}

ThreadPool::ThreadPool(std::shared_ptr<TaskScheduler> external) : external_(std::move(external)) {
  if (!external_) throw InvalidArgument("scheduler", "is null");
  const unsigned n = external_->concurrency();
  if (n < 1 || n > 1024)
    throw InvalidArgument("scheduler",
                          "concurrency() must be 1 to 1024 (got " + std::to_string(n) + ")");
  externalSize_ = n;
}

ThreadPool::~ThreadPool() {
  stopWorkers();
}

void ThreadPool::stopWorkers() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

void ThreadPool::runTasks() {
  for (;;) {
    const std::size_t i = next_.fetch_add(1, std::memory_order_relaxed);
    if (i >= tasks_) return;
    try {
      job_.call(job_.fn, i);
    } catch (...) {
      std::lock_guard lock(errorMutex_);
      if (!error_) error_ = std::current_exception();
      next_.store(tasks_, std::memory_order_relaxed);  // skip what is left
    }
  }
}

void ThreadPool::workerLoop() {
  std::uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
    }
    runTasks();
    {
      std::lock_guard lock(mutex_);
      if (--busy_ == 0) done_.notify_one();
    }
  }
}

void ThreadPool::runExternal(std::size_t tasks, Job job) {
  // The game's job system never sees an exception: the first a task throws is kept and
  // rethrown here, and the tasks after it return at once.
  struct Shared {
    Job job;
    std::atomic<std::size_t> ran{0};
    std::atomic<bool> failed{false};
    std::exception_ptr error;
    std::mutex errorMutex;
  } shared;
  shared.job = job;
  auto call = [](void* context, std::size_t i) {
    auto& sh = *static_cast<Shared*>(context);
    sh.ran.fetch_add(1, std::memory_order_relaxed);
    if (sh.failed.load(std::memory_order_relaxed)) return;
    try {
      sh.job.call(sh.job.fn, i);
    } catch (...) {
      std::lock_guard lock(sh.errorMutex);
      if (!sh.error) sh.error = std::current_exception();
      sh.failed.store(true, std::memory_order_relaxed);
    }
  };
  external_->parallelFor(tasks, TaskRef{&shared, call});
  if (shared.error) std::rethrow_exception(shared.error);
  // A scheduler that returned early would leave particles half stepped: say so.
  const std::size_t ran = shared.ran.load();
  if (ran != tasks)
    throw Error("the TaskScheduler's parallelFor returned after running " + std::to_string(ran) +
                " of " + std::to_string(tasks) + " tasks (each must run exactly once)");
}

void ThreadPool::run(std::size_t tasks, Job job) {
  if (external_) return runExternal(tasks, job);
  {
    std::lock_guard lock(mutex_);
    job_ = job;
    tasks_ = tasks;
    next_.store(0, std::memory_order_relaxed);
    error_ = nullptr;
    busy_ = unsigned(workers_.size());
    ++generation_;
  }
  wake_.notify_all();
  runTasks();
  {
    std::unique_lock lock(mutex_);
    done_.wait(lock, [&] { return busy_ == 0; });
    job_ = {};
  }
  if (error_) std::rethrow_exception(error_);
}

}  // namespace flurry::detail
