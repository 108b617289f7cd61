#!/usr/bin/python3
"""Benchmark of crossrtd --lsp (a program that prints a table, not a test).

How long after an edit the editor shows the translator's diagnostic, and clears it when the edit is
undone, on examples/bloom translated for Vulkan, the CPU and ISPC (three translations per edit), as
ratios to a cold translation (a new crossrt process translating Bloom for Vulkan in-process, as
bench_daemon.sh's "cold"). Scenarios:
  kernel body: a heap allocation typed into a kernel (an error on Vulkan and ISPC), then removed;
  header:      the size annotation of Run's pointer deleted from Bloom.h (the preamble's user part is rebuilt),
               then restored.
Latency runs from the moment the change is sent to the moment the diagnostics arrive, the server's
debounce (50 ms) included. Writes a CSV of every round and plots it.

usage: bench/bench_lsp.py [--build DIR] [--rounds N] [--csv FILE] [--plot FILE]
"""
import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "test", "lsp"))
from lsp_client import Client, uri  # noqa: E402


def cpu_model():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0], usage=__doc__.split("usage: ")[1])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--csv", default=None)
    ap.add_argument("--plot", default=None)
    a = ap.parse_args()
    build = os.path.abspath(a.build)
    crossrt, crossrtd = os.path.join(build, "bin", "crossrt"), os.path.join(build, "bin", "crossrtd")
    csv_path = a.csv or os.path.join(build, "bench_lsp.csv")
    plot_path = a.plot or os.path.join(build, "bench_lsp.png")
    work = tempfile.mkdtemp(prefix="bench-lsp-")
    try:
        run(crossrt, crossrtd, work, a.rounds, csv_path, plot_path)
    except Exception:
        log = os.path.join(work, "lsp.log")
        if os.path.exists(log):
            sys.stderr.write("--- the server's log\n" + open(log).read())
        raise
    finally:
        if os.environ.get("BENCH_LSP_KEEP"): print("kept", work)
        else: shutil.rmtree(work, ignore_errors=True)


def run(crossrt, crossrtd, work, rounds, csv_path, plot_path):
    for f in ("Bloom.h", "Bloom.cpp"):
        shutil.copy(os.path.join(ROOT, "examples", "bloom", f), work)
    header, source = os.path.join(work, "Bloom.h"), os.path.join(work, "Bloom.cpp")
    os.makedirs(os.path.join(work, "build"))
    open(os.path.join(work, "build", "CMakeCache.txt"), "w").close()
    flags = ["--", "-I" + os.path.join(ROOT, "libs", "litemath"), "-I" + work]

    def translate(backend, suffix):
        out = os.path.join(work, "build", "crossrt", "Bloom_" + suffix)
        shutil.rmtree(out, ignore_errors=True)
        t0 = time.monotonic()
        subprocess.run([crossrt, "translate", "--no-daemon", "--build-dir", os.path.join(work, "build"), "--class", "Bloom", "--backend", backend, "--out", out,
                        "--source", source, "--templates", os.path.join(ROOT, "templates")] + flags, check=True,
                       capture_output=True)
        return (time.monotonic() - t0) * 1000
    cold = statistics.median(translate("vulkan", "Vulkan") for _ in range(5))
    translate("cpu", "CPU")
    translate("ispc", "ISPC")

    c = Client([crossrtd, "--lsp", "--log", os.path.join(work, "lsp.log")], cwd=work,
               env=dict(os.environ, XDG_CACHE_HOME=os.path.join(work, "cache")))
    c.initialize(work)
    for path in (header, source):
        c.notify("textDocument/didOpen", {"textDocument": {"uri": uri(path), "languageId": "cpp", "version": 1, "text": open(path).read()}})
    t0 = time.monotonic()
    c.call("textDocument/codeLens", {"textDocument": {"uri": uri(source)}}, timeout=300)  # answered once all three translated
    first = (time.monotonic() - t0) * 1000

    versions = {header: 1, source: 1}

    def change(path, line, old, new):
        versions[path] += 1
        t = time.monotonic()
        c.notify("textDocument/didChange", {"textDocument": {"uri": uri(path), "version": versions[path]},
                                            "contentChanges": [{"range": {"start": {"line": line, "character": 0},
                                                                          "end": {"line": line, "character": len(old)}},
                                                                "text": new}]})
        return t

    rows = []  # (scenario, round, ms)

    def break_and_fix(name, path, line, base, edited, r):
        """Times line `line` of `path` changed from base to edited (diagnostics shown) and back (cleared)."""
        for what, old, new, shown in (("diagnostic shown", base, edited, True), ("diagnostic cleared", edited, base, False)):
            t = change(path, line, old, new)
            t1, _ = c.diagnostics(path, lambda d: (len(d) > 0) == shown, version=versions[path])
            rows.append((name + ": " + what, r, (t1 - t) * 1000))

    src_lines = open(source).read().split("\n")
    kline = next(i for i, l in enumerate(src_lines) if "const float4 c = in[y * width + x];" in l)
    hdr_lines = open(header).read().split("\n")
    hline = next(i for i, l in enumerate(hdr_lines) if '[[crossrt::size("width*height")]] const float4* in' in l)
    for r in range(rounds):
        break_and_fix("kernel body", source, kline, src_lines[kline],
                      src_lines[kline] + " float4* scratch = new float4[%d]; delete[] scratch;" % (r + 1), r)
        break_and_fix("header", header, hline, hdr_lines[hline], hdr_lines[hline].replace('[[crossrt::size("width*height")]] ', ""), r)
    c.call("shutdown")
    c.notify("exit")
    c.proc.wait(30)

    goals = {"kernel body": 100.0, "header": 1000.0}
    print("crossrtd --lsp on examples/bloom (Vulkan, CPU and ISPC translations per edit); %s, %d cores; %d rounds"
          % (cpu_model(), os.cpu_count(), rounds))
    print("cold translation (new crossrt process, Vulkan, in-process): %.0f ms (median of 5); the server's first, all three backends: %.0f ms"
          % (cold, first))
    print()
    print("| %-34s | %9s | %9s | %9s | %10s | %8s |" % ("scenario", "median ms", "min ms", "max ms", "median/cold", "goal ms"))
    print("|%s|" % ("-" * 95))
    scenarios = []
    for name, _, _ in rows:
        if name not in scenarios:
            scenarios.append(name)
    medians = {}
    for name in scenarios:
        ms = [v for n, _, v in rows if n == name]
        medians[name] = statistics.median(ms)
        goal = goals[name.split(":")[0]]
        print("| %-34s | %9.0f | %9.0f | %9.0f | %10.3f | %8.0f |" % (name, medians[name], min(ms), max(ms), medians[name] / cold, goal))
    with open(csv_path, "w") as f:
        f.write("scenario,round,ms,cold_ms\n")
        for name, r, ms in rows:
            f.write("%s,%d,%.2f,%.2f\n" % (name, r, ms, cold))
    print("\nwrote %s" % csv_path)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("no matplotlib: no plot")
        return
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i, name in enumerate(scenarios):
        ms = [v for n, _, v in rows if n == name]
        ax.scatter([i] * len(ms), ms, alpha=0.6, label=name)
    ax.axhline(cold, color="black", linestyle="--", label="cold translation (%.0f ms)" % cold)
    ax.axhline(100, color="green", linestyle=":", label="goal, kernel body (100 ms)")
    ax.set_xticks(range(len(scenarios)))
    ax.set_xticklabels([s.replace(": ", ":\n") for s in scenarios], fontsize=8)
    ax.set_xlabel("edit scenario (each round: the edit, then its undo)")
    ax.set_ylabel("edit to diagnostics (ms)")
    ax.set_title("crossrtd --lsp latency, examples/bloom, 3 backends\n%s" % cpu_model(), fontsize=10)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(plot_path, dpi=120)
    print("wrote %s" % plot_path)


if __name__ == "__main__":
    main()
