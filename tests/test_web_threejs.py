"""three.js renders lutbake's DFGLUTData.js in its own renderer (the npm package pinned in web/package-lock.json, in
headless Chromium, WebGL2 on SwiftShader): the white furnace of web/threejs/furnace.js, a MeshStandardMaterial under a
uniform environment of radiance 1 through three.js's own PMREM, one pixel per (NoV, roughness, material), read back as
float. three.js's indirect specular is then its split sum with Fdez-Agüera's multiscattering (lights_physical_pars:
computeMultiscattering) of the DFG texel pair at (roughness, NoV); with the converged integral in place of the table
(lutbake's Gauss-Legendre, converged to 2e-7) that is the exact answer each pixel is compared with. Rendered with the
table three.js ships and with lutbake's preset file swapped in for three.js's DFGLUTData module (an import map), and
with lutbake's file loaded wrong on purpose: each mistake must fail the comparison. Skipped, with the reason, without
chromium, playwright, `npm ci` in web/ or WebGL2."""

from __future__ import annotations

import re

import numpy as np
import pytest
import web_harness
from test_gl_consumer import bilinear

THREE = web_harness.WEB / "node_modules" / "three"
SHIPPED = THREE / "src" / "renderers" / "shaders" / "DFGLUTData.js"
MISTAKES = ("flipY", "swapRG", "transpose")
# three.js vs the CPU model of the same texels: GPUs weight texels with 8 fractional bits (SwiftShader too), so up to
# 2^-8 of a texel step (<= 0.05 in a 16² table) after the compensation, and float32 through PMREM's half-float mips
SUBTEXEL = 2.0**-8 * 0.05 + 1e-5
# lutbake's 16² preset against the exact answer is a 16² table's bilinear error, as three.js's own: measured max 0.0679
# (the dielectric at NoV = 1/64, below the first texel centre, where clamp-to-edge holds NoV = 1/32; roughness 0.05),
# RMS 0.0034 (three.js's shipped table: 0.0679, 0.0035). The upload mistakes measured max >= 0.238, RMS >= 0.054.
LUTBAKE_MAX = 0.08
LUTBAKE_RMS = 0.005


def read_js_halfs(path) -> np.ndarray:
    """A three.js DFG module's Uint16Array of half floats as (16 NoV rows, 16 roughness columns, RG)."""
    text = path.read_text()
    body = text[text.index("Uint16Array(") :]
    bits = np.array([int(h, 16) for h in re.findall(r"0x[0-9a-fA-F]{4}", body)], np.uint16)
    return bits.view(np.float16).astype(np.float64).reshape(16, 16, 2)


def furnace_model(dfg, spec) -> np.ndarray:
    """three.js r187's furnace pixel (height, width, RGB) from ``dfg(roughness, nov) -> (N, 2)`` (scale, bias):
    RE_IndirectSpecular_Physical with radiance = irradiance / pi = 1."""
    nov = np.asarray(spec["nov"])
    out = []
    for row in spec["rows"]:
        fab = dfg(np.full_like(nov, row["roughness"]), nov)
        a, b = fab[:, :1], fab[:, 1:2]
        ess = a + b
        ems = 1 - ess

        def scatter(f):
            ss = f * a + b
            favg = f + (1 - f) / 21
            return ss, ss * favg / (1 - ems * favg) * ems

        ss_d, ms_d = scatter(np.full(3, 0.04))
        ss_m, ms_m = scatter(np.asarray(row["color"]))
        m = row["metalness"]
        diffuse = np.asarray(row["color"]) * (1 - m) * (1 - (ss_d + ms_d))
        out.append((1 - m) * (ss_d + ms_d) + m * (ss_m + ms_m) + diffuse)
    return np.stack(out)


def table(lut):
    return lambda rough, nov: bilinear(lut, np.stack([rough, nov], axis=1))


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    """{variant: (height, width, RGB) float pixels}: shipped, lutbake, and lutbake's file under each mistake."""
    luts = web_harness.bake_preset(tmp_path_factory, "three", "threejs")
    spec = web_harness.furnace_chart()
    page = "/web/threejs/furnace.html?driver&lut="
    mistakes = {m: {"mistake": m} for m in MISTAKES}
    out = web_harness.render_furnaces(
        luts, "three", [(page + "shipped", {"shipped": {}}), (page + "lutbake", {"lutbake": {}, **mistakes})], spec
    )
    out["spec"] = spec
    out["lutbake_file"] = luts / "DFGLUTData.js"
    return out


def errors(px, spec):
    return web_harness.pixel_errors(px, furnace_model(web_harness.exact_scale_bias, spec))


def test_threejs_white_metal_is_white_at_every_roughness(renders):
    # the red channel of the metal rows: f0 = f90 = 1, where Fdez-Agüera's compensation restores all energy whatever
    # the table holds; the float render target keeps it to float32 through PMREM
    for variant in ("shipped", "lutbake"):
        np.testing.assert_allclose(renders[variant][: web_harness.N_ROUGH, :, 0], 1.0, atol=1e-5)


def test_threejs_samples_lutbakes_file_as_its_contract_says(renders):
    """three.js's pixels are the CPU model of the file's texels, bilinear at uv = (roughness, NoV), rows as stored."""
    model = furnace_model(table(read_js_halfs(renders["lutbake_file"])), renders["spec"])
    np.testing.assert_allclose(renders["lutbake"], model, rtol=0, atol=SUBTEXEL)


def test_threejs_renders_shipped_table_as_the_cpu_model(renders):
    model = furnace_model(table(read_js_halfs(SHIPPED)), renders["spec"])
    np.testing.assert_allclose(renders["shipped"], model, rtol=0, atol=SUBTEXEL)


def test_threejs_furnace_with_lutbakes_table_is_within_its_interpolation_error(renders):
    worst, rms = errors(renders["lutbake"], renders["spec"])
    shipped_worst, shipped_rms = errors(renders["shipped"], renders["spec"])
    print(f"three.js vs exact: shipped max {shipped_worst:.4g} RMS {shipped_rms:.3g}, lutbake {worst:.4g} {rms:.3g}")
    assert worst < LUTBAKE_MAX and rms < LUTBAKE_RMS


@pytest.mark.parametrize("mistake", MISTAKES)
def test_threejs_furnace_catches_a_wrong_load(renders, mistake):
    exact_px = furnace_model(web_harness.exact_scale_bias, renders["spec"])
    web_harness.assert_wrong_load_caught(
        "three.js furnace", mistake, renders[mistake], exact_px, LUTBAKE_MAX, LUTBAKE_RMS
    )
