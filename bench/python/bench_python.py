"""Stepping a 1M-particle effect from Python against the same from C++, one run each.

    cmake --build --preset release -j 2 --target flurry_cli _flurry
    PYTHONPATH=build/release/bindings/python python3 bench/python/bench_python.py \
        --tool build/release/bin/flurry [--frames 60] [--threads 0] [--repeat 1]

C++: `flurry run million.json --quiet` reports the seconds of its step loop. Python: the same
effect, seed and steps through flurry.Context.step(), one call per frame, reading the
positions each frame through a view (whose data pointer must not change: no copy).
"""
import argparse
import pathlib
import re
import resource
import subprocess
import time

import flurry

here = pathlib.Path(__file__).resolve().parent
parser = argparse.ArgumentParser()
parser.add_argument("--tool", required=True, help="the flurry tool (C++)")
parser.add_argument("--frames", type=int, default=60)
parser.add_argument("--threads", type=int, default=0)
parser.add_argument("--repeat", type=int, default=1, help="alternating runs of each; the fastest counts")
args = parser.parse_args()
effect_file = here / "million.json"



def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_cpp():
    cpu0 = children_cpu()
    out = subprocess.run([args.tool, "run", str(effect_file), "--frames", str(args.frames),
                          "--threads", str(args.threads), "--quiet"],
                         check=True, capture_output=True, text=True).stdout
    # Wall: the tool's step loop; CPU: the whole process (load, build, steps), all threads.
    return float(re.search(r"steps in ([0-9.]+) s", out).group(1)), children_cpu() - cpu0


def run_python():
    cpu0 = time.process_time()
    ctx = flurry.simulate(flurry.load(str(effect_file)), threads=args.threads)
    group = ctx.group("water")
    pointers = set()
    start = time.perf_counter()
    for _ in range(args.frames):
        ctx.step()
        y = group.lane("position", 1)          # a view: no copy
        pointers.add(y.__array_interface__["data"][0])
    seconds = time.perf_counter() - start
    return seconds, time.process_time() - cpu0, group, y, pointers


# Alternating runs; the fastest of each side is the least disturbed by other load.
cpp_runs, py_runs, cpp_cpu, py_cpu = [], [], [], []
for _ in range(args.repeat):
    wall, cpu = run_cpp()
    cpp_runs.append(wall)
    cpp_cpu.append(cpu)
    seconds, cpu, group, y, pointers = run_python()
    py_runs.append(seconds)
    py_cpu.append(cpu)
cpp, py = min(cpp_runs), min(py_runs)
lowest = float(y.min())

# What Python adds per frame, apart from the step itself: a step() call from a Python loop
# against the same steps in one C++ loop (step(n)), and taking a view, on an idle group
# (where the step costs almost nothing, so the difference is the binding's own cost).
idle = flurry.Context(threads=1)
idle_group = idle.create_group("idle", 1)
n = 20000
t = time.perf_counter()
for _ in range(n):
    idle.step()
loop = time.perf_counter() - t
t = time.perf_counter()
idle.step(n)
one = time.perf_counter() - t
t = time.perf_counter()
for _ in range(n):
    idle_group.lane("position", 1)
view = time.perf_counter() - t
overhead = max(loop - one, 0.0) / n + view / n

print(f"CPU backend      the {flurry.cpu_instruction_set()} build")
print(f"particles        {len(group)} (capacity {group.capacity}), lowest y {lowest:.4f}")
print(f"runs             C++ {[round(t, 3) for t in cpp_runs]}, Python {[round(t, 3) for t in py_runs]}")
print(f"C++    {args.frames} steps in {cpp:.3f} s  ({cpp / args.frames * 1e3:.2f} ms/step)")
print(f"Python {args.frames} steps in {py:.3f} s  ({py / args.frames * 1e3:.2f} ms/step)")
print(f"Python / C++     {py / cpp:.3f} wall (step loops)")
print(f"CPU seconds      C++ {min(cpp_cpu):.3f}, Python {min(py_cpu):.3f}: "
      f"Python / C++ {min(py_cpu) / min(cpp_cpu):.3f} (load, build and steps, all threads)")
print(f"binding cost     {(loop - one) / n * 1e6:.2f} us per step() call, {view / n * 1e6:.2f} us "
      f"per view: {overhead / (cpp / args.frames) * 100:.3f} % of a C++ step here")
print(f"positions read   {args.frames} times through {len(pointers)} data pointer(s): no copy")
