#!/usr/bin/env python3
"""Plots bench_lbvh's slowdown table under --load (its CSV): per mesh, how much each CPU builder's
build slowed down beside the busy threads, its loaded median and 90th percentile over its quiet
median, with Embree LOW (TBB's threads) as the peer."""
import argparse
import csv
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("csv", help="the table bench_lbvh --load N wrote (default out/bvh_slowdown.csv)",
                        nargs="?", default="out/bvh_slowdown.csv")
    parser.add_argument("png", help="the plot to write (default out/bvh_slowdown.png)",
                        nargs="?", default="out/bvh_slowdown.png")
    args = parser.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("plot_bvh_slowdown.py: matplotlib is missing (Debian: apt install python3-matplotlib)")
    try:
        with open(args.csv, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f"plot_bvh_slowdown.py: cannot read {args.csv}: {e.strerror}")
    needed = {"cpu", "busy_threads", "mesh", "builder", "loaded_median_x", "loaded_p90_x"}
    if not rows or not needed <= set(rows[0]):
        sys.exit(f"plot_bvh_slowdown.py: {args.csv} has no rows with the columns {sorted(needed)}")

    meshes = list(dict.fromkeys(r["mesh"] for r in rows))
    builders = list(dict.fromkeys(r["builder"] for r in rows))
    by = {(r["mesh"], r["builder"]): r for r in rows}
    width = 0.8 / len(builders)
    fig, ax = plt.subplots(figsize=(max(8, 1.3 * len(meshes)), 5))
    for b, builder in enumerate(builders):
        xs = [m + (b - (len(builders) - 1) / 2) * width for m in range(len(meshes)) if (meshes[m], builder) in by]
        cells = [by[(mesh, builder)] for mesh in meshes if (mesh, builder) in by]
        median = [float(c["loaded_median_x"]) for c in cells]
        p90 = [float(c["loaded_p90_x"]) for c in cells]
        bars = ax.bar(xs, median, width, label=f"{builder}: median")
        # The 90th percentile as a thin bar over the median's, in the same colour.
        ax.bar(xs, [max(0.0, p - m) for p, m in zip(p90, median)], width * 0.35, bottom=median,
               color=bars.patches[0].get_facecolor(), alpha=0.45, label=f"{builder}: to the 90th percentile")
    ax.axhline(1.0, color="0.5", linewidth=0.8, linestyle="--")
    ax.set_xticks(range(len(meshes)))
    ax.set_xticklabels([m.split(".")[0] for m in meshes], rotation=20, fontsize=8)
    ax.set_xlabel("mesh")
    ax.set_ylabel("build time under load / quiet median (x)")
    target = f", ISPC {rows[0]['ispc_target']}" if rows[0].get("ispc_target") else ""
    ax.set_title(f"BVH builds beside {rows[0]['busy_threads']} busy threads, {rows[0]['cpu']}{target}")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(args.png, dpi=120)
    print(f"plot: {args.png}")


if __name__ == "__main__":
    main()
