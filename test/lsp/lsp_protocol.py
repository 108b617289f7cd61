#!/usr/bin/env python3
"""crossrtd --lsp against a client that speaks the protocol by hand: diagnostics as a class is
fixed, hover, code lenses, the way back from generated code, a quick fix, cancellation, and what a
malformed, hostile or vanishing client does to the server (nothing).

usage: lsp_protocol.py CROSSRT CROSSRTD TEMPLATES WORKDIR
"""
import os
import random
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lsp_client import Client, uri  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def check(condition, message):
    if not condition:
        raise AssertionError(message)
    print("ok:", message)


def setup(crossrt, templates, work):
    """A build tree that records Scale's translations, as crossrt_add_class does when it builds."""
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(os.path.join(work, "build"))
    for f in ("Scale.h", "ScaleImpl.cpp"):
        shutil.copy(os.path.join(HERE, f), work)
    open(os.path.join(work, "build", "CMakeCache.txt"), "w").close()
    for backend, suffix in (("vulkan", "Vulkan"), ("cpu", "CPU")):
        out = os.path.join(work, "build", "crossrt", "Scale_" + suffix)
        r = subprocess.run([crossrt, "translate", "--no-daemon", "--build-dir", os.path.join(work, "build"),
                            "--class", "Scale", "--backend", backend, "--out", out,
                            "--source", os.path.join(work, "ScaleImpl.cpp"), "--templates", templates, "--", "-std=c++17"],
                           capture_output=True, text=True)
        records = os.listdir(os.path.join(work, "build", ".crossrt", "requests"))
        check(len(records) == (1 if backend == "vulkan" else 2),
              "crossrt translate records the %s request in the build tree (exit %d), failed or not" % (backend, r.returncode))
        if backend == "vulkan":
            check(r.returncode != 0 and "has no size" in r.stderr, "the build's Vulkan translation fails: the pointers have no size")
            check(not os.path.exists(out), "and writes nothing into its output folder")


def server(crossrtd, work, *extra):
    env = dict(os.environ, XDG_CACHE_HOME=os.path.join(work, "cache"))
    return Client([crossrtd, "--lsp", "--log", os.path.join(work, "lsp.log")] + list(extra), cwd=work, env=env)


def open_file(client, path):
    client.notify("textDocument/didOpen", {"textDocument": {"uri": uri(path), "languageId": "cpp", "version": 1,
                                                            "text": open(path).read()}})


def main_session(crossrtd, work):
    header, source = os.path.join(work, "Scale.h"), os.path.join(work, "ScaleImpl.cpp")
    c = server(crossrtd, work)
    before = c.call("textDocument/hover", {"textDocument": {"uri": uri(source)}, "position": {"line": 0, "character": 0}})
    check(before.get("error", {}).get("code") == -32002, "a request before initialize is refused (ServerNotInitialized)")
    init = c.initialize(work)
    caps = init["result"]["capabilities"]
    check(caps["hoverProvider"] and caps["codeActionProvider"], "initialize announces hover and quick fixes")

    # The header: two errors on Vulkan, none on the CPU, each with its hint and backend.
    open_file(c, header)
    _, diags = c.diagnostics(header, lambda d: len(d) > 0)
    check(len(diags) == 2, "two diagnostics in Scale.h: %s" % [d["message"].split("\n")[0] for d in diags])
    check(all("has no size" in d["message"] and "hint:" in d["message"] for d in diags), "each says what is missing, with its hint")
    check(all(d["source"] == "crossrt (vulkan)" for d in diags), "each names its backend, Vulkan only")
    lines = open(header).read().split("\n")
    first = diags[0]
    line, char = first["range"]["start"]["line"], first["range"]["start"]["character"]
    check(lines[line][char:first["range"]["end"]["character"]] in ("in", "out"), "the range covers the parameter's name")

    # A quick fix: [[crossrt::size("n")]] before the parameter, applied as the editor would.
    actions = c.call("textDocument/codeAction", {"textDocument": {"uri": uri(header)}, "range": first["range"],
                                                 "context": {"diagnostics": [first]}})["result"]
    check(len(actions) == 1 and 'crossrt::size("n")' in actions[0]["title"], "a quick fix adds [[crossrt::size(\"n\")]]: %s"
          % [a["title"] for a in actions])
    edit = actions[0]["edit"]["changes"][uri(header)][0]
    version = 2
    t0 = time.monotonic()
    c.notify("textDocument/didChange", {"textDocument": {"uri": uri(header), "version": version},
                                        "contentChanges": [{"range": edit["range"], "text": edit["newText"]}]})
    t1, diags = c.diagnostics(header, lambda d: len(d) == 1)
    check(True, "after the quick fix one diagnostic is left (%.0f ms after a header edit)" % ((t1 - t0) * 1000))
    # The other by hand, as a whole-text change.
    text = open(header).read().replace("virtual void Run(int n, const float* in, float* out);",
                                       'virtual void Run(int n, [[crossrt::size("n")]] const float* in, [[crossrt::size("n")]] float* out);')
    version += 1
    c.notify("textDocument/didChange", {"textDocument": {"uri": uri(header), "version": version}, "contentChanges": [{"text": text}]})
    _, diags = c.diagnostics(header, lambda d: len(d) == 0)
    check(True, "fixed in the buffer, unsaved: the diagnostics are cleared")
    check("crossrt::size" not in open(header).read(), "the file on disk is untouched")

    # Hover on the kernel: what it becomes on each backend.
    open_file(c, source)
    src = open(source).read().split("\n")
    kline = next(i for i, l in enumerate(src) if "Scale::kernel1D_Scale" in l)
    kchar = src[kline].index("kernel1D_Scale") + 3
    hover = c.call("textDocument/hover", {"textDocument": {"uri": uri(source)}, "position": {"line": kline, "character": kchar}})["result"]
    value = hover["contents"]["value"] if hover else ""
    check("**Vulkan**" in value and "**CPU**" in value, "hover on kernel1D_Scale describes both backends")
    check("workgroups of 256x1x1" in value and "buffer 1: parameter 'in' (`in_[]`, read-only)" in value, "on Vulkan: its workgroups and what it binds:\n" + value)
    cline = next(i for i, l in enumerate(src) if "{ kernel1D_Scale(n, in, out); }" in l)
    call = c.call("textDocument/hover", {"textDocument": {"uri": uri(source)},
                                         "position": {"line": cline, "character": src[cline].index("kernel1D_Scale(") + 1}})["result"]
    check(call and call["contents"]["value"] == value, "hover on the kernel's call in Run says the same")
    nothing = c.call("textDocument/hover", {"textDocument": {"uri": uri(source)}, "position": {"line": 0, "character": 0}})["result"]
    check(nothing is None, "hover elsewhere is clangd's: null")

    # Code lenses open the generated code, kept out of the build tree; and back from it.
    lenses = c.call("textDocument/codeLens", {"textDocument": {"uri": uri(source)}})["result"]
    titles = [l["command"]["title"] for l in lenses]
    check(any("Vulkan: kernel1D_Scale.comp" in t for t in titles) and any(t.startswith("CrossRT CPU") for t in titles),
          "code lenses lead to the shader and the CPU class: %s" % titles)
    lens = next(l for l in lenses if "kernel1D_Scale.comp" in l["command"]["title"])
    shown = c.call("workspace/executeCommand", {"command": lens["command"]["command"], "arguments": lens["command"]["arguments"]})["result"]
    shader = shown["uri"][len("file://"):]
    check(os.path.isfile(shader) and shader.startswith(os.path.join(work, "cache")), "the shader is written under XDG_CACHE_HOME")
    check(not os.path.exists(os.path.join(work, "build", "crossrt", "Scale_Vulkan", "Scale_Vulkan.h")),
          "nothing is generated into the build tree")
    glsl = open(shader).read().split("\n")
    check("Scale::kernel1D_Scale" in glsl[shown["line"] - 1], "the lens's line is the kernel's mark")
    c.notify("textDocument/didOpen", {"textDocument": {"uri": shown["uri"], "languageId": "glsl", "version": 1, "text": "\n".join(glsl)}})
    back = c.call("textDocument/definition", {"textDocument": {"uri": shown["uri"]}, "position": {"line": shown["line"] + 2, "character": 0}})["result"]
    check(back and back["uri"] == uri(source) and back["range"]["start"]["line"] == kline,
          "definition from a generated line leads back to the user's kernel")

    # Cancellation: a request queued behind a translation, cancelled before its answer. The edit, the
    # request and the cancel go in one write: sent apart, a loaded machine could finish the edit's
    # translation and answer the request before the cancel arrived (which the protocol allows).
    rid = c.next_id
    c.next_id += 1
    c.send_together([
        {"jsonrpc": "2.0", "method": "textDocument/didChange",
         "params": {"textDocument": {"uri": uri(source), "version": 2}, "contentChanges": [{"text": open(source).read() + "\n// edited\n"}]}},
        {"jsonrpc": "2.0", "id": rid, "method": "textDocument/hover",
         "params": {"textDocument": {"uri": uri(source)}, "position": {"line": kline, "character": kchar}}},
        {"jsonrpc": "2.0", "method": "$/cancelRequest", "params": {"id": rid}}])
    answer = c.response(rid)
    check(answer.get("error", {}).get("code") == -32800, "a cancelled request is answered RequestCancelled")

    # An error in a helper the kernel calls: related information points back at the kernel.
    text = open(source).read()
    helper = "static float Twice(float v) { float* p = new float[1]; p[0] = v; const float r = 2.0f * p[0]; delete[] p; return r; }\n\n"
    broken = text.replace("void Scale::kernel1D_Scale", helper + "void Scale::kernel1D_Scale").replace("in[2 * i] * m_factor", "Twice(in[2 * i]) * m_factor")
    c.notify("textDocument/didChange", {"textDocument": {"uri": uri(source), "version": 3}, "contentChanges": [{"text": broken}]})
    _, diags = c.diagnostics(source, lambda d: len(d) > 0, version=3)
    new = next(d for d in diags if "'new'" in d["message"])
    lines = broken.split("\n")
    check(lines[new["range"]["start"]["line"]].startswith("static float Twice"), "the error is on the helper's line")
    related = new.get("relatedInformation", [])
    kernel_line = next(i for i, l in enumerate(lines) if "Scale::kernel1D_Scale" in l)
    check(len(related) == 1 and related[0]["message"] == "reached from kernel 'kernel1D_Scale'"
          and related[0]["location"]["range"]["start"]["line"] == kernel_line,
          "its related information points at the kernel that calls it: %s" % related)
    c.notify("textDocument/didChange", {"textDocument": {"uri": uri(source), "version": 4}, "contentChanges": [{"text": text}]})
    c.diagnostics(source, lambda d: len(d) == 0, version=4)
    check(True, "and it clears when the helper goes")

    # Unknown methods and malformed messages: answered, and the server goes on.
    check(c.call("textDocument/rename", {})["error"]["code"] == -32601, "an unknown method: MethodNotFound")
    c.notify("$/unknownNotification", {"x": 1})
    c.send_raw(b"Content-Length: 9\r\n\r\n{not json")
    check(c.wait(lambda m: m.get("error", {}).get("code") == -32700)[1]["id"] is None, "a body that is not JSON: ParseError")
    c.send_raw(b"Content-Length: 2\r\n\r\n[]")
    c.wait(lambda m: m.get("error", {}).get("code") == -32600 and m.get("id") is None)
    check(True, "a message that is not an object: InvalidRequest")
    c.send_raw(b"Content-Length: twelve\r\n\r\n")
    c.wait(lambda m: "Content-Length" in m.get("error", {}).get("message", ""))
    check(True, "a header without a length: InvalidRequest, and the stream goes on")
    hostile = [
        ("textDocument/hover", {"textDocument": 5, "position": "x"}),
        ("textDocument/hover", {"textDocument": {"uri": "file://host/etc/passwd"}, "position": {"line": -1, "character": 1e30}}),
        ("textDocument/codeAction", {"textDocument": {"uri": uri(header)}, "context": {"diagnostics": [{"source": "crossrt", "range": 7}]}}),
        ("textDocument/definition", {"textDocument": {"uri": uri(header)}, "position": {"line": 2 ** 40, "character": 2 ** 40}}),
        ("workspace/executeCommand", {"command": "crossrt.showGenerated", "arguments": [{"uri": 3}]}),
        ("textDocument/hover", []),
    ]
    for method, params in hostile:
        reply = c.call(method, params)
        check("result" in reply or "error" in reply, "a hostile %s is answered: %s" % (method, str(reply.get("error", reply.get("result")))[:60]))
    # Random requests and notifications of the methods the server knows, with parameters of random
    # shapes (seeded: the same 400 every run).
    rng = random.Random(55)
    methods = ["textDocument/hover", "textDocument/codeLens", "textDocument/definition", "textDocument/codeAction",
               "workspace/executeCommand", "textDocument/didChange", "textDocument/didOpen", "textDocument/didSave",
               "$/cancelRequest", "initialize"]

    def junk(depth=0):
        kinds = ["int", "str", "uri", "null", "float", "bool"] + (["list", "dict", "doc", "pos"] if depth < 3 else [])
        k = rng.choice(kinds)
        if k == "int":
            return rng.choice([0, -1, 1, 2 ** 31, -2 ** 63, 2 ** 64, rng.randint(-5, 500)])
        if k == "str":
            return rng.choice(["", "x", "\u0000", "file://", "%zz", "\U0001F600" * 3, "a" * 1000])
        if k == "uri":
            return rng.choice([uri(source), uri(header), "file:///nonexistent/a.cpp", "file://%2e%2e/x", "http://x/y"])
        if k == "null":
            return None
        if k == "float":
            return rng.choice([0.5, 1e308, -0.0])
        if k == "bool":
            return rng.choice([True, False])
        if k == "list":
            return [junk(depth + 1) for _ in range(rng.randint(0, 3))]
        if k == "doc":
            return {"uri": junk(depth + 1), "version": junk(depth + 1), "text": junk(depth + 1)}
        if k == "pos":
            return {"line": junk(depth + 1), "character": junk(depth + 1)}
        return {rng.choice(["textDocument", "position", "context", "contentChanges", "range", "command", "arguments", "id",
                            "text", "diagnostics"]): junk(depth + 1) for _ in range(rng.randint(0, 4))}
    ids = []
    for i in range(400):
        message = {"jsonrpc": "2.0", "method": rng.choice(methods), "params": junk()}
        if rng.random() < 0.5 and message["method"] not in ("textDocument/didOpen", "textDocument/didChange"):
            message["id"] = 10000 + i
            ids.append(10000 + i)
        c.send(message)
    for rid in ids:
        c.response(rid)
    check(c.proc.poll() is None, "400 random messages: every request answered, the server alive")
    # didOpen of junk may have replaced the documents' text: put them back as they are on disk.
    for path in (header, source):
        open_file(c, path)
    for params in ({"textDocument": {"uri": uri(source)}, "contentChanges": [{"range": {"start": {"line": 10 ** 9}}, "text": "x"}]},
                   {"textDocument": {"uri": uri("/nonexistent.cpp")}, "contentChanges": "x"}, None, 17):
        c.send({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": params})
    check(c.call("textDocument/codeLens", {"textDocument": {"uri": uri(source)}})["result"] is not None,
          "after all that, the server still answers")

    check(c.call("shutdown")["result"] is None, "shutdown answers null")
    c.notify("exit")
    check(c.proc.wait(30) == 0, "exit after shutdown: exit code 0")


def vanishing_client(crossrtd, work):
    c = server(crossrtd, work)
    c.initialize(work)
    open_file(c, os.path.join(work, "Scale.h"))
    c.send_raw(b"Content-Length: 100000000000\r\n\r\n{")  # a length it will never send, then gone
    code = c.close(timeout=30)
    check(code == 1, "a client that goes away without shutdown: the server exits by itself with 1, not a signal (%d)" % code)


def main():
    if len(sys.argv) != 5 or sys.argv[1] in ("--help", "-h"):
        print(__doc__.strip())
        sys.exit(0 if sys.argv[1:2] in (["--help"], ["-h"]) else 2)
    crossrt, crossrtd, templates, work = (os.path.abspath(a) for a in sys.argv[1:5])
    setup(crossrt, templates, work)
    main_session(crossrtd, work)
    vanishing_client(crossrtd, work)
    print("OK: the language server passed")


if __name__ == "__main__":
    main()
