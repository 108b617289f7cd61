#!/usr/bin/python3
"""Plots bench_sdf's table (out/bench_sdf.csv), one column of panels per mesh. Top: the mean
distance of hit points from the mesh surface against the time per ray on one thread, one point per
representation and knob setting. Bottom, as the paper's Figure 9: the time per ray of the translated
renderer (_CPU, all cores; _Vulkan, the device bench_sdf ran on) against the model's size in memory.
A third row, from out/bench_sdf_fig9.csv beside the CSV when it is there: the GPU's time per frame
against the SBS's size, software (BVHScene; SdfLeafScene's switch) against hardware (SdfLeafScene's
intersection shaders, where the device had ray tracing pipelines). A fourth, from
out/bench_sdf_fig10.csv, as the paper's Figure 10: those frames split into the walk and the bricks'
intersection, software (the switch) beside hardware (intersection shaders). Writes out/bench_sdf.png.

usage: bench/plot_sdf.py [CSV (default out/bench_sdf.csv)] [PNG (default out/bench_sdf.png)]"""
import csv
import os
import sys

if len(sys.argv) > 1 and sys.argv[1] in ("--help", "-h"):
    print(__doc__.strip().splitlines()[-1])
    sys.exit(0)
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

source = sys.argv[1] if len(sys.argv) > 1 else "out/bench_sdf.csv"
target = sys.argv[2] if len(sys.argv) > 2 else "out/bench_sdf.png"
rows = list(csv.DictReader(open(source)))  # empty after bench_sdf --figures
fig9_path = os.path.join(os.path.dirname(source) or ".", "bench_sdf_fig9.csv")
fig9 = list(csv.DictReader(open(fig9_path))) if os.path.exists(fig9_path) else []
fig10_path = os.path.join(os.path.dirname(source) or ".", "bench_sdf_fig10.csv")
fig10 = list(csv.DictReader(open(fig10_path))) if os.path.exists(fig10_path) else []
meshes = sorted({r["mesh"] for r in rows + fig9 + fig10})
if not meshes:
    sys.exit(f"plot_sdf: no rows in {source} or beside it: run bench_sdf first")
panels = [kind for kind, present in (("sweep", rows), ("size", rows), ("fig9", fig9), ("fig10", fig10)) if present]
fig, axes = plt.subplots(len(panels), len(meshes), figsize=(6 * len(meshes), 5 * len(panels)), squeeze=False)
row_of = {kind: axes[i] for i, kind in enumerate(panels)}
markers = {"grid": "s", "SVS": "o", "SBS": "^", "OpenVDB": "x"}


def decorate(ax, xlabel, ylabel, title, legend_size=None):
    """Log axes with their labels (units in them), a grid, a title and a legend."""
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=legend_size)


for ax, mesh in zip(row_of.get("sweep", []), meshes):
    for kind, marker in markers.items():
        pts = [r for r in rows if r["mesh"] == mesh and r["representation"] == kind]
        if not pts:
            continue
        x = [1.0 / float(r["mrays_per_s"]) for r in pts]  # microseconds per ray
        y = [float(r["mean_error"]) for r in pts]
        ax.scatter(x, y, marker=marker, label=kind)
        for r, xi, yi in zip(pts, x, y):
            ax.annotate(r["knobs"], (xi, yi), fontsize=6, alpha=0.7)
    decorate(ax, "time per ray, one thread (µs)", "mean distance of hits from the mesh (box = 2 units)", f"{mesh}: surface error against time")
for ax, mesh in zip(row_of.get("size", []), meshes):
    for kind, marker in markers.items():
        for column, style, label in (("mrays_per_s_cpu", "-", "_CPU"), ("mrays_per_s_vulkan", "--", "_Vulkan")):
            pts = sorted((r for r in rows if r["mesh"] == mesh and r["representation"] == kind and float(r.get(column) or 0) > 0),
                         key=lambda r: float(r["total_bytes"]))
            if not pts:
                continue
            x = [float(r["total_bytes"]) / 1048576.0 for r in pts]
            y = [1.0 / float(r[column]) for r in pts]  # microseconds per ray
            name = f"{kind}, {label}" if kind != "OpenVDB" else "OpenVDB, all cores"
            ax.plot(x, y, style, marker=marker, label=name)
    decorate(ax, "model size with its BVH (MiB)", "time per camera ray (µs)", f"{mesh}: render time against model size", 7)
for ax, mesh in zip(row_of.get("fig9", []), meshes):
    pts = sorted((r for r in fig9 if r["mesh"] == mesh), key=lambda r: float(r["sbs_bytes"]))
    x = [float(r["sbs_bytes"]) / 1048576.0 for r in pts]
    for column, style, label in (("bvhscene_ms", "-", "BVHScene traversal (compute, software)"),
                                 ("leaves_switch_ms", "--", "SdfLeafScene, switch (compute, software)"),
                                 ("leaves_hardware_ms", ":", "SdfLeafScene, intersection shaders (hardware)")):
        y = [float(r[column]) for r in pts]
        if pts and all(v > 0 for v in y):
            ax.plot(x, y, style, marker="o", label=label)
    decorate(ax, "SBS size, brick 4, 1 B (MiB)", "GPU time per frame (ms)", f"{mesh}: software against hardware (Figure 9)", 7)
for ax, mesh in zip(row_of.get("fig10", []), meshes):
    pts = sorted((r for r in fig10 if r["mesh"] == mesh), key=lambda r: int(r["depth"]))
    labels = [f"{2 ** int(r['depth'])}³\n{float(r['sbs_mib']):.2f} MiB" for r in pts]
    width = 0.38
    for offset, prefix, name, colours in ((-width / 2, "switch", "software (switch)", ("tab:blue", "lightsteelblue")),
                                          (width / 2, "shaders", "hardware (intersection shaders)", ("tab:orange", "navajowhite"))):
        walk = [float(r[f"{prefix}_walk_ms"]) for r in pts]
        isect = [float(r[f"{prefix}_intersection_ms"]) for r in pts]
        if not any(walk):
            continue
        x = [i + offset for i in range(len(pts))]
        ax.bar(x, walk, width, color=colours[0], label=f"{name}: BVH traversal")
        ax.bar(x, isect, width, bottom=walk, color=colours[1], label=f"{name}: intersection")
    ax.set_xticks(range(len(pts)))
    ax.set_xticklabels(labels)
    ax.set_xlabel("SBS (brick 4, 1 B)")
    ax.set_ylabel("GPU time per frame (ms)")
    ax.set_title(f"{mesh}: traversal and intersection (Figure 10)")
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=7)
fig.tight_layout()
fig.savefig(target, dpi=120)
print(f"wrote {target}")
