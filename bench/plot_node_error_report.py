#!/usr/bin/env python3
"""Plot the CSV a running collision_world_node writes with ~error_report.

One row per tick (columns: see docs/ros_interface.md, parameter ~error_report).
Four panels, one line per CSV given (e.g. one run per scheduler or budget):
  - the pairs accepted unresolved each tick, against the run's time;
  - the bound sum (sum of h_a + h_b, a proven bound) and nabla (the paper's
    gap estimate) over those pairs, metres, against time;
  - P, the perceived error, against time (0 while no gaze is set);
  - P against the tick's narrow-phase time, the axes of
    bench/plot_error_vs_runtime.py, so a user's own scene and gaze stream can
    be read beside the benchmark's.

Usage: plot_node_error_report.py REPORT.csv [MORE.csv ...] [-o PNG]
(PNG defaults to the first CSV's name with .png).
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            rows.append(r)
    if not rows:
        raise SystemExit(f"{path}: no rows (is ~error_report the file the node wrote?)")
    t0 = float(rows[0]["stamp"])
    return {
        "t": [float(r["stamp"]) - t0 for r in rows],
        "accepted": [int(r["unresolved_accepted"]) for r in rows],
        "bound": [float(r["geometric_bound"]) for r in rows],
        "nabla": [float(r["geometric_inaccuracy"]) for r in rows],
        "p": [float(r["perceived_inaccuracy"]) for r in rows],
        "narrow_ms": [float(r["narrow_ms"]) for r in rows],
        "label": f"{os.path.basename(path)}: {rows[0]['scheduler']}, "
                 + (f"{float(rows[0]['budget_ms']):g} ms" if float(rows[0]["budget_ms"]) >= 0 else "no ms budget")
                 + (f", {rows[0]['budget_sphere_tests']} tests" if int(rows[0]["budget_sphere_tests"]) >= 0 else ""),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", nargs="+")
    parser.add_argument("-o", "--output")
    args = parser.parse_args()
    runs = [load(p) for p in args.csv]
    out = args.output or os.path.splitext(args.csv[0])[0] + ".png"

    fig, ax = plt.subplots(2, 2, figsize=(12, 8))
    for k, run in enumerate(runs):
        colour = f"C{k}"
        ax[0][0].plot(run["t"], run["accepted"], color=colour, lw=0.8, label=run["label"])
        ax[0][1].plot(run["t"], run["bound"], color=colour, lw=0.8, label="bound sum (h_a + h_b)" if k == 0 else None)
        ax[0][1].plot(run["t"], run["nabla"], color=colour, lw=0.8, ls="--", label="nabla (estimate)" if k == 0 else None)
        ax[1][0].plot(run["t"], run["p"], color=colour, lw=0.8)
        ax[1][1].scatter(run["narrow_ms"], run["p"], color=colour, s=4, alpha=0.5)
    ax[0][0].set(title="pairs accepted unresolved", xlabel="time since the first row (s)", ylabel="pairs")
    ax[0][1].set(title="geometric error of those pairs", xlabel="time since the first row (s)", ylabel="m")
    ax[1][0].set(title="perceived error P", xlabel="time since the first row (s)", ylabel="P (sum of f(e, g))")
    ax[1][1].set(title="P against the tick's narrow phase", xlabel="narrow-phase time per tick (ms)",
                 ylabel="P (sum of f(e, g))")
    ax[0][0].legend(fontsize=7)
    ax[0][1].legend(fontsize=7)
    for a in ax.flat:
        a.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {out} ({sum(len(r['t']) for r in runs)} ticks from {len(runs)} run(s))")


if __name__ == "__main__":
    main()
