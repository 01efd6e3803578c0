#!/usr/bin/env python3
"""Two builds of libflurry against each other on one benchmark binary, alternated.

On a shared, noisy machine a benchmark run before a change and one after it differ by more
than most changes do. This runs the same benchmark binary with each library preloaded in turn
(LD_PRELOAD), alternating the order every round, and prints each benchmark's median over the
rounds and the ratio new/old: the two are measured under the same load.

    git worktree add /tmp/base <commit>          # the commit before, built beside:
    (cd /tmp/base && cmake --preset release -DFLURRY_PYTHON=OFF && ninja -C build/release flurry)
    python3 scripts/compare_libraries.py --rounds 6 \\
        --filter 'Classic/.*/render:0' build/release/bench/bench_classic \\
        /tmp/base/build/release/sdk/libflurry.so.0.1.0 build/release/sdk/libflurry.so.0.1.0

The figure compared is items_per_second where a benchmark reports it (higher is better),
else its real time (lower is better; the ratio is then old/new, so above 1 is faster too).
"""
import argparse
import collections
import json
import os
import statistics
import subprocess
import sys
import tempfile


def run(binary, library, bench_filter, min_time, out):
    env = dict(os.environ, LD_PRELOAD=os.path.abspath(library))
    cmd = [binary, f"--benchmark_filter={bench_filter}", f"--benchmark_out={out}",
           "--benchmark_out_format=json", f"--benchmark_min_time={min_time}"]
    done = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True)
    if done.returncode != 0:
        sys.exit(f"{binary} with {library} failed ({done.returncode}):\n{done.stderr[-2000:]}")
    with open(out) as f:
        return json.load(f)["benchmarks"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("binary", help="a Google Benchmark binary linked against libflurry")
    ap.add_argument("old", help="the library to compare against")
    ap.add_argument("new", help="the library compared")
    ap.add_argument("--filter", default=".", help="--benchmark_filter (default: all)")
    ap.add_argument("--rounds", type=int, default=6, help="runs of each library (default 6)")
    ap.add_argument("--min-time", default="0.5", help="--benchmark_min_time (default 0.5)")
    args = ap.parse_args()
    for lib in (args.old, args.new):
        if not os.path.isfile(lib):
            sys.exit(f"no library at {lib}")
    figures = collections.defaultdict(list)  # (name, which) -> values
    higher = {}  # name -> whether higher is better
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "run.json")
        for r in range(args.rounds):
            order = [("old", args.old), ("new", args.new)]
            for which, lib in (order if r % 2 == 0 else order[::-1]):
                for b in run(args.binary, lib, args.filter, args.min_time, out):
                    if b.get("run_type") == "aggregate" or "error_occurred" in b:
                        continue
                    name = b["name"]
                    if "items_per_second" in b:
                        figures[(name, which)].append(b["items_per_second"])
                        higher[name] = True
                    else:
                        figures[(name, which)].append(b["real_time"])
                        higher[name] = False
            print(f"round {r + 1}/{args.rounds} done", file=sys.stderr)
    print(f"medians of {args.rounds} alternated runs; ratio above 1: the new library is faster;"
          " in brackets the lowest and highest of the rounds' own ratios (a round: one run of"
          " each), the spread a difference must clear")
    for name in sorted(higher):
        olds, news = figures[(name, "old")], figures[(name, "new")]
        old = statistics.median(olds)
        new = statistics.median(news)
        faster = (lambda o, n: n / o) if higher[name] else (lambda o, n: o / n)
        ratio = faster(old, new)
        rounds = [faster(o, n) for o, n in zip(olds, news)]
        unit = "M items/s" if higher[name] else "time"
        scale = 1e-6 if higher[name] else 1.0
        print(f"  {name:55s} old {old * scale:9.2f}  new {new * scale:9.2f} ({unit})"
              f"  ratio {ratio:.3f} [{min(rounds):.3f}, {max(rounds):.3f}]")


if __name__ == "__main__":
    main()
