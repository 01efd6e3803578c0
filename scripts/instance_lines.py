#!/usr/bin/env python3
"""The cache lines one step of an effect instance touches, counted under Valgrind's lackey.

    python3 scripts/instance_lines.py [BUILD_DIR]      (default build/release; needs valgrind)

Runs BUILD_DIR/bench/instance_lines (10 instances of bench_runtime's 100-particle sparks,
stepped 45 times) under `valgrind --tool=lackey --trace-mem=yes`, takes the loads and stores
of its next step (between the two writes of its mark) and prints how many 64-byte lines of
each region of one instance (its state, what its vectors hold, its lanes) the step touched;
then the same run with 20 instances, whose extra lines over the 10's, per instance, are all an
instance costs the memory (its own and what it makes the step touch elsewhere). Valgrind
runs the program as on a CPU without AVX-512: the AVX2 build's loads.
"""
import collections
import os
import re
import subprocess
import sys
import tempfile

LINE = 64
ACCESS = re.compile(r"^\s*[LSM] ([0-9a-f]+),(\d+)")


def traced(binary, count):
    """(regions, lines touched by the marked step) of a run with `count` instances."""
    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, "lackey.log")
        done = subprocess.run(["valgrind", "--tool=lackey", "--trace-mem=yes",
                               f"--log-file={log}", binary, str(count)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if done.returncode != 0:
            sys.exit(f"{binary} {count} under lackey failed ({done.returncode}):\n"
                     f"{done.stderr[-2000:]}")
        mark, regions = None, []
        for line in done.stderr.splitlines():
            words = line.split()
            if words[:1] == ["MARK"]:
                mark = int(words[1], 16)
            elif words[:1] == ["REGION"]:
                regions.append((words[1], int(words[2], 16), int(words[3])))
        if mark is None:
            sys.exit(f"{binary} printed no MARK")
        lines, marks = set(), 0
        with open(log) as f:
            for text in f:
                m = ACCESS.match(text)
                if not m:
                    continue
                at, size = int(m.group(1), 16), int(m.group(2))
                if at == mark and text.lstrip()[0] in "SM":
                    marks += 1
                    if marks == 2:
                        break
                    continue
                if marks == 1:
                    lines.add(at // LINE)
                    lines.add((at + size - 1) // LINE)
        if marks < 2:
            sys.exit("the step's marks were not both found in the trace")
        return regions, lines


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build/release"
    binary = os.path.join(build, "bench", "instance_lines")
    if not os.access(binary, os.X_OK):
        sys.exit(f"{binary} not found: build the target instance_lines first")
    regions, lines = traced(binary, 10)
    print("One step of one of 10 instances of a 100-particle effect (1 thread): 64-byte lines")
    print("touched / held, by region of the instance")
    totals = collections.OrderedDict()
    for name, at, size in regions:
        first, last = at // LINE, (at + size - 1) // LINE
        touched = sum(1 for k in range(first, last + 1) if k in lines)
        t = totals.setdefault(name, [0, 0, 0])
        t[0] += touched
        t[1] += last - first + 1
        t[2] += 1
    named = 0
    for name, (touched, held, n) in totals.items():
        label = f"{name} ({n})" if n > 1 else name
        print(f"  {label:30s} {touched:4d} / {held}")
        named += touched
    print(f"  {'all named':30s} {named:4d}")
    _, more = traced(binary, 20)
    print(f"All the lines the step touched, per instance (20 instances against 10): "
          f"{(len(more) - len(lines)) / 10:.1f}")


if __name__ == "__main__":
    main()
