#!/usr/bin/python3
"""Plots bench_path_tracer's time-to-quality curves (the "quality" rows of out/bench_path_tracer.csv):
PSNR against the converged reference over render time, PathTracer_CPU and Cycles on the same cores,
with the 30 and 35 dB lines. Writes out/bench_path_tracer.png.

usage: bench/plot_path_tracer.py [CSV (default out/bench_path_tracer.csv)] [PNG (default out/bench_path_tracer.png)]"""
import csv
import sys

if len(sys.argv) > 1 and sys.argv[1] in ("--help", "-h"):
    print(__doc__.strip().splitlines()[-1])
    sys.exit(0)
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

source = sys.argv[1] if len(sys.argv) > 1 else "out/bench_path_tracer.csv"
target = sys.argv[2] if len(sys.argv) > 2 else "out/bench_path_tracer.png"
rows = [r for r in csv.DictReader(open(source)) if r["table"] == "quality"]
if not rows:
    sys.exit(f"plot_path_tracer.py: {source} has no time-to-quality rows (run bench_path_tracer with --reference and --cycles-log)")
fig, ax = plt.subplots(figsize=(8, 5))
for name in dict.fromkeys(r["implementation"] for r in rows):
    curve = [(float(r["seconds"]), float(r["psnr_db"]), r["spp"]) for r in rows if r["implementation"] == name]
    ax.plot([c[0] for c in curve], [c[1] for c in curve], marker="o", label=name)
    last = curve[-1]
    ax.annotate(f"{last[2]} spp", (last[0], last[1]), textcoords="offset points", xytext=(4, -12), fontsize=8)
for db in (30, 35):
    ax.axhline(db, color="gray", linewidth=0.8, linestyle="--")
ax.set_xscale("log")
ax.set_xlabel("render time (s, log scale)")
ax.set_ylabel("PSNR against the converged reference (dB, 8-bit sRGB)")
ax.set_title("bench_path_tracer: time to quality on the Cornell box, same cores")
ax.legend()
fig.tight_layout()
fig.savefig(target, dpi=120)
print(f"wrote {target}")
