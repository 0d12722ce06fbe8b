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
    """Serves the repo root and, under /lut/, the folder of baked tables (never cached: each test bakes its own)."""

    luts: Path = ROOT / "outputs"

    def translate_path(self, path):
        clean = path.split("?", 1)[0].split("#", 1)[0]
        if clean.startswith("/lut/"):
            return str(self.luts / clean[len("/lut/") :])
        return super().translate_path(path)

    def end_headers(self):
        # the engines' pinned npm files may be cached by the browser (a module's second page loads them once);
        # everything else, lutbake's tables above all, never
        immutable = self.path.startswith("/web/node_modules/")
        self.send_header("Cache-Control", "max-age=3600, immutable" if immutable else "no-store")
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


def require(engine_dir: str) -> None:
    """Skips the calling test (pytest) with the reason where the in-engine tests cannot run."""
    import pytest

    why = missing(engine_dir)
    if why:
        pytest.skip(why)


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


# The white-furnace chart every engine page renders (web/furnace.js defaultChart's, at the tests' size): one pixel per
# (NoV, row); 16 perceptual roughnesses 0.05 .. 1 (three.js clamps below 0.045) for each of two materials
N_NOV = 32  # columns: NoV = (i + 0.5) / 32
N_ROUGH = 16  # rows per material
METAL = {"metalness": 1.0, "color": [1.0, 0.5, 0.2]}  # f0 = base colour per channel, f90 = 1
DIELECTRIC = {"metalness": 0.0, "color": [0.0, 0.0, 0.0]}  # f0 = 0.04, no diffuse


def furnace_chart(n_nov: int = N_NOV, n_rough: int = N_ROUGH) -> dict:
    import numpy as np

    nov = (np.arange(n_nov) + 0.5) / n_nov
    rough = 0.05 + 0.95 * np.arange(n_rough) / (n_rough - 1)
    rows = [{**m, "roughness": float(r)} for m in (METAL, DIELECTRIC) for r in rough]
    return {"nov": nov.tolist(), "rows": rows}


def exact_scale_bias(rough, nov):
    """(N, 2) (scale, bias) of GGX with height-correlated Smith at perceptual ``rough``: lutbake's Gauss-Legendre
    integral, converged to 2e-7 (the furnaces' exact answer)."""
    import numpy as np

    from lutbake.integrands import specular

    return specular.hemisphere_integral(
        "ggx", "smith_height_correlated", "scale_bias", nov, np.asarray(rough) ** 2, "gauss_legendre", 1728
    )[:, :2]


def bake_preset(tmp_path_factory, engine_dir: str, preset: str) -> Path:
    """Skips the calling test where the harness cannot run for ``engine_dir``; else bakes lutbake's ``preset`` into a
    fresh folder (served as /lut/) and returns it."""
    from lutbake.api import bake
    from lutbake.config import preset_path

    require(engine_dir)
    luts = tmp_path_factory.mktemp(preset)
    bake([preset_path(preset)], out_dir=luts)
    return luts


def render_furnaces(luts: Path, engine_dir: str, pages, spec: dict, infos: dict | None = None) -> dict:
    """{variant: (height, width, RGB) float pixels} of ``pages`` = [(URL path, {variant: extra spec})], each page
    opened once in one browser and driven through window.furnace (``infos``, if given, gets each variant's ``info``);
    skips the test (pytest) with the reason where the harness cannot run."""
    import numpy as np
    import pytest

    require(engine_dir)
    out = {}
    with serve(luts) as url, browser() as b:
        why = webgl2_problem(b)
        if why:
            pytest.skip(why)
        for path, variants in pages:
            page = open_page(b, url + path)
            for name, extra in variants.items():
                r = page.evaluate("spec => window.furnace(spec)", {**spec, **extra})
                out[name] = np.asarray(r["pixels"], np.float64).reshape(r["height"], r["width"], 4)[..., :3]
                if infos is not None:
                    infos[name] = r.get("info")
            assert not page.errors, page.errors
            page.close()
    return out


def pixel_errors(px, exact_px) -> tuple[float, float]:
    """max and RMS of |pixel - exact answer| over every pixel and channel."""
    import numpy as np

    diff = np.asarray(px) - exact_px
    return float(np.abs(diff).max()), float(np.sqrt(np.mean(diff**2)))


def assert_wrong_load_caught(engine: str, mistake: str, px, exact_px, max_ok: float, rms_ok: float) -> None:
    """A file loaded wrong must leave the tolerance the right load meets, in max and in RMS."""
    worst, rms = pixel_errors(px, exact_px)
    print(f"{engine}, lutbake's file with {mistake}: max {worst:.4g} RMS {rms:.3g}")
    assert worst > max_ok and rms > rms_ok


FILAMENT_WEB = "filament-web"  # the Filament page's files under /lut/: its 64² DFG bakes and the furnace's KTX 1
BABYLON_ASSETS = "babylon"  # Tools.AssetBaseUrl of Babylon's page: /lut/babylon/areaLights/areaLightsLTC.bin


def write_furnace_ibl(folder: Path, size: int = 64, smallest: int = 16) -> Path:
    """The white furnace's image-based light for Filament: a KTX 1 cube of radiance 1 (cmgen's R11F_G11F_B10F, mips
    ``size`` down to ``smallest`` as cmgen's; 1.0 is exact there) and the SH of a constant (form ``filament``: c_0 = 1,
    E / pi = 1), written by lutbake.io.ktx1 to ``folder/filament_furnace_ibl.ktx``."""
    import numpy as np

    from lutbake.io.ktx1 import encode_ktx1_cube

    mips = [np.ones((6, n, n, 3)) for n in (size >> m for m in range(size.bit_length())) if n >= smallest]
    sh = np.zeros((9, 3))
    sh[0] = 1.0
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "filament_furnace_ibl.ktx"
    path.write_bytes(encode_ktx1_cube(mips, "r11g11b10f", sh))
    return path


def demo_files(luts: Path) -> None:
    """What the pages need beside the bakes of make demo: Filament's furnace light, and Babylon's LTC file where its
    loader fetches it (<Tools.AssetBaseUrl>/areaLights/areaLightsLTC.bin)."""
    write_furnace_ibl(luts / FILAMENT_WEB)
    ltc = luts / "areaLightsLTC.bin"
    if ltc.is_file():
        (luts / BABYLON_ASSETS / "areaLights").mkdir(parents=True, exist_ok=True)
        shutil.copyfile(ltc, luts / BABYLON_ASSETS / "areaLights" / ltc.name)


def main():
    parser = argparse.ArgumentParser(description="Serve the engine pages (web/) with lutbake's tables, on 127.0.0.1.")
    parser.add_argument("--luts", type=Path, default=ROOT / "outputs", help="the folder of baked tables (make luts)")
    parser.add_argument("--port", type=int, default=8049)
    args = parser.parse_args()
    demo_files(args.luts)
    with serve(args.luts.resolve(), args.port) as url:
        print(f"open {url}/web/  (tables from {args.luts}; Ctrl-C stops)", flush=True)
        try:
            threading.Event().wait()
        except KeyboardInterrupt:
            pass


if __name__ == "__main__":
    main()
