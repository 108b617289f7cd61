#!/usr/bin/python3
"""Plots bench_sdf's table (out/bench_sdf.csv): the mean distance of hit points from the mesh
surface against the time per ray, one point per representation and knob setting, one panel per
mesh. Writes out/bench_sdf.png.

usage: bench/plot_sdf.py [CSV (default out/bench_sdf.csv)] [PNG (default out/bench_sdf.png)]"""
import csv
import sys

if len(sys.argv) > 1 and sys.argv[1] in ("--help", "-h"):
    print(__doc__.strip().splitlines()[-1])
    sys.exit(0)
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

source = sys.argv[1] if len(sys.argv) > 1 else "out/bench_sdf.csv"
target = sys.argv[2] if len(sys.argv) > 2 else "out/bench_sdf.png"
rows = list(csv.DictReader(open(source)))
meshes = sorted({r["mesh"] for r in rows})
fig, axes = plt.subplots(1, len(meshes), figsize=(6 * len(meshes), 5), squeeze=False)
markers = {"grid": "s", "SVS": "o", "SBS": "^", "OpenVDB": "x"}
for ax, mesh in zip(axes[0], meshes):
    for kind, marker in markers.items():
        pts = [r for r in rows if r["mesh"] == mesh and r["representation"] == kind]
        if not pts:
            continue
        x = [1.0 / float(r["mrays_per_s"]) for r in pts]  # microseconds per ray
        y = [float(r["mean_error"]) for r in pts]
        ax.scatter(x, y, marker=marker, label=kind)
        for r, xi, yi in zip(pts, x, y):
            ax.annotate(r["knobs"], (xi, yi), fontsize=6, alpha=0.7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time per ray, one thread (µs)")
    ax.set_ylabel("mean distance of hits from the mesh (box = 2 units)")
    ax.set_title(f"{mesh}: surface error against time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
fig.tight_layout()
fig.savefig(target, dpi=120)
print(f"wrote {target}")
