#!/usr/bin/python3
"""Plots bench_specialize's table (out/bench_specialize.csv): the first frame (making the pipelines with
no cache, then rendering) and a later frame of PrimaryRays_Vulkan's translated traversal, per scene,
specialised to the scene's kinds of geometry or not, as bars on a log axis. Writes
out/bench_specialize.png.

usage: bench/plot_specialize.py [CSV (default out/bench_specialize.csv)] [PNG (default out/bench_specialize.png)]"""
import csv
import sys

if len(sys.argv) > 1 and sys.argv[1] in ("--help", "-h"):
    print(__doc__.strip().splitlines()[-1])
    sys.exit(0)
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

source = sys.argv[1] if len(sys.argv) > 1 else "out/bench_specialize.csv"
target = sys.argv[2] if len(sys.argv) > 2 else "out/bench_specialize.png"
rows = list(csv.DictReader(open(source)))
if not rows:
    sys.exit(f"plot_specialize.py: {source} has no rows")
fig, (first, later) = plt.subplots(1, 2, figsize=(11, 5))
names = [r["scene"] for r in rows]
colours = ["tab:blue", "tab:green", "tab:red"][: len(rows)]
for ax, column, label in ((first, "first_frame_s", "first frame: pipelines made with no cache, then rendered (s)"),
                          (later, "frame_ms", "later frame (ms, median of interleaved rounds)")):
    values = [float(r[column]) for r in rows]
    bars = ax.bar(range(len(rows)), values, color=colours, label=names)
    ax.set_yscale("log")
    ax.set_xticks(range(len(rows)))
    ax.set_xticklabels([f"kinds {r['scene_kinds']}" for r in rows])
    ax.set_xlabel("scene (BVHScene::m_sceneKinds the shader is made for)")
    ax.set_ylabel(label)
    ratios = "first_frame_vs_unspecialised" if column == "first_frame_s" else "frame_vs_unspecialised"
    for bar, r in zip(bars, rows):
        ratio = float(r[ratios])
        ax.annotate(f"{ratio:.2f}x", (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center", va="bottom")
first.legend(fontsize=8)
fig.suptitle(f"bench_specialize: the composed traversal specialised to the scene\n{rows[0]['device']}, {rows[0]['cpu']}")
fig.tight_layout()
fig.savefig(target, dpi=120)
print(f"wrote {target}")
