#!/usr/bin/env python3
"""Plots bench_first_build's table (its CSV): per mesh, a program's first BVH build in ms, each
builder's in a fresh process: Embree LOW, LBVH_CPU, and LBVH_ISPC in the first, second and later runs
of a program that builds once (crossrt::LaneMemory: lanes, then the scalar loops, then the faster)."""
import argparse
import csv
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("csv", help="the table bench_first_build wrote (default out/first_build.csv)",
                        nargs="?", default="out/first_build.csv")
    parser.add_argument("png", help="the plot to write (default out/first_build.png)",
                        nargs="?", default="out/first_build.png")
    args = parser.parse_args()
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("plot_first_build.py: matplotlib is missing (Debian: apt install python3-matplotlib)")
    try:
        with open(args.csv, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f"plot_first_build.py: cannot read {args.csv}: {e.strerror}")
    columns = [("embree_low_ms", "Embree LOW"), ("lbvh_cpu_ms", "LBVH_CPU"), ("lbvh_ispc_run1_ms", "LBVH_ISPC, run 1 (lanes)"),
               ("lbvh_ispc_run2_ms", "LBVH_ISPC, run 2 (scalar loops)"), ("lbvh_ispc_later_ms", "LBVH_ISPC, runs 3 on (remembered)")]
    needed = {"cpu", "ispc_target", "mesh"} | {c for c, _ in columns}
    if not rows or not needed <= set(rows[0]):
        sys.exit(f"plot_first_build.py: {args.csv} has no rows with the columns {sorted(needed)}")

    width = 0.8 / len(columns)
    fig, ax = plt.subplots(figsize=(max(8, 1.3 * len(rows)), 5))
    for k, (column, label) in enumerate(columns):
        xs = [m + (k - (len(columns) - 1) / 2) * width for m, r in enumerate(rows) if float(r[column]) >= 0]
        ax.bar(xs, [float(r[column]) for r in rows if float(r[column]) >= 0], width, label=label)
    ax.set_xticks(range(len(rows)))
    ax.set_xticklabels([f"{r['mesh'].split('.')[0]}\n({r['triangles']} tris)" for r in rows], fontsize=8)
    ax.set_yscale("log")
    ax.set_xlabel("mesh")
    ax.set_ylabel("first build in a fresh process, ms (log scale)")
    ax.set_title(f"A program's first BVH build\n{rows[0]['cpu']}, ISPC target {rows[0]['ispc_target']}")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.png, dpi=120)
    print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
