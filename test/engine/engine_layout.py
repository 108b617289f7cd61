#!/usr/bin/env python3
"""The engine's layout as its READMEs describe it (issue 54): every source file of a pass folder is
named in that folder's README and every file a README names exists; no engine file is over 1,000
lines; the GLSL printer's files never name ISPC and the ISPC printer's never name GLSL's printer.

usage: engine_layout.py ENGINE_DIR    (daemon/engine)"""
import pathlib
import re
import sys

if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
    print(__doc__)
    sys.exit(0 if len(sys.argv) == 2 else 2)
engine = pathlib.Path(sys.argv[1])
problems = []

# Which README describes which folder: print/README.md has sections for glsl/ and ispc/.
folders = {"parse": "parse", "analyse": "analyse", "control": "control", "print": "print",
           "print/glsl": "print", "print/ispc": "print", "generate": "generate", "compile": "compile"}
top_sources = {p.name for p in engine.glob("*") if p.suffix in (".cpp", ".h")}
for folder in sorted({p.parent.relative_to(engine).as_posix() for p in engine.rglob("*.*") if p.suffix in (".cpp", ".h")}):
    if folder != "." and folder not in folders:
        problems.append(f"{folder}/ is not a pass folder with a README")
named_anywhere = set()
all_sources = {p.name for p in engine.rglob("*") if p.suffix in (".cpp", ".h")}
for folder, readme_folder in folders.items():
    readme = engine / readme_folder / "README.md"
    if not readme.exists():
        problems.append(f"{readme} is missing")
        continue
    text = readme.read_text()
    if folder != readme_folder:  # a subfolder's section: from its heading to the next
        match = re.search(r"^## " + re.escape(folder.split("/")[-1]) + r"/.*?(?=^## |\Z)", text, re.M | re.S)
        text = match.group(0) if match else ""
    named = set(re.findall(r"`([A-Za-z0-9_]+\.(?:cpp|h))`", text))
    files = {p.name for p in (engine / folder).glob("*") if p.suffix in (".cpp", ".h")}
    if not files:
        problems.append(f"{folder}/ has no sources")
    for f in sorted(files - named):
        problems.append(f"{folder}/{f} is not named in {readme.relative_to(engine)}")
    for f in sorted(named - all_sources):  # a README may name another folder's file, not a missing one
        problems.append(f"{readme.relative_to(engine)} names {f}, which the engine does not hold")
    named_anywhere |= files

for path in sorted(engine.rglob("*")):
    if path.suffix in (".cpp", ".h"):
        lines = path.read_text().count("\n")
        if lines > 1000:
            problems.append(f"{path.relative_to(engine)} has {lines} lines (at most 1,000)")
for path in sorted((engine / "print" / "glsl").glob("*")):
    if "ispc" in path.read_text().lower():
        problems.append(f"{path.relative_to(engine)} names ISPC")
for path in sorted((engine / "print" / "ispc").glob("*")):
    if "GlslPrinter" in path.read_text():
        problems.append(f"{path.relative_to(engine)} names the GLSL printer")
for path in sorted((engine / "print").glob("*.cpp")) + sorted((engine / "print").glob("*.h")):
    if re.search(r"\bispc\b\s*[?&|)]|\(\s*!?ispc\b", path.read_text()):
        problems.append(f"{path.relative_to(engine)} tests a language flag")

for p in problems:
    print("engine layout:", p)
print(f"engine layout: {'FAIL' if problems else 'ok'} ({len(named_anywhere)} sources in {len(folders)} folders)")
sys.exit(1 if problems else 0)
