#!/usr/bin/env bash
# Sets up, builds and runs the fountain sample headless, writing PNG, VDB and PLY frames
# under out/fountain/ (no display needed: the renderer starts its own Xvfb).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
./build/release/bin/flurry run fountain --frames 300 --every 30 --out out/fountain \
  --png out/fountain --vdb out/fountain --vdb-every 30 "$@"
