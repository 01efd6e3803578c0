#!/usr/bin/env bash
# Sets up, builds the `flurry` tool (only it: no tests, no benchmarks) and runs the fountain
# sample headless, writing PNG, VDB and PLY frames under out/fountain/ (no display needed: the
# renderer starts its own Xvfb). Extra arguments go to `flurry run`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# Quiet unless it fails (Debian's FindOpenVDB prints "COMPONENT = openvdb" on every run).
if ! log=$(cmake --preset release 2>&1); then
  echo "$log" >&2
  exit 1
fi
cmake --build --preset release -j "$(nproc)" --target flurry_cli
# Progress as a bar on a terminal, as ten whole lines in a log (not a line per frame).
export FLURRY_PROGRESS="${FLURRY_PROGRESS:-1}"
out=out/fountain
# The defaults below, each unless an extra argument gives it (the tool takes an option once).
args=()
for d in "--frames 300" "--every 30" "--out $out" "--png $out" "--vdb $out" "--vdb-every 30"; do
  case " $* " in *" ${d%% *} "*) ;; *) read -ra kv <<<"$d" && args+=("${kv[@]}") ;; esac
done
./build/release/bin/flurry run fountain "${args[@]}" "$@"
# The newest PNG is this run's last frame (extra arguments may change the frame count).
last=$(ls -t "$out"/fountain.*.png 2>/dev/null | head -n 1 || true)
echo
if [ -n "$last" ]; then
  echo "demo: done. Open $last (the last frame; PLY and VDB frames are beside it),"
else
  echo "demo: done. Frames are in $out/,"
fi
echo "demo: or, with a display, watch it live: build/release/bin/flurry view fountain"
