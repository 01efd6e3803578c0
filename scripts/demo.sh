#!/usr/bin/env bash
# Sets up, builds and runs the fountain sample headless, writing its frames under out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
./build/release/bin/flurry run fountain --frames 300 --every 30 --out out/fountain "$@"
