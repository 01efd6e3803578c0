"""Stepping a 1M-particle effect from Python against the same from C++, one run each.

    cmake --build --preset release -j 2 --target flurry_cli _flurry
    PYTHONPATH=build/release/bindings/python python3 bench/python/bench_python.py \
        --tool build/release/bin/flurry [--frames 60] [--threads 0]

C++: `flurry run million.json --quiet` reports the seconds of its step loop. Python: the same
effect, seed and steps through flurry.Context.step(), one call per frame, reading the
positions each frame through a view (whose data pointer must not change: no copy).
"""
import argparse
import pathlib
import re
import subprocess
import time

import flurry

here = pathlib.Path(__file__).resolve().parent
parser = argparse.ArgumentParser()
parser.add_argument("--tool", required=True, help="the flurry tool (C++)")
parser.add_argument("--frames", type=int, default=60)
parser.add_argument("--threads", type=int, default=0)
args = parser.parse_args()
effect_file = here / "million.json"

out = subprocess.run([args.tool, "run", str(effect_file), "--frames", str(args.frames),
                      "--threads", str(args.threads), "--quiet"],
                     check=True, capture_output=True, text=True).stdout
cpp = float(re.search(r"steps in ([0-9.]+) s", out).group(1))

ctx = flurry.simulate(flurry.load(str(effect_file)), threads=args.threads)
group = ctx.group("water")
pointers = set()
lowest = 0.0
start = time.perf_counter()
for _ in range(args.frames):
    ctx.step()
    y = group.lane("position", 1)          # a view: no copy
    pointers.add(y.__array_interface__["data"][0])
py = time.perf_counter() - start
lowest = float(y.min())

print(f"particles        {len(group)} (capacity {group.capacity}), lowest y {lowest:.4f}")
print(f"C++    {args.frames} steps in {cpp:.3f} s  ({cpp / args.frames * 1e3:.2f} ms/step)")
print(f"Python {args.frames} steps in {py:.3f} s  ({py / args.frames * 1e3:.2f} ms/step)")
print(f"Python / C++     {py / cpp:.3f}")
print(f"positions read   {args.frames} times through {len(pointers)} data pointer(s): no copy")
