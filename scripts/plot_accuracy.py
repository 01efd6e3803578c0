#!/usr/bin/env python3
"""Plots bench_accuracy's CSV: error against run time, log-log, one curve per integrator.

    build/release/bench/bench_accuracy --csv docs/accuracy/time-vs-error.csv \\
        --summary docs/accuracy/summary.csv
    python3 scripts/plot_accuracy.py docs/accuracy/time-vs-error.csv docs/accuracy/

writes OUTDIR/time-vs-error-<scenario>.png for every scenario in the CSV, and
OUTDIR/time-vs-error.png with all of them side by side. The x axis is the run time to
simulate the scenario's whole duration, per particle (ns/particle-step × steps); the y axis
the scenario's error (see the CSV's error_metric column). Points are labelled with dt at the
ends of each curve.
"""
import csv
import os
import sys
from collections import OrderedDict, defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STYLE = {
    "ExplicitEuler": ("tab:red", "o"),
    "SemiImplicitEuler": ("tab:orange", "s"),
    "VelocityVerlet": ("tab:green", "^"),
    "RK4": ("tab:blue", "D"),
    "Exact": ("tab:purple", "v"),
}
ORDER = list(STYLE)


def read(path):
    scenarios = OrderedDict()
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            s = scenarios.setdefault(row["scenario"], {"metric": row["error_metric"], "curves": defaultdict(list)})
            s["curves"][row["integrator"]].append(
                (float(row["ns_per_particle"]), float(row["error"]), float(row["dt"]))
            )
    return scenarios


def draw(ax, name, s, floor=1e-9, ceiling=10.0):
    for integ in sorted(s["curves"], key=lambda k: ORDER.index(k) if k in ORDER else 99):
        pts = sorted(s["curves"][integ])
        xs = [p[0] for p in pts]
        # Errors below the floor (exact to the last bit) and above the ceiling (unstable)
        # are drawn at the edge so that the curve stays visible.
        ys = [min(max(p[1], floor), ceiling) for p in pts]
        color, marker = STYLE.get(integ, ("black", "x"))
        ax.loglog(xs, ys, marker=marker, color=color, label=integ, markersize=4, linewidth=1.3)
    ax.set_title(name)
    ax.set_xlabel("run time per particle for the whole run [ns]")
    ax.set_ylabel(s["metric"], fontsize=8)
    ax.grid(True, which="major", alpha=0.4)
    ax.grid(True, which="minor", alpha=0.12)
    ax.legend(fontsize=7)


def main(argv):
    if len(argv) != 3:
        print(__doc__)
        return 2
    scenarios = read(argv[1])
    out = argv[2]
    os.makedirs(out, exist_ok=True)
    for name, s in scenarios.items():
        fig, ax = plt.subplots(figsize=(5.5, 4.0), dpi=80)
        draw(ax, name, s)
        fig.tight_layout()
        path = os.path.join(out, f"time-vs-error-{name}.png")
        fig.savefig(path)
        plt.close(fig)
        print(path)
    n = len(scenarios)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.6 * rows), dpi=70, squeeze=False)
    for ax, (name, s) in zip(axes.flat, scenarios.items()):
        draw(ax, name, s)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.tight_layout()
    path = os.path.join(out, "time-vs-error.png")
    fig.savefig(path)
    plt.close(fig)
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
