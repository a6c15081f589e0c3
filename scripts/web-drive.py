#!/usr/bin/env python3
"""Drives the built page (web/dist) in headless Chromium over the DevTools protocol (a pipe, no
extra packages): serves the site on a loopback port, loads each query of the automation
contract (docs/web.md) in one page, one after another, and prints a JSON list with, per query,
the page's title and its `#shadowlab-result`; with --screenshot FILE it also saves a PNG of the
page after the last query and reports whether it is blank.

Usage: scripts/web-drive.py [--dist web/dist] [--screenshot FILE] [--timeout S] QUERY [QUERY...]
The first query is loaded as the page's URL; the following run on the same page through
`window.shadowlab.run` (as a person pressing Run again).
"""
import argparse
import base64
import functools
import http.server
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time
import zlib

CHROMIUM = "/usr/bin/chromium"


class Quiet(http.server.SimpleHTTPRequestHandler):
    extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, ".wasm": "application/wasm", ".js": "text/javascript"}

    def log_message(self, *args):
        pass


class Cdp:
    """The DevTools protocol over --remote-debugging-pipe: JSON messages ended by NUL."""

    def __init__(self, proc, to_chrome, from_chrome):
        self.proc, self.out, self.inp = proc, to_chrome, from_chrome
        self.next_id, self.buf = 0, b""

    def call(self, method, params=None, session=None, timeout=60):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self.out, json.dumps(msg).encode() + b"\0")
        end = time.time() + timeout
        while time.time() < end:
            while b"\0" in self.buf:
                raw, self.buf = self.buf.split(b"\0", 1)
                reply = json.loads(raw)
                if reply.get("id") == self.next_id:
                    if "error" in reply:
                        raise RuntimeError(f"{method}: {reply['error']}")
                    return reply.get("result", {})
            chunk = os.read(self.inp, 1 << 20)
            if not chunk:
                raise RuntimeError(f"Chromium closed the pipe during {method}")
            self.buf += chunk
        raise TimeoutError(method)

    def evaluate(self, session, expr, await_promise=False, timeout=60):
        r = self.call("Runtime.evaluate", {"expression": expr, "returnByValue": True, "awaitPromise": await_promise}, session, timeout)
        if "exceptionDetails" in r:
            raise RuntimeError(f"{expr}: {r['exceptionDetails']}")
        return r["result"].get("value")


def png_is_blank(data):
    """Whether a PNG (8-bit RGB or RGBA, as Chromium writes) has a single colour."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, w, h, ctype = 8, b"", 0, 0, 0
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos : pos + 8])
        body = data[pos + 8 : pos + 8 + n]
        if kind == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and ctype in (2, 6), f"PNG depth {depth} type {ctype}"
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    bpp = 4 if ctype == 6 else 3
    raw, stride = zlib.decompress(idat), w * bpp
    prev, colours = bytearray(stride), set()
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1 : (y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        for x in range(0, stride, bpp * 7):
            colours.add(bytes(line[x : x + bpp]))
        prev = line
        if len(colours) > 1:
            return False
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dist", default=os.path.join(os.path.dirname(__file__), "..", "web", "dist"))
    ap.add_argument("--screenshot")
    ap.add_argument("--timeout", type=float, default=300)
    ap.add_argument("queries", nargs="+")
    a = ap.parse_args()
    if not os.path.exists(os.path.join(a.dist, "index.html")):
        sys.exit(f"error: {a.dist}/index.html missing: run `make web` first")
    if not os.path.exists(CHROMIUM):
        sys.exit(f"error: {CHROMIUM} missing: run `make setup` (scripts/setup.sh installs it)")
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=a.dist))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}/index.html"
    profile = tempfile.mkdtemp(prefix="shadowlab-web-")
    cmd_r, cmd_w = os.pipe()
    res_r, res_w = os.pipe()

    def fds():
        os.dup2(cmd_r, 3)
        os.dup2(res_w, 4)

    flags = ["--headless=new", "--no-sandbox", "--enable-unsafe-webgpu", "--enable-unsafe-swiftshader", "--disable-quic",
             "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync",
             "--window-size=1200,1400", f"--user-data-dir={profile}", "--remote-debugging-pipe", "about:blank"]
    proc = subprocess.Popen([CHROMIUM] + flags, preexec_fn=fds, close_fds=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(cmd_r)
    os.close(res_w)
    out = []
    try:
        cdp = Cdp(proc, cmd_w, res_r)
        target = cdp.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = cdp.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        cdp.call("Page.enable", session=session)
        for i, q in enumerate(a.queries):
            t0 = time.time()
            if q.startswith("eval:"):
                # a script for the page (window.shadowlab.loseDevice()), not a run
                value = cdp.evaluate(session, q[len("eval:"):], True, a.timeout)
                out.append({"query": q, "value": value})
                continue
            if i == 0:
                cdp.call("Page.navigate", {"url": f"{base}?{q}"}, session)
                title = ""
                while not (title.startswith("shadowlab: done") or title.startswith("shadowlab: error")):
                    if time.time() - t0 > a.timeout:
                        raise TimeoutError(f"page still '{title}' after {a.timeout} s")
                    time.sleep(0.25)
                    title = cdp.evaluate(session, "document.title") or ""
            else:
                cdp.evaluate(session, f"window.shadowlab.run({json.dumps(q)}).then(() => document.title)", True, a.timeout)
                title = cdp.evaluate(session, "document.title")
            result = cdp.evaluate(session, "document.getElementById('shadowlab-result').textContent")
            out.append({"query": q, "title": title, "seconds": round(time.time() - t0, 2),
                        "result": json.loads(result) if result else None})
        if a.screenshot:
            shot = base64.b64decode(cdp.call("Page.captureScreenshot", {"format": "png", "captureBeyondViewport": True}, session)["data"])
            with open(a.screenshot, "wb") as f:
                f.write(shot)
            out.append({"screenshot": a.screenshot, "blank": png_is_blank(shot)})
    finally:
        proc.kill()
        proc.wait()
        server.shutdown()
        shutil.rmtree(profile, ignore_errors=True)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
