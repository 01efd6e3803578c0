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
vectorised = re.compile(r"^(\S+?):\d+: optimized: loop vectorized using (\d+) byte vectors")
narrow = collections.Counter()
loops = 0
for path in reports:
    with open(path) as f:
        for line in f:
            m = vectorised.match(line)
            if not m:
                continue
            loops += 1
            if int(m.group(2)) <= 8:
                narrow["%s (%s bytes)" % (m.group(1), m.group(2))] += 1
if loops == 0:
    sys.exit("%s: the reports name no vectorised loop (was it built with GCC -O3?)" % target)
if narrow:
    print("%s: loops vectorised two floats wide or narrower:" % target)
    for where, count in sorted(narrow.items()):
        print("  %s  x%d" % (where, count))
    sys.exit(1)
print("%s: %d vectorised loops, none narrower than 16 bytes" % (target, loops))
