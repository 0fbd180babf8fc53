#!/usr/bin/env python3
"""Plots `whitted bench aa` results: error against run time, one figure per scene.

Usage:  python3 scripts/plot_aa.py AA.CSV OUT_DIR

For each scene in the CSV writes OUT_DIR/aa-<scene>.png: display-referred RMSE against render
time (process CPU or wall-clock, as the CSV's timing column says) on log-log axes, one curve per mode (adaptive: one per depth, points along the threshold
sweep; stratified: one per filter along spp), the Pareto front (no other run is both faster
and more accurate) as a dashed black line through circled points, and a star at 1/3 of stratified
16 spp's cost at its error (the adaptive target: a curve below and left of it meets it). A
second panel plots the same error against total rays traced, a cost that does not depend on the
machine's load. When `aa_target_search.csv` (the bench's `--target-search` runs) lies next to
AA.CSV, its runs are drawn as crosses in their depth's colour.
Needs matplotlib (Debian: apt-get install python3-matplotlib).
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def curve_key(row):
    mode = row["mode"]
    if mode == "adaptive":
        return f"adaptive d={row['depth']}"
    if mode == "stratified":
        return f"stratified {row['filter']}"
    return mode


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    path, out_dir = sys.argv[1], sys.argv[2]
    rows = list(csv.DictReader(open(path, newline="")))
    scenes = defaultdict(list)
    for r in rows:
        scenes[r["scene"]].append(r)
    searched = defaultdict(list)
    search_path = os.path.join(os.path.dirname(path), "aa_target_search.csv")
    if os.path.exists(search_path):
        for r in csv.DictReader(open(search_path, newline="")):
            searched[r["scene"]].append(r)
    styles = {"center": ("s", "tab:gray"), "corners": ("D", "tab:brown"), "adaptive d=1": ("o", "tab:olive"),
              "adaptive d=2": ("o", "tab:orange"), "adaptive d=3": ("o", "tab:red"),
              "stratified box": ("^", "tab:blue"), "stratified tent": ("v", "tab:cyan")}
    for scene, runs in scenes.items():
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
        # Older CSVs have no timing column: their times are wall-clock.
        timing = runs[0].get("timing") or "wall"
        threads = runs[0].get("threads") or "?"
        time_label = (f"render time [s], process CPU, {threads} thread(s)" if timing == "cpu"
                      else f"render time [s], wall-clock, {threads} thread(s)")
        for ax, xkey, xlabel in ((axes[0], "seconds", time_label), (axes[1], "total_rays", "total rays traced")):
            curves = defaultdict(list)
            for r in runs:
                curves[curve_key(r)].append(r)
            for name, pts in curves.items():
                pts.sort(key=lambda r: float(r["camera_rays"]))
                marker, color = styles.get(name, ("x", "black"))
                ax.plot([float(p[xkey]) for p in pts], [float(p["rmse_display"]) for p in pts], marker=marker,
                        color=color, label=name, linewidth=1.2, markersize=5)
            # The threshold search's runs (not in the Pareto front, which is the sweep's).
            by_depth = defaultdict(list)
            for r in searched.get(scene, []):
                by_depth[curve_key(r)].append(r)
            for name, pts in sorted(by_depth.items()):
                ax.scatter([float(p[xkey]) for p in pts], [float(p["rmse_display"]) for p in pts], marker="x",
                           color=styles.get(name, ("x", "black"))[1], s=30, linewidths=1.0,
                           label=f"threshold search, {name.split()[-1]}")
            # Pareto front over this axis' cost.
            ordered = sorted(runs, key=lambda r: (float(r[xkey]), float(r["rmse_display"])))
            front, best = [], float("inf")
            for r in ordered:
                e = float(r["rmse_display"])
                if e < best:
                    front.append(r)
                    best = e
            ax.plot([float(p[xkey]) for p in front], [float(p["rmse_display"]) for p in front], "k--", linewidth=0.8,
                    label="Pareto front")
            ax.scatter([float(p[xkey]) for p in front], [float(p["rmse_display"]) for p in front], s=90,
                       facecolors="none", edgecolors="black", linewidths=0.8)
            # The issue's target: adaptive at stratified 16's RMSE for at most 1/3 of its cost; a
            # curve passing below and left of the star meets it.
            s16 = [r for r in runs if r["mode"] == "stratified" and r["filter"] == "box" and r["spp"] == "16"]
            if s16:
                ax.plot([float(s16[0][xkey]) / 3.0], [float(s16[0]["rmse_display"])], marker="*", color="black",
                        markersize=11, linestyle="none", label="target: 1/3 of stratified 16")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel("RMSE (display-referred, sRGB)")
            ax.grid(True, which="both", alpha=0.3)
        axes[0].legend(fontsize=8)
        fig.suptitle(f"{scene}: error against cost (reference: stratified box, high spp)")
        fig.tight_layout()
        out = os.path.join(out_dir, f"aa-{scene}.png")
        fig.savefig(out, dpi=90)
        plt.close(fig)
        print(f"wrote {out}")


if __name__ == "__main__":
    main()
