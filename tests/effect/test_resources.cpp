// What the system refuses (threads, memory) ends in a flurry::Error or std::bad_alloc that a
// program (the `flurry` tool) can report, never in std::terminate.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <new>

#include "flurry/flurry.hpp"

using namespace flurry;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;  // it reserves terabytes: no address-space limit
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

/// Limits this (forked) process's address space to what it uses now plus `extraMiB`.
void limitAddressSpace(long extraMiB) {
  long pages = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) pages = 0;
    std::fclose(f);
  }
  const rlim_t bytes = rlim_t(pages) * rlim_t(::sysconf(_SC_PAGESIZE)) + (rlim_t(extraMiB) << 20);
  const rlimit lim{bytes, bytes};
  ::setrlimit(RLIMIT_AS, &lim);
}

}  // namespace

TEST(Resources, ThreadsTheSystemRefusesAreAnError) {
  if (kAddressSanitizer) GTEST_SKIP() << "an address-space limit breaks AddressSanitizer";
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  // 1000 threads' stacks (8 MiB each by default) do not fit in 256 MiB more: the pool starts
  // some, then the system refuses one. Before, the started ones were destroyed unjoined.
  EXPECT_EXIT(
      {
        limitAddressSpace(256);
        try {
          Context ctx({.threads = 1000});
          std::_Exit(ctx.threads() == 1000 ? 2 : 4);  // the system allowed them after all
        } catch (const Error& e) {
          std::fprintf(stderr, "%s\n", e.what());
          std::_Exit(3);
        }
      },
      ::testing::ExitedWithCode(3), "cannot start 1000 threads");
}

TEST(Resources, WorkerExceptionsReachTheCaller) {
  // An exception thrown on a worker thread (here from a callback, as a kernel's allocation
  // could) is rethrown by step(), on the calling thread.
  Context ctx({.threads = 4});
  Group& g = ctx.createGroup("g", 20000);
  for (int i = 0; i < 20000; ++i) g.add(Particle{});
  ActionList list;
  list.add(Callback{[](Particle&, const CallbackContext&) { throw std::bad_alloc(); }});
  g.setActions(list);
  EXPECT_THROW(ctx.step(), std::bad_alloc);
  // The pool still works afterwards.
  g.setActions(ActionList().add(Move{}));
  EXPECT_NO_THROW(ctx.step());
}
