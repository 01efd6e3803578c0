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
  ctest --preset "$preset"
done
