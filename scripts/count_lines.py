#!/usr/bin/env python3
"""Code lines (not blank, not only a comment) of the engine's parts at git revisions: what
issue #13 (one source) asks to report before and after.

    python3 scripts/count_lines.py 3088d3e^ HEAD

3088d3e is the first one-source commit, so 3088d3e^ is the engine before it. Its effect.cpp
held the reader and Effect::build; since a0dbe80 effect.cpp is the reader alone (the build
and EffectInstance are in effect_instance.cpp, the writer in effect_writer.cpp, all counted
in the "effect files, all" row).
"""
import re
import subprocess
import sys

# Each part: path patterns (regular expressions on the repository path).
PARTS = [
    ("effect loader (effect.cpp)", [r"^sdk/src/effect/effect\.cpp$"]),
    ("effect files, all (reader, writer, descriptors, docs)", [r"^sdk/src/effect/.*\.(cpp|hpp)$"]),
    ("action plumbing (actions.cpp, traits, OpenCL packers, codegen)",
     [r"^sdk/src/actions\.cpp$", r"^sdk/src/action_(traits|params)\.hpp$",
      r"^sdk/src/opencl/actions_\w+\.cpp$", r"^sdk/src/opencl/codegen\.(cpp|hpp)$"]),
    ("CPU math (cpu/ kernels, domains, sampling, noise, shapes)",
     [r"^sdk/src/cpu/(kernels|actions_more|integrate|collisions)\.hpp$",
      r"^sdk/src/(domain|sampling|newborns)\.cpp$",
      r"^sdk/src/(noise|shape_math|field_math|sampling|forces_kernel)\.hpp$"]),
    ("OpenCL C only (kernels/*.cl)", [r"^kernels/.*\.cl$"]),
    ("shared by both (kernels/*.h)", [r"^kernels/.*\.h$"]),
]


def files(rev):
    out = subprocess.run(["git", "ls-tree", "-r", "--name-only", rev], capture_output=True,
                         text=True, check=True).stdout
    return out.split()


def code_lines(rev, path):
    text = subprocess.run(["git", "show", f"{rev}:{path}"], capture_output=True, text=True,
                          check=True).stdout
    n, in_block = 0, False
    for line in text.splitlines():
        s = line.strip()
        if in_block:
            if "*/" not in s:
                continue
            s = s.split("*/", 1)[1].strip()
            in_block = False
        if s.startswith("/*") and "*/" not in s:
            in_block = True
            continue
        if not s or s.startswith("//") or (s.startswith("/*") and s.endswith("*/")):
            continue
        n += 1
    return n


def main():
    revs = sys.argv[1:] or ["HEAD"]
    table = {}
    for rev in revs:
        names = files(rev)
        for part, patterns in PARTS:
            chosen = [f for f in names if any(re.search(p, f) for p in patterns)]
            table[(part, rev)] = sum(code_lines(rev, f) for f in chosen)
    print("| part | " + " | ".join(revs) + " |")
    print("| --- |" + " --- |" * len(revs))
    for part, _ in PARTS:
        print(f"| {part} | " + " | ".join(str(table[(part, r)]) for r in revs) + " |")


if __name__ == "__main__":
    main()
