#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite: the Release build, then the same suite
# under AddressSanitizer + UndefinedBehaviorSanitizer. Long stress tests (label `stress`)
# are left to `ctest --preset release -L stress`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc)
for preset in release debug; do
  echo "== $preset build"
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset" -j "$jobs"
  echo "== $preset tests"
  log="build/$preset/ctest-output.log"
  if ! ctest --preset "$preset" 2>&1 | tee "$log"; then
    # LeakSanitizer's tracer can crash at exit after a test has passed. One cause is known
    # and switched off in CMakePresets.json: GCC <= 13's __tls_get_addr interceptor takes a
    # dynamic TLS block that happens to start 16 bytes into a page for glibc 2.19's header
    # and scans a bogus range (google/sanitizers#1322), hence intercept_tls_get_addr=0.
    # (What PoCL's kernel compiler keeps past exit is suppressed there too: tests/lsan.supp.)
    # Any other tracer crash, and only that, earns the failed tests one rerun.
    if [ "$preset" = debug ] && grep -q "Tracer caught signal" "$log"; then
      echo "== LeakSanitizer's tracer crashed (not a leak report): rerunning the failed tests once"
      ctest --preset "$preset" --rerun-failed
    else
      exit 1
    fi
  fi
done
