#!/usr/bin/env python3
"""Plot docs/error_vs_runtime.csv (written by bench_error_vs_runtime).

One row of panels per scene: perceived error (true P, the sum of f(e, g_true)
over the accepted unresolved pairs) and geometric error (the true 3D gap, FCL
distance, summed over the same pairs), per tick, against the median
narrow-phase time per tick (of ticks that kept their core, so wall time equals
thread CPU time). One line per scheduler through its
wall-clock budgets: the point is the median over the repeats, the band their
min-max. A user picks a scheduler by reading across at the time they have.

Functions a sibling script can reuse (e.g. to add a node's own CSV to the
same axes): load(path) -> rows; series(rows, scene, scheduler, field) ->
(x_ms, y_median, y_min, y_max); draw(ax, rows, scene, field).

Usage: plot_error_vs_runtime.py [CSV] [PNG]
"""
import csv
import statistics
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
SCENES = [("packed_box", "paper's scene: 500 packed rocks"), ("rockfall", "rockfall: 200 rocks")]
FIELDS = [("true_p_unres", "perceived error per tick\nΣ f(e, g_true) [px]"),
          ("true_gap_unres", "geometric error per tick\nΣ true gap [m]")]


def load(path):
    """The CSV's rows as dicts, numbers converted."""
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            for k, v in r.items():
                if k not in ("scene", "scheduler", "budget_kind"):
                    r[k] = float(v)
            rows.append(r)
    return rows


def series(rows, scene, scheduler, field, budget_kind="seconds"):
    """Per budget: median tick time [ms] and the field per tick (median, min, max over repeats)."""
    by_budget = defaultdict(list)
    for r in rows:
        if r["scene"] == scene and r["scheduler"] == scheduler and r["budget_kind"] == budget_kind:
            by_budget[r["fraction"]].append(r)
    out = []
    for fraction in sorted(by_budget):
        reps = by_budget[fraction]
        ys = [r[field] / r["ticks"] for r in reps]
        out.append((statistics.median(r["narrow_ms_median"] for r in reps),
                    statistics.median(ys), min(ys), max(ys)))
    return out


def draw(ax, rows, scene, field):
    """One line per scheduler with its min-max band; log y (the errors span
    decades), so a budget whose median error is 0 (all resolved) ends the line."""
    for scheduler, name, colour in SCHEDULERS:
        pts = [p for p in series(rows, scene, scheduler, field) if p[1] > 0]
        if not pts:
            continue
        xs = [p[0] for p in pts]
        ax.fill_between(xs, [max(p[2], 1e-3 * p[1]) for p in pts], [p[3] for p in pts],
                        color=colour, alpha=0.18, linewidth=0)
        ax.plot(xs, [p[1] for p in pts], "-o", color=colour, markersize=3, linewidth=1.4, label=name)
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)


def plot(src, dst):
    rows = load(src)
    scenes = [s for s in SCENES if any(r["scene"] == s[0] for r in rows)]
    fig, axes = plt.subplots(len(scenes), len(FIELDS), figsize=(12, 4.4 * len(scenes)), squeeze=False)
    for i, (scene, title) in enumerate(scenes):
        for j, (field, label) in enumerate(FIELDS):
            ax = axes[i][j]
            draw(ax, rows, scene, field)
            ax.set_xlabel("narrow-phase time per tick, median [ms]\n(ticks that kept their core: wall = thread CPU time)")
            ax.set_ylabel(label)
            ax.set_title(title)
            if i == 0 and j == 0:
                ax.legend(fontsize=8, title="wall-clock budgets; band: min-max of the repeats",
                          title_fontsize=8)
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    return dst


def main():
    src = sys.argv[1] if len(sys.argv) > 1 else "docs/error_vs_runtime.csv"
    dst = sys.argv[2] if len(sys.argv) > 2 else "docs/error_vs_runtime.png"
    print("wrote", plot(src, dst))


if __name__ == "__main__":
    main()
