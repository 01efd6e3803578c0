#!/usr/bin/env python3
"""Checks that GCC vectorised no loop of an instruction-set build in vectors of 8 bytes or
fewer (two floats): such a loop runs at a quarter of the speed the build exists for, and
comes from a type narrower than the data (a bool selected into an int: the sink loops once
were, at a third of a busy effect's step).

usage: check_vector_width.py REPORT_DIR TARGET   (reads REPORT_DIR/TARGET.*.txt, written by
GCC -fdump-tree-vect-optimized=FILE when the target's files were compiled)
"""
import collections
import glob
import os
import re
import sys

folder, target = sys.argv[1], sys.argv[2]
reports = sorted(glob.glob(os.path.join(folder, target + ".*.txt")))
if not reports:
    sys.exit("no vectoriser report for %s in %s: build the target first" % (target, folder))
# A loop's epilogue is reported after it, at the same place and narrower, in the same
# function's part of the dump (";; Function ..."): a loop is judged by the widest vectors used
# at its place in its function (one source line stands in many template instances).
function = re.compile(r"^;; Function (.*)")
vectorised = re.compile(r"^(.+?:\d+):\d+: optimized: loop vectorized using (\d+) byte vectors")
widest = collections.defaultdict(int)
loops = 0
for path in reports:
    with open(path) as f:
        current = ""
        for line in f:
            m = function.match(line)
            if m:
                current = m.group(1)
                continue
            m = vectorised.match(line)
            if not m:
                continue
            loops += 1
            key = (m.group(1), current)
            widest[key] = max(widest[key], int(m.group(2)))
if loops == 0:
    sys.exit("%s: the reports name no vectorised loop (was it built with GCC -O3?)" % target)
narrow = collections.Counter()
for (where, _), bytes_ in widest.items():
    if bytes_ <= 8:
        narrow["%s (%d bytes)" % (where, bytes_)] += 1
if narrow:
    print("%s: loops vectorised two floats wide or narrower:" % target)
    for where, count in sorted(narrow.items()):
        print("  %s  x%d" % (where, count))
    sys.exit(1)
print("%s: %d vectorised loops, none narrower than 16 bytes" % (target, len(widest)))
