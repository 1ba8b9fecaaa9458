#!/usr/bin/env python3
"""Plot docs/error_vs_runtime.csv (written by bench_error_vs_runtime).

One row per scene, two panels: perceived error (true P, sum of f(e, g_true)
over accepted unresolved pairs) and geometric error (true 3D gap, FCL
distance summed over the same pairs), each against the narrow phase's run
time, one line per scheduler. Solid: budgets in sphere tests; dashed: budgets
in wall time. Points are means over the snapshots.

Also prints, per scene, the perceived error of each scheduler at equal
narrow-phase time, read off the sphere-test-budget curves (deterministic
results, min-of-3 timings) by linear interpolation: a steadier equal-time
comparison than the wall-budget runs on a shared machine.

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
            for field in ("narrow_s", "true_p_unres", "true_gap_unres", "unresolved", "pairs",
                          "overhead_s", "sphere_tests"):
                sums[key][field] += float(r[field])
    means = {}
    for key, s in sums.items():
        means[key] = {k: v / counts[key] for k, v in s.items()}
    return means


def curve(means, scene, sched, field):
    """(narrow ms, value) along the sphere-test budgets, made monotone in time."""
    pts = sorted((m["narrow_s"] * 1e3, m[field], m["unresolved"] / max(1.0, m["pairs"]))
                 for (sc, sd, k, _), m in means.items() if sc == scene and sd == sched and k == "tests")
    out, best = [], None
    for t, v, u in pts:  # a later point can only be as bad as an earlier, faster one
        best = v if best is None else min(best, v)
        out.append((t, best, u))
    return out


def at(points, t):
    if t <= points[0][0]:
        return points[0][1]
    for (t0, v0, _), (t1, v1, _) in zip(points, points[1:]):
        if t0 <= t <= t1:
            return v0 + (v1 - v0) * (t - t0) / (t1 - t0) if t1 > t0 else v1
    return points[-1][1]


def equal_time_table(means):
    lines = ["| scene | narrow ms | RR unresolved % | RR true P | PQ / RR | PSeq / RR | Seq / RR |",
             "|---|---|---|---|---|---|---|"]
    for scene, _ in SCENES:
        rr = curve(means, scene, "round_robin", "true_p_unres")
        others = {s: curve(means, scene, s, "true_p_unres")
                  for s in ("priority_queues", "perceptual_sequential", "sequential")}
        for t, v, unres in rr:
            if unres < 0.2 or v <= 0 or t <= rr[0][0]:
                continue
            lines.append("| %s | %.3f | %.1f | %.1f | %.3f | %.3f | %.3f |" % (
                scene, t, 100 * unres, v, at(others["priority_queues"], t) / v,
                at(others["perceptual_sequential"], t) / v, at(others["sequential"], t) / v))
    return "\n".join(lines)


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
    print()
    print("Perceived error at equal narrow-phase time (interpolated on the sphere-test-budget runs):")
    print()
    print(equal_time_table(means))


if __name__ == "__main__":
    main()
