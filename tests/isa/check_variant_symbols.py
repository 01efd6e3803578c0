#!/usr/bin/env python3
"""Checks that an instruction-set build of the fused pass shares no code with the others.

The linker keeps one copy of each inline (weak) function for the whole library. If an AVX2
object file defines a weak symbol that other objects define too, the SSE2 path may end up
calling its AVX2 copy (issue #12: Illegal instruction on CPUs without AVX). Every symbol an
ISA object exports must therefore be its own (its mangled name carries the variant's
namespace), or contain no instruction beyond the baseline.

usage: check_variant_symbols.py VARIANT OBJECT...   (VARIANT: avx2 or avx512)
"""
import re
import subprocess
import sys

variant, objects = sys.argv[1], sys.argv[2:]
own = re.compile(r"isa_%s|6flurry6detail%d%s\d" % (variant, len(variant), variant))
# VEX/EVEX-encoded instructions: ymm/zmm/mask registers, or AVX mnemonics (v-prefixed).
beyond_baseline = re.compile(r"\b(%?[yz]mm\d+|%k[0-7])\b|^\s*[0-9a-f]+:\s+v[a-z0-9]+\s")

bad = []
for obj in objects:
    nm = subprocess.run(["nm", "--defined-only", obj], capture_output=True, text=True, check=True)
    shared = []
    for line in nm.stdout.splitlines():
        parts = line.split()
        if len(parts) != 3:
            continue
        _, kind, name = parts
        if kind in "tdbrn" or kind == "?":  # local to this object
            continue
        if own.search(name):
            continue
        shared.append((kind, name))
    for kind, name in shared:
        if kind not in "TWiu":  # data (V, D, B, R): no instructions
            continue
        dis = subprocess.run(["objdump", "-d", "--no-show-raw-insn", "--disassemble=" + name, obj],
                             capture_output=True, text=True, check=True).stdout
        hits = [l for l in dis.splitlines() if beyond_baseline.search(l)]
        if hits:
            demangled = subprocess.run(["c++filt", name], capture_output=True, text=True).stdout.strip()
            bad.append("  %s\n    e.g. %s" % (demangled[:160], hits[0].strip()))

if bad:
    print("%s: %d function(s) of the %s build are shared with other builds and use %s instructions:"
          % (", ".join(objects), len(bad), variant, variant))
    print("\n".join(bad))
    print("Put them in the instruction set's inline namespace (sdk/src/isa_namespace.hpp) "
          "or out of line in a baseline translation unit.")
    sys.exit(1)
print("%s: no shared function uses instructions beyond the baseline" % variant)
