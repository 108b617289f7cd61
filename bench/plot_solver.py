#!/usr/bin/python3
"""Plots bench_solver's table (out/bench_solver.csv): microseconds per Jacobi step of HeatDiffusion's
solve to convergence, per implementation, with the residual read every step or every k steps, as
grouped bars on a log axis. Writes out/bench_solver.png.

usage: bench/plot_solver.py [CSV (default out/bench_solver.csv)] [PNG (default out/bench_solver.png)]"""
import csv
import sys

if len(sys.argv) > 1 and sys.argv[1] in ("--help", "-h"):
    print(__doc__.strip().splitlines()[-1])
    sys.exit(0)
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

source = sys.argv[1] if len(sys.argv) > 1 else "out/bench_solver.csv"
target = sys.argv[2] if len(sys.argv) > 2 else "out/bench_solver.png"
rows = list(csv.DictReader(open(source)))
if not rows:
    sys.exit(f"plot_solver.py: {source} has no rows")
impls = list(dict.fromkeys(r["implementation"] for r in rows))
reads = list(dict.fromkeys(r["residual_read"] for r in rows))
width = 0.8 / len(reads)
fig, ax = plt.subplots(figsize=(9, 5))
for k, read in enumerate(reads):
    xs, ys = [], []
    for i, impl in enumerate(impls):
        for r in rows:
            if r["implementation"] == impl and r["residual_read"] == read:
                xs.append(i + (k - (len(reads) - 1) / 2) * width)
                ys.append(float(r["us_per_step"]))
    ax.bar(xs, ys, width, label=f"residual read {read}")
ax.set_xticks(range(len(impls)))
ax.set_xticklabels([i.lstrip("_") for i in impls])
ax.set_yscale("log")
ax.set_xlabel("implementation of HeatDiffusion")
ax.set_ylabel("time per Jacobi step (microseconds, log scale)")
ax.set_title("bench_solver: iterate until converged, reading the residual every step or every k")
ax.legend()
fig.tight_layout()
fig.savefig(target, dpi=120)
print(f"wrote {target}")
