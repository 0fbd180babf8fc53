#!/usr/bin/python3
"""Supersampling converges to the pixel integral of the point-sampled texture (issue 25).

Usage: PYTHONPATH=build/release/python /usr/bin/python3 scripts/texture_convergence.py [--width 128] [--out DIR]

For each scene: a reference rendered with stratified 32 x 32 samples per pixel and
--texture-filter none (point samples of the finest level: the box-filtered pixel integral), then
stratified 4, 16, 64 and 256 spp with --texture-filter mip and with none. Prints the linear RMSE
of each against the reference, writes texture_convergence.csv and texture_convergence.png
(log-log RMSE over spp, with a 1/sqrt(spp) guide). The commands and figures are in
docs/measurements/antialiasing.md.
"""
import argparse
import csv
import math
import os
import sys
import time

import numpy as np

import whitted

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = [
    ("default.glb", "assets/scenes/default.glb"),
    ("whitted1980.json", "assets/scenes/whitted1980.json"),
    ("TextureSettingsTest", "assets/gltf/TextureSettingsTest/glTF-Binary/TextureSettingsTest.glb"),
]
SPPS = [4, 16, 64, 256]
REFERENCE_SPP = 1024


def rmse(a, b):
    return float(np.sqrt(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--width", type=int, default=128)
    ap.add_argument("--out", default="texture-convergence")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for label, rel in SCENES:
        path = os.path.join(ROOT, rel)
        if not os.path.exists(path):
            sys.exit(f"texture_convergence: {path}: no such file")
        scene = whitted.load(path)
        common = dict(width=args.width, aa="stratified", progress=False)
        t = time.perf_counter()
        ref = whitted.render(scene, spp=REFERENCE_SPP, texture_filter="none", **common).beauty
        print(f"== {label}: {ref.shape[1]}x{ref.shape[0]}, reference {REFERENCE_SPP} spp point-sampled "
              f"in {time.perf_counter() - t:.1f}s")
        for spp in SPPS:
            for tf in ("mip", "none"):
                e = rmse(whitted.render(scene, spp=spp, texture_filter=tf, **common).beauty, ref)
                rows.append({"scene": label, "texture_filter": tf, "spp": spp, "rmse": e})
                print(f"   stratified {spp:4d} spp, {tf:4s}: RMSE {e:.5f}")
    with open(os.path.join(args.out, "texture_convergence.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["scene", "texture_filter", "spp", "rmse"])
        w.writeheader()
        w.writerows(rows)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(SCENES), figsize=(4.2 * len(SCENES), 3.6), squeeze=False)
    for ax, (label, _) in zip(axes[0], SCENES):
        for tf, style in (("mip", "o-"), ("none", "s--")):
            pts = [(r["spp"], r["rmse"]) for r in rows if r["scene"] == label and r["texture_filter"] == tf]
            ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, label=f"--texture-filter {tf}")
        first = next(r["rmse"] for r in rows if r["scene"] == label and r["texture_filter"] == "mip")
        ax.loglog(SPPS, [first * math.sqrt(SPPS[0] / n) for n in SPPS], ":", color="grey", label="1/sqrt(spp)")
        ax.set_title(label)
        ax.set_xlabel("stratified samples per pixel")
        ax.set_ylabel(f"linear RMSE vs {REFERENCE_SPP} point samples")
        ax.set_xticks(SPPS)
        ax.set_xticklabels([str(n) for n in SPPS])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "texture_convergence.png"), dpi=110)
    print(f"wrote {args.out}/texture_convergence.csv and texture_convergence.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
