#!/usr/bin/env python3
"""Plots bench_lbvh's speed-against-quality table (its CSV): build time against tracing speed,
LBVH and binned SAH per mesh, a line joining each mesh's two builders."""
import argparse
import csv
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("csv", help="the table bench_lbvh wrote (default out/bvh_tradeoff.csv)",
                        nargs="?", default="out/bvh_tradeoff.csv")
    parser.add_argument("png", help="the plot to write (default out/bvh_tradeoff.png)",
                        nargs="?", default="out/bvh_tradeoff.png")
    args = parser.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("plot_bvh_tradeoff.py: matplotlib is missing (Debian: apt install python3-matplotlib)")
    try:
        with open(args.csv, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f"plot_bvh_tradeoff.py: cannot read {args.csv}: {e.strerror}")
    needed = {"mesh", "lbvh_build_ms", "lbvh_mrays_per_s", "sah_build_ms", "sah_mrays_per_s"}
    if not rows or not needed <= set(rows[0]):
        sys.exit(f"plot_bvh_tradeoff.py: {args.csv} has no rows with the columns {sorted(needed)}")

    fig, ax = plt.subplots(figsize=(8, 5))
    for i, r in enumerate(rows):
        lx, ly = float(r["lbvh_build_ms"]), float(r["lbvh_mrays_per_s"])
        sx, sy = float(r["sah_build_ms"]), float(r["sah_mrays_per_s"])
        ax.plot([lx, sx], [ly, sy], color="0.7", zorder=1)
        ax.scatter([lx], [ly], color="tab:blue", zorder=2, label="LBVH (LBVH_CPU build)" if i == 0 else None)
        ax.scatter([sx], [sy], color="tab:orange", zorder=2, label="binned SAH" if i == 0 else None)
        ax.annotate(r["mesh"], (sx, sy), textcoords="offset points", xytext=(5, 3), fontsize=8)
    ax.set_xscale("log")
    ax.set_xlabel("BVH build time, ms (log scale)")
    ax.set_ylabel("primary rays traced, Mrays/s (CPU, all cores)")
    ax.set_title("BVH build time against tracing speed: LBVH and binned SAH per mesh")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.png, dpi=120)
    print(f"plot: {args.png}")


if __name__ == "__main__":
    main()
