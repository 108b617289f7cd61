#!/usr/bin/python3
"""Plots bench_examples' table (out/bench_examples.csv): the speed-up of each implementation of
each example over the class as written (single-threaded C++), as grouped bars on a log axis.
Writes out/bench_examples.png.

usage: bench/plot_examples.py [CSV (default out/bench_examples.csv)] [PNG (default out/bench_examples.png)]"""
import csv
import sys

if len(sys.argv) > 1 and sys.argv[1] in ("--help", "-h"):
    print(__doc__.strip().splitlines()[-1])
    sys.exit(0)
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

source = sys.argv[1] if len(sys.argv) > 1 else "out/bench_examples.csv"
target = sys.argv[2] if len(sys.argv) > 2 else "out/bench_examples.png"
rows = list(csv.DictReader(open(source)))
if not rows:
    sys.exit(f"plot_examples.py: {source} has no rows")
examples = list(dict.fromkeys(r["example"] for r in rows))


def backend(impl):  # Particles_CPU -> CPU (matplotlib leaves "_" labels out of legends); "Vulkan wavefront" stays
    return impl[impl.index("_") + 1:] if "_" in impl else impl


backends = list(dict.fromkeys(backend(r["implementation"]) for r in rows))
width = 0.8 / len(backends)
fig, ax = plt.subplots(figsize=(9, 5))
for b, name in enumerate(backends):
    xs, ys = [], []
    for e, example in enumerate(examples):
        for r in rows:
            if r["example"] == example and backend(r["implementation"]) == name:
                xs.append(e + (b - (len(backends) - 1) / 2) * width)
                ys.append(float(r["speedup_vs_original"]))
    ax.bar(xs, ys, width, label=name)
ax.set_xticks(range(len(examples)))
ax.set_xticklabels(examples)
ax.set_yscale("log")
ax.axhline(1.0, color="gray", linewidth=0.8)
ax.set_xlabel("example")
ax.set_ylabel("speed-up over the class as written (x, log scale)")
ax.set_title("bench_examples: translated classes against the original, one run")
ax.legend()
fig.tight_layout()
fig.savefig(target, dpi=120)
print(f"wrote {target}")
