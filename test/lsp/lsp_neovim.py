#!/usr/bin/env python3
"""Neovim's built-in LSP client, headless, drives crossrtd --lsp (neovim.lua).

usage: lsp_neovim.py CROSSRT CROSSRTD TEMPLATES WORKDIR
"""
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lsp_protocol import setup  # noqa: E402


def main():
    if len(sys.argv) != 5 or sys.argv[1] in ("--help", "-h"):
        print(__doc__.strip())
        sys.exit(0 if sys.argv[1:2] in (["--help"], ["-h"]) else 2)
    crossrt, crossrtd, templates, work = (os.path.abspath(a) for a in sys.argv[1:5])
    nvim = shutil.which("nvim")
    if not nvim:
        print("FAIL: nvim is not installed (scripts/install-deps.sh installs Debian's neovim)")
        sys.exit(1)
    setup(crossrt, templates, work)
    env = dict(os.environ, CROSSRT_LSP_SERVER=crossrtd, CROSSRT_LSP_WORK=work, XDG_CACHE_HOME=os.path.join(work, "cache"),
               XDG_STATE_HOME=os.path.join(work, "state"), XDG_DATA_HOME=os.path.join(work, "data"))
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "neovim.lua")
    r = subprocess.run([nvim, "--headless", "-u", "NONE", "-i", "NONE", "-n", "-c", "luafile " + script],
                       env=env, cwd=work, capture_output=True, text=True, timeout=240)
    sys.stdout.write(r.stdout)
    sys.stdout.write(r.stderr)
    log = os.path.join(work, "nvim-lsp.log")
    if os.path.exists(log):
        sys.stdout.write("--- the server's log\n" + open(log).read())
    sys.exit(r.returncode)


if __name__ == "__main__":
    main()
