#!/usr/bin/python3
"""kernel_slicer's feature tests and sample apps as a user's classes: how many CrossRT translates
and compiles (issue 52). Each sample (apps/NN_*, apps/tests/NNN_*, apps/z_*) of a kernel_slicer
checkout becomes a folder of one outside CMake project against CrossRT as installed (cmake --install
of the build tree): an object library of the sample's own sources (all but main.cpp and the files
kernel_slicer generated) that define the class's member functions, or those of its base classes
and composed implementations, and crossrt_add_class() for each backend. A sample's class is its
kmake.json's mainClass, else the class that declares its kernel_ functions; its composition
(kmake.json's composClasses, or -composInterface/-composImplementation in kernel_slicer's own
.vscode/launch.json, or else the one class of the sample derived from the interface of a
std::shared_ptr member, or BVHScene for an ISceneObject the sample does not implement) becomes
COMPOSE. Each target is built on its own; the
table gives per sample and backend "ok" or the first error (the translator's file:line:col: error,
or the compiler's). Usable = translated and compiled (shaders included); nothing is run. Writes
WORK/survey.csv.

kernel_slicer's LiteMath, LiteScene and RayTracing are git submodules: the samples get CrossRT's
LiteMath, Image2d and CrossRT.h (ISceneObject) instead, as crossrt_add_class gives every class.

usage: bench/kernel_slicer_survey.py KSLICER_DIR [--build BUILD] [--work WORK] [--backends vulkan,cpu,ispc] [--only PREFIX,...] [--include DIR]"""
import argparse
import csv
import json
import os
import re
import shutil
import subprocess
import sys

SKIPPED_SOURCES = re.compile(r"^(main|glfw_window|generated_userfix)\.cpp$|_gpu\.cpp$|_generated|_ispc\.cpp$|_wgpu|_cuda")
KERNEL_DECL = re.compile(r"\bkernel(?:BE)?(?:1D|2D|3D)?_\w+\s*\(")


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def read_json(path):
    """JSON with // comments (kernel_slicer's kmake.json and launch.json), or {}."""
    text = re.sub(r"(?<![:\"])//[^\n]*", "", open(path, encoding="utf-8", errors="replace").read())
    text = re.sub(r",(\s*[}\]])", r"\1", text)  # trailing commas
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return {}


def load_kmake(folder):
    """The sample's kmake.json, else its first kmake_*.json (compute before ray tracing pipelines), or {}."""
    names = sorted(n for n in os.listdir(folder) if re.match(r"^kmake.*\.json$", n))
    names.sort(key=lambda n: (n != "kmake.json", not re.search(r"_(cs|compute)\.json$", n), n))
    return read_json(os.path.join(folder, names[0])) if names else {}


def launch_compositions(root):
    """kernel_slicer's own launch configurations: source file -> [INTERFACE=IMPLEMENTATION]."""
    path = os.path.join(root, ".vscode", "launch.json")
    found = {}
    # Read as text: the file is not always JSON (it has held merge conflict markers).
    text = re.sub(r"^\s*//[^\n]*", "", open(path, encoding="utf-8", errors="replace").read(), flags=re.M) if os.path.exists(path) else ""
    for block in re.findall(r'"args"\s*:\s*\[(.*?)\]', text, flags=re.S):
        args = re.findall(r'"([^"]*)"', block)
        if args and "-composInterface" in args and "-composImplementation" in args:
            source = os.path.normpath(args[0].replace("${workspaceFolder}", root))
            pair = f"{args[args.index('-composInterface') + 1]}={args[args.index('-composImplementation') + 1]}"
            found.setdefault(source, [pair])
    return found


def compositions(kmake, folder, sources, launch):
    compose = kmake.get("composClasses") or {}
    if isinstance(compose, dict):
        pairs = [f"{i}={c}" for i, c in compose.items()]
    else:
        pairs = [f"{c['interface']}={c['implementation']}" for c in compose if isinstance(c, dict) and "interface" in c]
    for source in sources:
        pairs += [p for p in launch.get(os.path.normpath(source), []) if p not in pairs]
    return pairs


def implied_compositions(folder, main_class):
    """INTERFACE=IMPLEMENTATION where the class holds a std::shared_ptr<INTERFACE> member and the
    sample's headers derive exactly one class from INTERFACE (samples that name no composition)."""
    text = ""
    for name in sorted(os.listdir(folder)):
        if name.endswith((".h", ".hpp")):
            text += strip_comments(open(os.path.join(folder, name), encoding="utf-8", errors="replace").read())
    pairs = []
    for interface in sorted(set(re.findall(r"std::shared_ptr<\s*(\w+)\s*>\s*\w+\s*(?:=[^;]*)?;", text))):
        derived = re.findall(r"\b(?:class|struct)\s+(\w+)\s*:\s*(?:public\s+)?" + re.escape(interface) + r"\b", text)
        if len(derived) == 1 and derived[0] != main_class:
            pairs.append(f"{interface}={derived[0]}")
        elif not derived and interface == "ISceneObject":  # CreateSceneRT's scene: CrossRT's own, as the paper composes it
            pairs.append("ISceneObject=BVHScene")
    return pairs


def defining_sources(folder, names, classes):
    """The .cpp files that define a member function of one of `classes` (kmake.json's "source" when it names them)."""
    found = []
    for name in names:
        text = strip_comments(open(os.path.join(folder, name), encoding="utf-8", errors="replace").read())
        if any(re.search(r"\b" + re.escape(c) + r"\s*::\s*~?\w+\s*\(", text) for c in classes):
            found.append(name)
    return found


def classes_with_kernels(folder):
    """Classes (in declaration order) whose bodies declare kernel_ functions, over the folder's headers."""
    found = []
    for name in sorted(os.listdir(folder)):
        if not name.endswith((".h", ".hpp")):
            continue
        text = strip_comments(open(os.path.join(folder, name), encoding="utf-8", errors="replace").read())
        for m in re.finditer(r"\b(?:class|struct)\s+(\w+)\s*(?::[^{;]*)?\{", text):
            depth, i = 1, m.end()
            while i < len(text) and depth:
                depth += {"{": 1, "}": -1}.get(text[i], 0)
                i += 1
            body = text[m.end():i]
            # Only kernels declared at the class's own level, not in a nested class.
            if KERNEL_DECL.search(body) and m.group(1) not in found:
                found.append(m.group(1))
    return found


def samples(root):
    apps = os.path.join(root, "apps")
    launch = launch_compositions(root)
    folders = [os.path.join(apps, d) for d in sorted(os.listdir(apps)) if re.match(r"^(\d+_|z_)", d)]
    folders += [os.path.join(apps, "tests", d) for d in sorted(os.listdir(os.path.join(apps, "tests"))) if re.match(r"^\d+_", d)]
    for folder in folders:
        kmake = load_kmake(folder)
        candidates = [s for s in sorted(os.listdir(folder)) if s.endswith(".cpp") and not SKIPPED_SOURCES.search(s)]
        classes = classes_with_kernels(folder)
        main_class = kmake.get("mainClass") or (classes[-1] if classes else None)
        listed = [s for s in kmake.get("source", []) if s in candidates]
        compose = compositions(kmake, folder, [os.path.join(folder, s) for s in listed or candidates], launch)
        compose += [p for p in implied_compositions(folder, main_class) if p.split("=")[0] not in {c.split("=")[0] for c in compose}]
        owners = [main_class] + list(kmake.get("baseClasses") or []) + [p.split("=")[1] for p in compose]
        sources = sorted(set(listed + defining_sources(folder, candidates, [c for c in owners if c])))
        yield {
            "sample": os.path.relpath(folder, apps),
            "folder": folder,
            "class": main_class,
            "sources": [os.path.join(folder, s) for s in sources],
            "compose": compose,
        }


def target_name(sample, backend):
    return re.sub(r"\W", "_", sample) + "_" + backend


def write_project(project, root, found, backends, extra_includes):
    os.makedirs(project, exist_ok=True)
    lines = ["cmake_minimum_required(VERSION 3.22)", "project(kernel_slicer_survey CXX)", "set(CMAKE_CXX_STANDARD 17)",
             "find_package(CrossRT REQUIRED)"]
    for s in found:
        if not s["class"] or not s["sources"]:
            continue
        sub = re.sub(r"\W", "_", s["sample"])
        os.makedirs(os.path.join(project, sub), exist_ok=True)
        body = []
        for b in backends:
            t = target_name(s["sample"], b)
            body.append(f"add_library({t} OBJECT {' '.join(s['sources'])})")
            includes = [s["folder"], os.path.join(s["folder"], "include"), os.path.join(root, "apps", "LiteMathAux"),
                        os.path.join(root, "apps", "utils")] + [os.path.abspath(d) for d in extra_includes]
            body.append(f"target_include_directories({t} PRIVATE {' '.join(includes)})")
            body.append(f"target_link_libraries({t} PRIVATE crossrt::litemath crossrt::liteimage crossrt::litert)")
            compose = f" COMPOSE {' '.join(s['compose'])}" if s["compose"] else ""
            body.append(f"crossrt_add_class({t} {s['class']} BACKEND {b}{compose})")
        open(os.path.join(project, sub, "CMakeLists.txt"), "w").write("\n".join(body) + "\n")
        lines.append(f"add_subdirectory({sub})")
    open(os.path.join(project, "CMakeLists.txt"), "w").write("\n".join(lines) + "\n")


def first_error(log):
    """The first diagnostic worth a row: the translator's or the compiler's error line."""
    for pattern in (r"^\S+:\d+:\d+: error: .*$", r"^.*error: .*$", r"^.*Error.*$"):
        m = re.search(pattern, log, flags=re.M)
        if m:
            return m.group(0).strip()[:220]
    return log.strip().splitlines()[-1][:220] if log.strip() else "failed"


def main():
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0], usage=__doc__.strip().splitlines()[-1][7:])
    parser.add_argument("kslicer", metavar="KSLICER_DIR", help="a kernel_slicer checkout (its apps/ folder)")
    parser.add_argument("--build", default="build", help="CrossRT's build tree, installed into WORK/prefix (default build)")
    parser.add_argument("--work", default="out/kernel_slicer_survey", help="where the project, its build and survey.csv go")
    parser.add_argument("--backends", default="vulkan,cpu", help="comma-separated: vulkan, cpu, ispc (default vulkan,cpu)")
    parser.add_argument("--only", default="", help="comma-separated prefixes of sample names (e.g. tests/003,04_)")
    parser.add_argument("--include", action="append", default=[], metavar="DIR",
                        help="an include folder for every sample, e.g. a LiteScene checkout for the samples that load meshes (cmesh4.h)")
    args = parser.parse_args()
    root = os.path.abspath(args.kslicer)
    if not os.path.isdir(os.path.join(root, "apps", "tests")):
        sys.exit(f"kernel_slicer_survey: {root} has no apps/tests: not a kernel_slicer checkout")
    backends = [b for b in args.backends.split(",") if b]
    work = os.path.abspath(args.work)
    prefix, project, build = (os.path.join(work, d) for d in ("prefix", "project", "build"))
    shutil.rmtree(project, ignore_errors=True)
    found = [s for s in samples(root) if not args.only or any(s["sample"].startswith(p) for p in args.only.split(","))]
    subprocess.run(["cmake", "--install", args.build, "--prefix", prefix], check=True, stdout=subprocess.DEVNULL)
    write_project(project, root, found, backends, args.include)
    configure = subprocess.run(["cmake", "-S", project, "-B", build, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                                f"-DCMAKE_PREFIX_PATH={prefix}"], capture_output=True, text=True)
    if configure.returncode != 0:
        sys.exit("kernel_slicer_survey: the project did not configure:\n" + configure.stdout[-3000:] + configure.stderr[-3000:])
    rows, usable = [], {b: 0 for b in backends}
    print(f"| {'sample':<36} | {'class':<26} | " + " | ".join(f"{b:<8}" for b in backends) + " |")
    try:
        for s in found:
            results = {}
            for b in backends:
                if not s["class"]:
                    results[b] = "no class with kernel_ functions found"
                    continue
                built = subprocess.run(["cmake", "--build", build, "--target", target_name(s["sample"], b)], capture_output=True, text=True)
                results[b] = "ok" if built.returncode == 0 else first_error(built.stdout + built.stderr)
                usable[b] += results[b] == "ok"
            print(f"| {s['sample']:<36} | {str(s['class']):<26} | " + " | ".join(f"{'ok' if results[b] == 'ok' else 'FAILED':<8}" for b in backends) + " |",
                  flush=True)
            for b in backends:
                if results[b] != "ok":
                    print(f"|   {b}: {results[b]}")
            rows.append([s["sample"], s["class"]] + [results[b] for b in backends])
    finally:
        subprocess.run([os.path.join(prefix, "bin", "crossrt"), "daemon", "stop", "--build-dir", build], capture_output=True)
    with open(os.path.join(work, "survey.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["sample", "class"] + backends)
        w.writerows(rows)
    print(f"\nkernel_slicer survey: {len(found)} samples; usable: " + ", ".join(f"{b} {usable[b]}" for b in backends) +
          f" (table: {os.path.join(work, 'survey.csv')})")


if __name__ == "__main__":
    main()
