#!/usr/bin/env python3
"""Log-log plot of `whitted bench scale` (docs/performance.md): load, build and render time and
peak memory per object against the number of objects, one line per kind (scene-file spheres,
glTF nodes with their own meshes). A linear cost is a line of slope 1 in the time panel and a
flat line in the memory panel.

Usage: python3 scripts/plot_scale.py scale.csv OUT_DIR  (writes OUT_DIR/scale.png)
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(path, out_dir):
    rows = defaultdict(list)
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            rows[r["kind"]].append(r)
    if not rows:
        print("plot_scale: no rows")
        return 1
    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(11, 4.2))
    for kind, rs in sorted(rows.items()):
        rs.sort(key=lambda r: int(r["objects"]))
        n = [int(r["objects"]) for r in rs]
        for column, style in (("load_seconds", "o-"), ("build_seconds", "s--"), ("render_seconds", "^:")):
            ax_t.loglog(n, [max(float(r[column]), 1e-5) for r in rs], style, label=f"{kind} {column.split('_')[0]}")
        ax_m.loglog(n, [max(float(r["peak_bytes_per_object"]), 1.0) for r in rs], "o-", label=f"{kind}: peak RSS")
    ax_t.set_xlabel("objects")
    ax_t.set_ylabel("seconds")
    ax_t.set_title("time (slope 1 = linear)")
    ax_t.grid(True, which="both", alpha=0.3)
    ax_t.legend(fontsize=7)
    ax_m.set_xlabel("objects")
    ax_m.set_ylabel("bytes per object")
    ax_m.set_title("peak memory above the empty process, per object")
    ax_m.grid(True, which="both", alpha=0.3)
    ax_m.legend(fontsize=7)
    fig.tight_layout()
    out = os.path.join(out_dir, "scale.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
