#!/usr/bin/env python3
"""Plot `whitted bench accel` CSV: nanoseconds per ray against triangle count, log-log, one panel
per ray kind (camera, shadow, secondary: the rays recorded from a render, docs/accelerators.md),
one line per backend, 1 thread. One row of panels per scene measured at two sizes or more (the
generated scenes; a scene file has one size and is left out), or only --scene. Several CSVs
(e.g. a run with a larger --budget for the 5M cells) are read in order; a row for the same scene,
size and backend replaces the earlier one.
Usage: python3 scripts/plot_accel.py accel.csv [more.csv ...] accel.png [--scene spheres]"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

KINDS = ("camera", "shadow", "secondary")


def main() -> int:
    args = sys.argv[1:]
    only = None
    if "--scene" in args:
        i = args.index("--scene")
        only = args[i + 1] if i + 1 < len(args) else None
        del args[i : i + 2]
    if len(args) < 2 or only == "":
        print(__doc__)
        return 2
    *sources, dst = args
    series = defaultdict(dict)  # (scene, kind, accel) -> {tris: ns/ray}
    sizes = defaultdict(set)  # scene -> triangle counts
    for src in sources:
        with open(src, newline="") as f:
            for row in csv.DictReader(f):
                if row["threads"] != "1" or (only and row["scene"] != only):
                    continue
                sizes[row["scene"]].add(int(row["triangles"]))
                for kind in KINDS:
                    mrays = float(row[f"{kind}_mrays"])
                    if mrays > 0:
                        series[(row["scene"], kind, row["accel"])][int(row["triangles"])] = 1e3 / mrays
    scenes = [s for s in sizes if len(sizes[s]) >= 2 or s == only]
    if not scenes:
        print(f"{' '.join(sources)}: no scene measured at two sizes or more (1 thread): nothing to plot")
        return 1
    fig, axes = plt.subplots(len(scenes), 3, figsize=(15, 4.5 * len(scenes)), sharey="row", squeeze=False)
    for row_axes, scene in zip(axes, scenes):
        for ax, kind in zip(row_axes, KINDS):
            for (s, k, accel), by_size in sorted(series.items()):
                if s != scene or k != kind:
                    continue
                pts = sorted(by_size.items())
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker="o", label=accel)
            ax.set_title(f"{kind} rays, scene '{scene}', 1 thread")
            ax.set_xlabel("triangles")
            ax.grid(True, which="both", alpha=0.3)
        row_axes[0].set_ylabel("ns per ray")
        row_axes[0].legend()
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    print(f"wrote {dst}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
