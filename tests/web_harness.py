"""The in-engine harness: the engines' own npm packages (web/package.json, web/package-lock.json; `npm ci` in web/),
their pages (web/<engine>/), and lutbake's baked files served over HTTP from 127.0.0.1 (an ephemeral port), driven in
the system Chromium (Debian's `chromium`, headless, WebGL2 through SwiftShader) by Playwright for Python. No lutbake
shader code runs in those pages: each engine loads the file through its own loader and material.

`python tests/web_harness.py [--luts outputs]` (make demo) serves the same pages for a person to open."""

from __future__ import annotations

import argparse
import functools
import http.server
import shutil
import threading
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
WEB = ROOT / "web"
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome")
# WebGL2 without a GPU: ANGLE on SwiftShader (Chromium's CPU Vulkan); --enable-unsafe-swiftshader lets Chromium use it
# for WebGL (it refuses SwiftShader without it since Chromium 137)
CHROMIUM_ARGS = (
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--ignore-gpu-blocklist",
    "--no-sandbox",
    "--disable-dev-shm-usage",
)
PAGE_TIMEOUT_MS = 60_000  # a page's first render compiles three.js's / Babylon's shaders in SwiftShader


class _Handler(http.server.SimpleHTTPRequestHandler):
    """Serves the repo root and, under /lut/, the folder of baked tables; no caching (each test bakes its own)."""

    luts: Path = ROOT / "outputs"

    def translate_path(self, path):
        clean = path.split("?", 1)[0].split("#", 1)[0]
        if clean.startswith("/lut/"):
            return str(self.luts / clean[len("/lut/") :])
        return super().translate_path(path)

    def end_headers(self):
        self.send_header("Cache-Control", "no-store")
        super().end_headers()

    def log_message(self, format, *args):  # noqa: A002 - the stdlib's name
        pass


@contextmanager
def serve(luts: Path, port: int = 0):
    """An HTTP server on 127.0.0.1 (``port`` 0: an ephemeral one) in a thread; yields its base URL; stopped after."""
    handler = type("Handler", (_Handler,), {"luts": Path(luts)})
    server = http.server.ThreadingHTTPServer(("127.0.0.1", port), functools.partial(handler, directory=str(ROOT)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


def chromium_path() -> str | None:
    return next((p for p in map(shutil.which, CHROMIUM_NAMES) if p), None)


def missing(engine_dir: str) -> str | None:
    """Why the in-engine tests cannot run here (None: they can)."""
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "playwright is not installed (pip install '.[test]')"
    if chromium_path() is None:
        return "no chromium on PATH (Debian: apt-get install chromium)"
    if not (WEB / "node_modules" / engine_dir).is_dir():
        return f"web/node_modules/{engine_dir} is missing (run `npm ci` in web/)"
    return None


@contextmanager
def browser():
    """The system Chromium, headless, launched by Playwright (no browser download)."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=chromium_path(), headless=True, args=list(CHROMIUM_ARGS))
        try:
            yield b
        finally:
            b.close()


def webgl2_problem(b) -> str | None:
    """None where the browser gives a WebGL2 context, else what it says instead."""
    page = b.new_page()
    try:
        return page.evaluate(
            """() => { const gl = document.createElement('canvas').getContext('webgl2');
                       if (!gl) return 'no WebGL2 context in headless chromium';
                       return gl.getExtension('EXT_color_buffer_float') ? null
                              : 'WebGL2 without EXT_color_buffer_float (no float render targets)'; }"""
        )
    finally:
        page.close()


def open_page(b, url: str):
    """Opens ``url`` and waits for its module to set window.furnaceReady; page errors raise."""
    page = b.new_page()
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(url)
    try:
        page.wait_for_function("window.furnaceReady === true", timeout=PAGE_TIMEOUT_MS)
    except Exception as e:
        raise RuntimeError(f"{url} did not load: {errors or e}") from e
    page.errors = errors
    return page


def main():
    parser = argparse.ArgumentParser(description="Serve the engine pages (web/) with lutbake's tables, on 127.0.0.1.")
    parser.add_argument("--luts", type=Path, default=ROOT / "outputs", help="the folder of baked tables (make luts)")
    parser.add_argument("--port", type=int, default=8049)
    args = parser.parse_args()
    with serve(args.luts.resolve(), args.port) as url:
        print(f"open {url}/web/  (tables from {args.luts}; Ctrl-C stops)", flush=True)
        try:
            threading.Event().wait()
        except KeyboardInterrupt:
            pass


if __name__ == "__main__":
    main()
