"""A small Language Server Protocol client for crossrtd --lsp: the tests' and the benchmark's.

It speaks the base protocol (Content-Length framing) over the server's stdin and stdout, reads on
a thread of its own, and lets a caller wait for a response or for a notification that satisfies a
predicate, with a timeout.
"""
import json
import os
import queue
import subprocess
import threading
import time


def uri(path):
    return "file://" + os.path.abspath(path)


class Client:
    def __init__(self, argv, cwd=None, env=None):
        self.proc = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, cwd=cwd, env=env)
        self.messages = queue.Queue()
        self.next_id = 1
        self.pending = []  # messages read but not yet taken by a wait
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        out = self.proc.stdout
        while True:
            length = None
            while True:
                line = out.readline()
                if not line:
                    self.messages.put(None)
                    return
                line = line.strip()
                if not line:
                    break
                name, _, value = line.decode().partition(":")
                if name.lower() == "content-length":
                    length = int(value.strip())
            body = out.read(length)
            self.messages.put((time.monotonic(), json.loads(body)))

    def send_raw(self, data):
        self.proc.stdin.write(data)
        self.proc.stdin.flush()

    @staticmethod
    def frame(message):
        body = json.dumps(message).encode()
        return b"Content-Length: %d\r\n\r\n" % len(body) + body

    def send(self, message):
        self.send_raw(self.frame(message))

    def send_together(self, messages):
        """Writes several messages in one write, so that the server reads them back to back."""
        self.send_raw(b"".join(self.frame(m) for m in messages))

    def request(self, method, params=None):
        rid = self.next_id
        self.next_id += 1
        self.send({"jsonrpc": "2.0", "id": rid, "method": method, "params": params or {}})
        return rid

    def notify(self, method, params=None):
        self.send({"jsonrpc": "2.0", "method": method, "params": params or {}})

    def wait(self, predicate, timeout=60.0, what="a message"):
        """The first message (time read, message) that satisfies predicate; earlier ones stay pending."""
        for i, (t, m) in enumerate(self.pending):
            if predicate(m):
                del self.pending[i]
                return t, m
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError("no %s within %.0f s" % (what, timeout))
            try:
                item = self.messages.get(timeout=left)
            except queue.Empty:
                continue
            if item is None:
                raise EOFError("the server closed its output while waiting for %s" % what)
            if predicate(item[1]):
                return item
            self.pending.append(item)

    def response(self, rid, timeout=60.0):
        return self.wait(lambda m: m.get("id") == rid and "method" not in m, timeout, "the response to request %s" % rid)[1]

    def call(self, method, params=None, timeout=60.0):
        return self.response(self.request(method, params), timeout)

    def diagnostics(self, path, predicate=lambda d: True, timeout=60.0, version=None):
        """The next diagnostics published for path (of that document version, if given) whose list
        satisfies predicate: (time, list)."""
        target = uri(path)

        def match(m):
            return (m.get("method") == "textDocument/publishDiagnostics" and m["params"]["uri"] == target
                    and (version is None or m["params"].get("version") == version)
                    and predicate(m["params"]["diagnostics"]))
        t, m = self.wait(match, timeout, "diagnostics for " + path)
        return t, m["params"]["diagnostics"]

    def initialize(self, root, options=None):
        result = self.call("initialize", {"processId": os.getpid(), "rootUri": uri(root), "capabilities": {},
                                          "initializationOptions": options or {}})
        self.notify("initialized", {})
        return result

    def close(self, timeout=30.0):
        self.proc.stdin.close()
        return self.proc.wait(timeout)
