#!/usr/bin/python3
"""Plots bench_radiance_fields' CSV: test PSNR against render time over the knobs (grid resolution,
SH degree, early-termination threshold), and render time per backend and method.

usage: plot_radiance_fields.py [CSV (default out/bench_radiance_fields.csv)] [PNG (default out/bench_radiance_fields.png)]
"""
import csv
import sys

if __name__ == "__main__" and len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help"):
    print(__doc__.strip().splitlines()[-1])  # before matplotlib, which --help does not need
    sys.exit(0)
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) > 1 and sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip().splitlines()[-1])
        return 0
    src = sys.argv[1] if len(sys.argv) > 1 else "out/bench_radiance_fields.csv"
    dst = sys.argv[2] if len(sys.argv) > 2 else "out/bench_radiance_fields.png"
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f))
    sweep = [r for r in rows if r["part"] == "sweep"]
    render = [r for r in rows if r["part"] == "render"]
    if not sweep or not render:
        sys.exit(f"plot_radiance_fields: {src} has no sweep or render rows")

    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5))
    # The sweep's families: grids at SH 2 and T 0.01, SH degrees at the largest grid, thresholds.
    largest = max(int(r["grid"]) for r in sweep)
    families = {
        "grid resolution (SH 2, T = 0.01)": [r for r in sweep if r["sh"] == "2" and float(r["stop"]) == 0.01],
        f"SH degree ({largest}^3, T = 0.01)": [r for r in sweep if int(r["grid"]) == largest and float(r["stop"]) == 0.01],
        f"stop threshold T ({largest}^3, SH 2)": [r for r in sweep if int(r["grid"]) == largest and r["sh"] == "2"],
    }
    labels = {
        "grid resolution (SH 2, T = 0.01)": lambda r: f'{r["grid"]}^3',
        f"SH degree ({largest}^3, T = 0.01)": lambda r: f'SH {r["sh"]}',
        f"stop threshold T ({largest}^3, SH 2)": lambda r: f'T={float(r["stop"]):g}',
    }
    knobs = [lambda r: int(r["grid"]), lambda r: int(r["sh"]), lambda r: -float(r["stop"])]
    for (name, family), marker, knob in zip(families.items(), ["o", "s", "^"], knobs):
        family = sorted(family, key=knob)
        xs = [float(r["render_ms"]) for r in family]
        ys = [float(r["psnr_db"]) for r in family]
        left.plot(xs, ys, marker=marker, label=name)
        for r, x, y in zip(family, xs, ys):
            left.annotate(labels[name](r), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    backend = sweep[0]["backend"]
    left.set_xlabel(f"render time per test view on {backend} (ms)")
    left.set_ylabel("test PSNR (dB)")
    left.set_title("ReLU fields: accuracy against render time")
    left.grid(True, alpha=0.3)
    left.legend(fontsize=8)

    sizes = sorted({int(r["size"]) for r in render})
    backends = list(dict.fromkeys(r["backend"] for r in render))
    width = 0.8 / (2 * len(backends))
    for i, b in enumerate(backends):
        for j, method in enumerate(["march", "tree"]):
            ms = []
            for s in sizes:
                match = [float(r["render_ms"]) for r in render if r["backend"] == b and r["method"] == method and int(r["size"]) == s]
                ms.append(match[0] if match else 0.0)
            offset = (2 * i + j) * width - 0.4 + width / 2
            right.bar([k + offset for k in range(len(sizes))], ms, width, label=f"{'ReluField' + b if b.startswith('_') else b} {method}", hatch="//" if method == "march" else None)
    right.set_xticks(range(len(sizes)))
    right.set_xticklabels([f"{s}x{s}" for s in sizes])
    right.set_yscale("log")
    right.set_xlabel("image size (pixels)")
    right.set_ylabel("render time per frame (ms, log scale)")
    right.set_title("Marching against the occupied-cell tree, per backend")
    right.grid(True, axis="y", alpha=0.3)
    right.legend(fontsize=8)

    fig.tight_layout()
    fig.savefig(dst, dpi=120)
    print(f"wrote {dst}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
