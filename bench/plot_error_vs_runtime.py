#!/usr/bin/env python3
"""Plot docs/error_vs_runtime.csv (written by bench_error_vs_runtime).

One row per scene, two panels: perceived error (true P, sum of f(e, g_true)
over accepted unresolved pairs) and geometric error (true 3D gap, FCL
distance summed over the same pairs), each against the narrow phase's run
time, one line per scheduler. Solid: budgets in sphere tests; dashed: budgets
in wall time. Points are means over the snapshots.

Usage: plot_error_vs_runtime.py [CSV] [PNG]
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SCHEDULERS = [
    ("round_robin", "round-robin", "tab:blue"),
    ("sequential", "sequential", "tab:gray"),
    ("perceptual_sequential", "perceptually sorted sequential", "tab:orange"),
    ("priority_queues", "priority queues", "tab:green"),
]
SCENES = [("packed_box", "paper's scene: 500 packed entities"), ("rockfall", "rockfall")]


def load(path):
    sums = defaultdict(lambda: defaultdict(float))
    counts = defaultdict(int)
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            kind = "tests" if r["budget_kind"] == "unlimited" else r["budget_kind"]
            key = (r["scene"], r["scheduler"], kind, float(r["fraction"]))
            counts[key] += 1
            for field in ("narrow_s", "true_p_unres", "true_gap_unres", "unresolved", "pairs"):
                sums[key][field] += float(r[field])
    means = {}
    for key, s in sums.items():
        means[key] = {k: v / counts[key] for k, v in s.items()}
    return means


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else "docs/error_vs_runtime.csv"
    dst = sys.argv[2] if len(sys.argv) > 2 else "docs/error_vs_runtime.png"
    means = load(src)
    fig, axes = plt.subplots(len(SCENES), 2, figsize=(12, 4.2 * len(SCENES)), squeeze=False)
    for row, (scene, title) in enumerate(SCENES):
        for col, (field, label) in enumerate(
            [("true_p_unres", "perceived error  Σ f(e, g_true)  [px]"),
             ("true_gap_unres", "geometric error  Σ true gap  [m]")]):
            ax = axes[row][col]
            for sched, name, colour in SCHEDULERS:
                for kind, style in (("tests", "-o"), ("seconds", "--x")):
                    pts = sorted(
                        (m["narrow_s"] * 1e3, m[field])
                        for (sc, sd, k, _), m in means.items()
                        if sc == scene and sd == sched and k == kind)
                    if not pts:
                        continue
                    xs, ys = zip(*pts)
                    ax.plot(xs, ys, style, color=colour, markersize=3, linewidth=1.2,
                            label=name if kind == "tests" else None)
            ax.set_xlabel("narrow-phase run time per tick [ms]")
            ax.set_ylabel(label)
            ax.set_title(title)
            ax.grid(True, alpha=0.3)
            if row == 0 and col == 0:
                ax.legend(fontsize=8, title="solid: sphere-test budget\ndashed: wall-time budget",
                          title_fontsize=8)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    print("wrote", dst)


if __name__ == "__main__":
    main()
