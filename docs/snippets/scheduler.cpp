// docs/snippets/scheduler.cpp: built and run by tests/docs
#include <flurry/flurry.hpp>

#include <cstdio>
#include <cstring>
#include <future>
#include <vector>

// The game's job system, here std::async: the Context hands it each parallel loop.
class AsyncJobs final : public flurry::TaskScheduler {
 public:
  unsigned concurrency() const override { return 4; }
  void parallelFor(std::size_t count, flurry::TaskRef task) override {
    std::vector<std::future<void>> jobs;
    for (std::size_t i = 1; i < count; ++i)
      jobs.push_back(std::async(std::launch::async, [task, i] { task(i); }));
    task(0);  // the calling thread works too
    for (auto& j : jobs) j.get();
  }
};

static std::vector<float> heights(flurry::ContextOptions options) {
  flurry::Context ctx(options);
  flurry::Group& g = ctx.createGroup("sparks", 100000);
  flurry::Emitter e;
  e.rate = 200000;  // 100,000 alive: the pass is split into tasks
  e.types[0].velocity = flurry::Domain::sphere({0, 5, 0}, 2.0f);
  g.addEmitter(e);
  g.setActions({flurry::Gravity{{0, -9.8f, 0}}, flurry::Move{}});
  ctx.run(30);
  const auto y = g.lane(flurry::Attribute::Position, 1);
  return {y.begin(), y.end()};
}

int main() {
  flurry::ContextOptions own;  // the Context's own threads
  flurry::ContextOptions game;
  game.scheduler = std::make_shared<AsyncJobs>();  // threads stays 0
  const std::vector<float> a = heights(own), b = heights(game);
  const bool same = a.size() == b.size() && std::memcmp(a.data(), b.data(), 4 * a.size()) == 0;
  std::printf("%zu particles, %s\n", b.size(), same ? "bitwise the same" : "DIFFERENT");
  return same && b.size() == 100000 ? 0 : 1;
}
