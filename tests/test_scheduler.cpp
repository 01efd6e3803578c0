// A game's own job system (ContextOptions::scheduler, TaskScheduler): the particles are
// bitwise those of the built-in threads, what the work throws reaches the caller and never
// the scheduler, and a scheduler that breaks its contract is a clear error.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstring>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "builtin.hpp"
#include "flurry/flurry.hpp"

using namespace flurry;

namespace {

// A job system as a game has one: its own worker threads take tasks from a queue; the caller
// runs tasks too while it waits. Tasks are queued last first, so the order is not the pool's.
class JobSystem final : public TaskScheduler {
 public:
  explicit JobSystem(unsigned workers) {
    for (unsigned i = 0; i < workers; ++i) threads_.emplace_back([this] { work(); });
  }
  ~JobSystem() override {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (auto& t : threads_) t.join();
  }
  unsigned concurrency() const override { return unsigned(threads_.size()) + 1; }
  void parallelFor(std::size_t count, TaskRef task) override {
    ++calls;
    smallest = std::min(smallest.load(), count);
    std::atomic<std::size_t> left{count};
    {
      std::lock_guard lock(mutex_);
      for (std::size_t i = count; i-- > 0;)
        queue_.push_back([task, i, &left] {
          task(i);
          --left;
        });
    }
    wake_.notify_all();
    while (left.load() > 0)
      if (!runOne()) std::this_thread::yield();
  }
  std::atomic<std::size_t> calls{0}, smallest{~std::size_t(0)};

 private:
  bool runOne() {
    std::function<void()> job;
    {
      std::lock_guard lock(mutex_);
      if (queue_.empty()) return false;
      job = std::move(queue_.back());
      queue_.pop_back();
    }
    job();
    return true;
  }
  void work() {
    for (;;) {
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
        if (stop_) return;
      }
      runOne();
    }
  }
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::vector<std::function<void()>> queue_;
  bool stop_ = false;
};

// The built-in fountain as group `name`, firing `rate` a second.
Group& fountain(Context& ctx, const std::string& name, std::size_t capacity, double rate) {
  const EffectGroup& fx = samples::findSample("fountain")->effect->groups.at(0);
  Group& g = ctx.createGroup(name, capacity);
  Emitter e = fx.emitters.at(0);
  e.rate = rate;
  g.addEmitter(e);
  g.setActions(fx.actions);
  return g;
}

// A large fountain (10,000 births a step, its pass split into tasks once past 32,768) and 24
// small ones (stepped side by side): every particle's position and velocity after `steps`,
// in group order.
std::vector<float> simulate(const ContextOptions& o, int steps) {
  Context ctx(o);
  fountain(ctx, "large", 200000, 300000.0);
  for (int k = 0; k < 24; ++k) {
    Group& g = fountain(ctx, "small" + std::to_string(k), 2000, 300.0 + 10.0 * k);
    Transform t;
    t.position = Vec3(float(k), 0.0f, 0.0f);
    g.setTransform(t);
  }
  ctx.run(std::size_t(steps));
  std::vector<float> all;
  for (const Group* g : ctx.groups())
    for (Attribute a : {Attribute::Position, Attribute::Velocity})
      for (int c = 0; c < 3; ++c) {
        const auto lane = g->lane(a, c);
        all.insert(all.end(), lane.begin(), lane.end());
      }
  return all;
}

bool bitwiseEqual(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace

TEST(Scheduler, AGameJobSystemGivesTheBuiltInThreadsParticles) {
  ContextOptions own;
  own.threads = 1;
  const std::vector<float> reference = simulate(own, 60);
  ASSERT_GT(reference.size(), 100000u);

  for (unsigned workers : {1u, 3u}) {
    auto jobs = std::make_shared<JobSystem>(workers);
    ContextOptions o;
    o.scheduler = jobs;
    {
      Context ctx(o);
      EXPECT_EQ(ctx.threads(), workers + 1);
    }
    EXPECT_TRUE(bitwiseEqual(simulate(o, 60), reference)) << workers << " workers";
    // The work went through it (the large group's pass, the small groups side by side), and
    // only loops of two tasks or more, as TaskScheduler promises.
    EXPECT_GT(jobs->calls.load(), 60u);
    EXPECT_GE(jobs->smallest.load(), 2u);
  }
}

namespace {
// A job system that claims four threads but runs every task on the calling thread, one after
// another, first to last or last to first: the pass that fills holes as it goes (one task
// from the front, the others from the back) never waits on a task that has not started.
class OneByOne final : public TaskScheduler {
 public:
  explicit OneByOne(bool reversed) : reversed_(reversed) {}
  unsigned concurrency() const override { return 4; }
  void parallelFor(std::size_t count, TaskRef task) override {
    for (std::size_t i = 0; i < count; ++i) task(reversed_ ? count - 1 - i : i);
  }

 private:
  bool reversed_;
};
}  // namespace

TEST(Scheduler, TasksRunOneByOneInEitherOrderGiveTheSameParticles) {
  ContextOptions own;
  own.threads = 1;
  const std::vector<float> reference = simulate(own, 30);
  for (bool reversed : {false, true}) {
    ContextOptions o;
    o.scheduler = std::make_shared<OneByOne>(reversed);
    EXPECT_TRUE(bitwiseEqual(simulate(o, 30), reference)) << (reversed ? "last first" : "first");
  }
}

TEST(Scheduler, WhatTheWorkThrowsReachesTheCallerNotTheScheduler) {
  auto jobs = std::make_shared<JobSystem>(2);
  ContextOptions o;
  o.scheduler = jobs;
  Context ctx(o);
  Group& g = fountain(ctx, "large", 200000, 300000.0);
  ctx.run(20);
  ASSERT_GT(g.size(), 100000u);  // the pass in several tasks
  ActionList actions = g.actions();
  // Thrown in one task of many, on one of the job system's threads (an exception escaping
  // there would end the program): the step rethrows it.
  actions.add(Callback{[](Particle& p, const CallbackContext&) {
    if (p.id == 777) throw std::runtime_error("particle 777 is cursed");
  }});
  g.setActions(actions);
  try {
    ctx.step();
    FAIL() << "the step did not rethrow";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "particle 777 is cursed");
  }
}

namespace {
// Breaks the contract: runs only the first task.
class Skipper final : public TaskScheduler {
 public:
  unsigned concurrency() const override { return 4; }
  void parallelFor(std::size_t count, TaskRef task) override {
    if (count > 0) task(0);
  }
};
class Concurrency final : public TaskScheduler {
 public:
  explicit Concurrency(unsigned n) : n_(n) {}
  unsigned concurrency() const override { return n_; }
  void parallelFor(std::size_t count, TaskRef task) override {
    for (std::size_t i = 0; i < count; ++i) task(i);
  }

 private:
  unsigned n_;
};

std::string invalidParameter(const ContextOptions& o) {
  try {
    Context ctx(o);
  } catch (const InvalidArgument& e) {
    return e.parameter();
  }
  return "none";
}
}  // namespace

TEST(Scheduler, ContractBreachesAreClearErrors) {
  ContextOptions o;
  o.scheduler = std::make_shared<Concurrency>(2);
  o.threads = 4;  // which one? neither: say so
  EXPECT_EQ(invalidParameter(o), "threads");
  o.threads = 0;
  o.scheduler = std::make_shared<Concurrency>(0);
  EXPECT_EQ(invalidParameter(o), "scheduler");
  o.scheduler = std::make_shared<Concurrency>(1025);
  EXPECT_EQ(invalidParameter(o), "scheduler");

  o.scheduler = std::make_shared<Skipper>();
  Context broken(o);
  fountain(broken, "large", 200000, 300000.0);
  try {
    broken.run(10);
    FAIL() << "a scheduler that skipped tasks went unnoticed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("returned after running 1 of"), std::string::npos)
        << e.what();
  }
}
