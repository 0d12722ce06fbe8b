"""Babylon.js renders lutbake's babylon_environment_brdf.dds in its own renderer (@babylonjs/core pinned in
web/package-lock.json, in headless Chromium, WebGL2 on SwiftShader): the white furnace of web/babylon/furnace.js, a
PBRMaterial (metallic/roughness, Babylon's defaults) under a uniform environment of radiance 1 (a one-level float cube
of ones: every LOD reads 1), one pixel per (NoV, roughness, material), read back as float. Babylon's environment
specular is then, per channel (pbrBlockReflectance, pbrBlockFinalLitComponents; BRDF_V_HEIGHT_CORRELATED,
MS_BRDF_ENERGY_CONSERVATION): ((1 - F0) x + F0 y) (1 + F0 (1 / y - 1)), with (x, y) = environmentBRDF's RG at
vec2(NdotV, perceptualRoughness) and F90 = 1; with the converged integral in place of the table (x = bias,
y = scale + bias: lutbake's Gauss-Legendre, converged to 2e-7) that is the exact answer each pixel is compared with.
Rendered with the table Babylon ships (its base64 RGBD PNG, BRDFTextureTools.GetEnvironmentBRDFTexture, expanded to
half floats by RGBDTextureTools.ExpandRGBDTexture) and with lutbake's `babylon` preset file loaded through Babylon's
own DDS loader as README says (isRGBD false, invertY false), and with lutbake's file loaded wrong on purpose: each
mistake must fail the comparison. Skipped, with the reason, without chromium, playwright, `npm ci` in web/ or WebGL2."""

from __future__ import annotations

import numpy as np
import pytest
import web_harness
from test_babylon import load, rgbd_decode
from test_gl_consumer import bilinear

from lutbake.io.dds import read_dds

DIELECTRIC_F0 = 0.04  # PBRMaterial's default indexOfRefraction 1.5: ((1.5 - 1) / (1.5 + 1))^2
MISTAKES = ("invertY", "rgbd", "swapRG", "transpose")
# Babylon's pixels vs the CPU model of the same texels (bilinear at uv = (NoV, roughness), rows as stored): SwiftShader
# filters a float texture in float32 here; measured 3.9e-7 (lutbake's DDS) and 4.8e-7 (the expanded RGBD PNG)
TEXELS_ATOL = 2e-6
# lutbake's 256² half-float preset against the exact answer: measured max 9.2e-4 (the dielectric at NoV = 1/64,
# roughness 0.05, where the table is steepest), RMS 6.7e-5; Babylon's shipped 8-bit RGBD table: 1.15e-2, 1.31e-3. The
# upload mistakes measured max >= 0.24, RMS >= 0.051.
LUTBAKE_MAX = 2e-3
LUTBAKE_RMS = 2e-4


def furnace_model(xy, spec) -> np.ndarray:
    """Babylon 9.37's furnace pixel (height, width, RGB) from ``xy(roughness, nov) -> (N, 2)`` (the table's R, G):
    environment radiance 1 times the reflectance and its energy-conservation factor; metal F0 = base colour, dielectric
    F0 = 0.04, F90 = 1 (the metal's and the dielectric's, indexOfRefraction 1.5); black albedo or metal: no diffuse."""
    nov = np.asarray(spec["nov"])
    out = []
    for row in spec["rows"]:
        t = xy(np.full_like(nov, row["roughness"]), nov)
        x, y = t[:, :1], t[:, 1:2]
        f0 = np.asarray(row["color"]) if row["metalness"] == 1 else np.full(3, DIELECTRIC_F0)
        out.append(((1 - f0) * x + f0 * y) * (1 + f0 * (1 / y - 1)))
    return np.stack(out)


def exact(rough, nov):
    scale, bias = web_harness.exact_scale_bias(rough, nov).T
    return np.stack([bias, scale + bias], axis=1)


def table(lut):
    """The (roughness rows, NoV columns, C) table's RG sampled as Babylon does: bilinear at uv = (NoV, roughness)."""
    return lambda rough, nov: bilinear(lut[..., :2], np.stack([nov, rough], axis=1))


def shipped_table() -> np.ndarray:
    """Babylon's PNG (tests/data: the same bytes, sha256 in its note, as @babylonjs/core 9.37.1's base64) as
    ExpandRGBDTexture leaves it: fromRGBD into a half-float target."""
    return rgbd_decode(load("babylon_environment_brdf")[1]).astype(np.float16).astype(np.float64)


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    """{variant: (height, width, RGB) float pixels}: shipped, lutbake, and lutbake's file under each mistake."""
    luts = web_harness.bake_preset(tmp_path_factory, "@babylonjs/core", "babylon")
    spec = web_harness.furnace_chart()
    variants = {"shipped": {"lut": "shipped"}, "lutbake": {"lut": "lutbake"}}
    variants.update({m: {"lut": "lutbake", "mistake": m} for m in MISTAKES})
    variants.update({f"{lut} anisotropic": {"lut": lut, "anisotropy": 4} for lut in ("shipped", "lutbake")})
    out = web_harness.render_furnaces(luts, "@babylonjs/core", [("/web/babylon/furnace.html?driver", variants)], spec)
    out["spec"] = spec
    out["lutbake_table"] = read_dds(luts / "babylon_environment_brdf.dds").data.astype(np.float64)
    return out


def errors(px, spec):
    return web_harness.pixel_errors(px, furnace_model(exact, spec))


def test_babylon_white_metal_is_white_at_every_roughness(renders):
    # the red channel of the metal rows: F0 = F90 = 1, where Babylon's energy conservation 1 + F0 (1 / y - 1) restores
    # all energy whatever the table holds (y (1 / y)); the environment's radiance reads 1 at every LOD
    for variant in ("shipped", "lutbake"):
        np.testing.assert_allclose(renders[variant][: web_harness.N_ROUGH, :, 0], 1.0, atol=1e-6)


def test_babylon_samples_lutbakes_file_as_its_contract_says(renders):
    """Babylon's pixels are the CPU model of the DDS's texels: isRGBD false (no decode), invertY false (row 0 at v = 0,
    roughness 0), R = bias, G = scale + bias read at vec2(NdotV, perceptualRoughness)."""
    model = furnace_model(table(renders["lutbake_table"]), renders["spec"])
    np.testing.assert_allclose(renders["lutbake"], model, rtol=0, atol=TEXELS_ATOL)


def test_babylon_renders_shipped_table_as_the_cpu_model(renders):
    model = furnace_model(table(shipped_table()), renders["spec"])
    np.testing.assert_allclose(renders["shipped"], model, rtol=0, atol=TEXELS_ATOL)


def test_babylon_furnace_with_lutbakes_table_is_within_its_interpolation_error(renders):
    for sampler in ("", " anisotropic"):
        worst, rms = errors(renders["lutbake" + sampler], renders["spec"])
        shipped_worst, shipped_rms = errors(renders["shipped" + sampler], renders["spec"])
        print(f"Babylon{sampler} vs exact: shipped max {shipped_worst:.4g} RMS {shipped_rms:.3g}", end=", ")
        print(f"lutbake {worst:.4g} {rms:.3g}")
    worst, rms = errors(renders["lutbake"], renders["spec"])
    assert worst < LUTBAKE_MAX and rms < LUTBAKE_RMS


@pytest.mark.parametrize("mistake", MISTAKES)
def test_babylon_furnace_catches_a_wrong_load(renders, mistake):
    exact_px = furnace_model(exact, renders["spec"])
    web_harness.assert_wrong_load_caught(
        "Babylon furnace", mistake, renders[mistake], exact_px, LUTBAKE_MAX, LUTBAKE_RMS
    )
