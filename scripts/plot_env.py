#!/usr/bin/env python3
"""Plots `whitted bench env` results: display error against render time of N extracted lights.

Usage:  python3 scripts/plot_env.py ENV.CSV OUT_DIR

Writes OUT_DIR/env.png: one panel per map, one curve per asset through its light counts N (each
point labelled with N), display-referred RMSE against the reference N (in 8-bit codes, 1 code =
1/255) over render time (process CPU or wall-clock, as the CSV's timing column says), both axes
logarithmic; the reference itself (RMSE 0) is drawn on the bottom edge. The dashed line is one
code, the tolerance the default is chosen by.
Needs matplotlib (Debian: apt-get install python3-matplotlib).
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    path, out_dir = sys.argv[1], sys.argv[2]
    rows = list(csv.DictReader(open(path, newline="")))
    if not rows:
        sys.exit(f"{path}: no rows")
    maps = list(dict.fromkeys(r["map"] for r in rows))
    fig, axes = plt.subplots(1, len(maps), figsize=(6.4 * len(maps), 4.8), squeeze=False)
    timing = rows[0]["timing"]
    threads = rows[0]["threads"]
    time_label = f"render time [s], {'process CPU' if timing == 'cpu' else 'wall-clock'}, {threads} thread(s)"
    codes = [float(r["rmse_display_codes"]) for r in rows if float(r["rmse_display_codes"]) > 0]
    floor = min(codes) / 2 if codes else 0.01
    for ax, env in zip(axes[0], maps):
        curves = defaultdict(list)
        for r in rows:
            if r["map"] == env:
                curves[r["asset"]].append(r)
        for asset, runs in curves.items():
            runs.sort(key=lambda r: int(r["lights"]))
            xs = [float(r["seconds"]) for r in runs]
            ys = [max(float(r["rmse_display_codes"]), floor) for r in runs]
            line, = ax.plot(xs, ys, "o-", label=asset)
            for r, x, y in zip(runs, xs, ys):
                ax.annotate(r["lights"], (x, y), textcoords="offset points", xytext=(3, 3), fontsize=7,
                            color=line.get_color())
        ax.axhline(1.0, color="black", linestyle="--", linewidth=1, label="1 code (1/255)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(time_label)
        ax.set_ylabel(f"display RMSE against N = {rows[0]['reference']} [8-bit codes]")
        ax.set_title(f"{env}: N extracted lights")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    out = os.path.join(out_dir, "env.png")
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
