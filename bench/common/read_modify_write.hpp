// The ceiling every particle benchmark compares against: a[i] = a[i]*s + c over `lanes`
// arrays of n floats (a particle update is in place, so this, not STREAM copy or triad, is
// its limit), allocated as the groups' lanes are (huge pages), on `threads` threads.
#pragma once

#include <benchmark/benchmark.h>
#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <thread>
#include <vector>

namespace flurry::bench {

inline void readModifyWrite(benchmark::State& state, int lanes, unsigned threads) {
  const auto n = std::size_t(state.range(0));
  std::vector<float*> arrays;
  const std::size_t bytes = (n * 4 + (2u << 20) - 1) / (2u << 20) * (2u << 20);
  for (int k = 0; k < lanes; ++k) {
    auto* a = static_cast<float*>(std::aligned_alloc(2u << 20, bytes));
    madvise(a, bytes, MADV_HUGEPAGE);
    for (std::size_t i = 0; i < n; ++i) a[i] = float(i & 1023);
    arrays.push_back(a);
  }
  for (auto _ : state) {
    std::vector<std::thread> pool;
    for (unsigned w = 0; w < threads; ++w)
      pool.emplace_back([&, w] {
        const std::size_t lo = n * w / threads, hi = n * (w + 1) / threads;
        for (float* a : arrays) {
          float* __restrict p = a;
          for (std::size_t i = lo; i < hi; ++i) p[i] = p[i] * 0.999f + 0.001f;
        }
      });
    for (auto& th : pool) th.join();
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(std::int64_t(double(state.iterations()) * double(n) * lanes * 8.0));
  for (float* a : arrays) std::free(a);
}

}  // namespace flurry::bench
