#!/usr/bin/env python3
"""Plot `whitted bench accel` CSV: nanoseconds per ray against triangle count, log-log, one panel
per ray kind, one line per backend (1 thread, the `spheres` scene unless --scene is given).
Usage: python3 scripts/plot_accel.py accel.csv accel.png [--scene spheres]"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    src, dst = sys.argv[1], sys.argv[2]
    scene = sys.argv[4] if len(sys.argv) > 4 and sys.argv[3] == "--scene" else "spheres"
    series = defaultdict(list)  # (kind, accel) -> [(tris, ns/ray)]
    with open(src, newline="") as f:
        for row in csv.DictReader(f):
            if row["scene"] != scene or row["threads"] != "1":
                continue
            for kind in ("camera", "shadow", "incoherent"):
                mrays = float(row[f"{kind}_mrays"])
                if mrays > 0:
                    series[(kind, row["accel"])].append((int(row["triangles"]), 1e3 / mrays))
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5), sharey=True)
    for ax, kind in zip(axes, ("camera", "shadow", "incoherent")):
        for (k, accel), pts in sorted(series.items()):
            if k != kind:
                continue
            pts.sort()
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker="o", label=accel)
        ax.set_title(f"{kind} rays, scene '{scene}', 1 thread")
        ax.set_xlabel("triangles")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("ns per ray")
    axes[0].legend()
    fig.tight_layout()
    fig.savefig(dst, dpi=110)
    print(f"wrote {dst}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
