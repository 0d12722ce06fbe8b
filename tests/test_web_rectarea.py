"""three.js's RectAreaLight with lutbake's ltc_threejs.js (the `ltc-threejs` preset) in its own renderer (the npm
package pinned in web/package-lock.json, headless Chromium, WebGL2 on SwiftShader): web/threejs/rectarea.js, one
rectangular light of radiance 1 over a chart of 1-pixel MeshStandardMaterial quads (NoV per column, roughness per
row; a metal of base colour (1, 0.5, 0.2) and a black dielectric, f0 = 0.04, F90 = 1), nothing else lit, read back as
float. Each pixel is three.js's LTC shading (RE_Direct_RectArea_Physical: LTC_Uv, the two 64² tables, LTC_Evaluate's
rational edge integral and clipped-sphere horizon, fresnel = F0 t2.x + (F90 - F0) t2.y) at its own shading point,
normal and light polygon. Compared with (a) a numpy port of that shader reading the same file's texels: the upload
contract (the tables three.js builds in RectAreaLightUniformsLib.init(): 64² RGBA float, linear, clamp, flipY false;
lutbake's arrays written into the same textures); (b) the exact answer: the polygon-light integral of GGX with
height-correlated Smith and Schlick's Fresnel at each pixel's (v, roughness, polygon), by lutbake's area-light
benchmark's ground truth (lutbake.validate.ltc_bench.ground_truth: stratified visible-normal sampling), for three.js's
shipped tables and lutbake's; (c) lutbake's file loaded wrong on purpose (LTC_1 and LTC_2 exchanged, flipY): each
must fail. Babylon.js's RectAreaLight with lutbake's areaLightsLTC.bin (the `ltc-babylon` preset) below, on the same
chart, light and truth; both presets are baked in one batch (one fit). Skipped, with the reason, without chromium,
playwright, `npm ci` in web/ or WebGL2."""

from __future__ import annotations

import re

import numpy as np
import pytest
import web_harness
from test_gl_consumer import bilinear

from lutbake.api import bake
from lutbake.config import preset_path
from lutbake.validate import ltc_bench

SHIPPED = web_harness.WEB / "node_modules" / "three" / "examples" / "jsm" / "lights" / "RectAreaLightTexturesLib.js"
# the chart: 16 NoV columns x 8 roughnesses (0.05 .. 1) x two materials, 1/16 world units per pixel: a unit square at
# z = 0 (the ground truth costs a sample grid per pixel)
N_NOV, N_ROUGH = 16, 8
SCALE = 1 / 16
# the light (rectarea.js's demo light): 1 x 0.6, centred above the chart's top edge, facing the chart's centre
LIGHT = {"position": [0.5, 1.1, 0.9], "target": [0.5, 0.5, 0.0], "width": 1.0, "height": 0.6, "intensity": 1.0}
VIEW = np.array([0.0, 0.0, 1.0])  # three.js's view direction under an orthographic camera
GT_SAMPLES = (
    128  # ground truth: a stratified 128 x 128 visible-normal grid per pixel (96² vs 256²: 1.1e-3 apart at most)
)
DIELECTRIC_F0 = 0.04
MISTAKES = ("swap", "flipY")
# three.js's pixels vs the numpy port of its shader on the same texels: float32 shader arithmetic on values <= 1 (the
# FLOAT textures: OES_texture_float_linear holds in SwiftShader; the HALF pair would be ~1e-4 off); measured 1.6e-7
# (lutbake's file) and 8.9e-8 (three.js's) here, 2.8e-6 and 6.3e-6 on a 32 x 32 chart of the same square
SHADER_ATOL = 2e-5
# against the polygon-light integral: measured max 0.0245, RMS 2.69e-3 with lutbake's tables (three.js's: 0.0247,
# 2.75e-3): the LTC lobe's and three.js's horizon approximation (LTC_ClippedSphereFormFactor), the same with either
# table; relative error where the truth exceeds 1e-3 of its maximum: median 0.110 (three.js's 0.109). The wrong loads
# measured max >= 0.999, RMS >= 0.059.
LUTBAKE_MAX = 0.035
LUTBAKE_RMS = 3.5e-3
LUTBAKE_MEDIAN_REL = 0.12
REL_FLOOR = 1e-3  # relative errors where the truth exceeds this fraction of its largest pixel
NUMBER = r"[-+]?\s*(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def ltc_arrays(text: str) -> tuple[np.ndarray, np.ndarray]:
    """LTC_MAT_1, LTC_MAT_2 of a three.js LTC module's text as (64 rows t, 64 columns roughness, RGBA) float32
    (three.js's own file writes a space after a minus sign)."""
    out = []
    for name in ("LTC_MAT_1", "LTC_MAT_2"):
        body = text[re.search(rf"{name} = (new Float32Array\()?\[", text).end() :]
        body = body[: body.index("]")]
        out.append(
            np.array([float(x.replace(" ", "")) for x in re.findall(NUMBER, body)], np.float32).reshape(64, 64, 4)
        )
    return out[0], out[1]


def light_corners(light) -> np.ndarray:
    """(4, 3) world corners in three.js's order (rectCoords: pos + hw - hh, pos - hw - hh, pos - hw + hh,
    pos + hw + hh), the light oriented by Object3D.lookAt (a light's +z points away from its target)."""
    pos, target = np.asarray(light["position"]), np.asarray(light["target"])
    z = (pos - target) / np.linalg.norm(pos - target)
    x = np.cross([0.0, 1.0, 0.0], z)
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    hw, hh = x * light["width"] / 2, y * light["height"] / 2
    return np.array([pos + hw - hh, pos - hw - hh, pos - hw + hh, pos + hw + hh])


def pixels(spec):
    """Per pixel (rows x columns, flattened): shading point, normal, perceptual roughness, F0 (RGB)."""
    nov = np.asarray(spec["nov"])
    h, w = len(spec["rows"]), len(nov)
    jj, ii = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    p = np.stack([(ii + 0.5) * SCALE, (jj + 0.5) * SCALE, np.zeros_like(ii, float)], -1).reshape(-1, 3)
    c = np.tile(nov, h)
    n = np.stack([np.zeros_like(c), np.sqrt(1 - c * c), c], -1)
    rough = np.repeat([r["roughness"] for r in spec["rows"]], w)
    f0 = np.repeat([r["color"] if r["metalness"] == 1 else [DIELECTRIC_F0] * 3 for r in spec["rows"]], w, axis=0)
    return p, n, rough, f0


def _edge(v1, v2):
    """three.js's LTC_EdgeVectorFormFactor: cross(v1, v2) theta / sin(theta) / 2 pi, its rational fit."""
    x = np.sum(v1 * v2, -1)
    y = np.abs(x)
    v = (0.8543985 + (0.4965155 + 0.0145206 * y) * y) / (3.4175940 + (4.1616724 + y) * y)
    ts = np.where(x > 0, v, 0.5 / np.sqrt(np.maximum(1 - x * x, 1e-7)) - v)
    return np.cross(v1, v2) * ts[:, None]


def ltc_shading(ltc1, ltc2, rough, p, n, v, corners) -> tuple[np.ndarray, np.ndarray]:
    """(t2 (N, 4), the LTC integral (N,)) at shading points ``p``, normals ``n``, view vectors ``v`` (N, 3) of the
    polygon ``corners`` (4, 3) in the shader's order: three.js's LTC_Uv and LTC_Evaluate (Babylon's LTCUv and
    LTCEvaluate are the same code) written out in numpy, the back-of-the-light test included."""
    nov = np.clip(np.sum(n * v, axis=1), 0, 1)
    uv = np.stack([rough, np.sqrt(1 - nov)], 1) * 63 / 64 + 0.5 / 64
    t1, t2 = bilinear(ltc1, uv), bilinear(ltc2, uv)
    minv = np.zeros((len(p), 3, 3))  # mat3(vec3(t1.x, 0, t1.y), vec3(0, 1, 0), vec3(t1.z, 0, t1.w)), columns
    minv[:, 0, 0], minv[:, 2, 0], minv[:, 0, 2], minv[:, 2, 2] = t1.T
    minv[:, 1, 1] = 1
    tt1 = v - n * nov[:, None]
    tt1 /= np.linalg.norm(tt1, axis=1, keepdims=True)
    tt2 = -np.cross(n, tt1)
    frame = np.stack([tt1, tt2, n], 1)  # rows: transpose(mat3(T1, T2, N))
    mat = minv @ frame
    coords = np.einsum("pij,kpj->kpi", mat, corners[:, None, :] - p[None])
    coords /= np.linalg.norm(coords, axis=2, keepdims=True)
    f = sum(_edge(coords[k], coords[(k + 1) % 4]) for k in range(4))
    length = np.linalg.norm(f, axis=1)
    form = np.maximum((length * length + f[:, 2]) / (length + 1), 0)
    lit = (p - corners[0]) @ np.cross(corners[1] - corners[0], corners[3] - corners[0]) >= 0
    return t2, np.where(lit, form, 0.0)


def shader_model(ltc1, ltc2, spec, light=LIGHT) -> np.ndarray:
    """three.js r187's pixel (height, width, RGB) with the tables ``ltc1``, ``ltc2`` ((t, roughness, RGBA) texels):
    RE_Direct_RectArea_Physical, LTC_Uv, LTC_Evaluate, LTC_ClippedSphereFormFactor written out in numpy."""
    p, n, rough, f0 = pixels(spec)
    t2, form = ltc_shading(ltc1, ltc2, rough, p, n, np.broadcast_to(VIEW, p.shape), light_corners(light))
    fresnel = f0 * t2[:, :1] + (1 - f0) * t2[:, 1:2]
    value = light["intensity"] * fresnel * form[:, None]
    return value.reshape(len(spec["rows"]), len(spec["nov"]), 3)


def ground_truth(spec, light=LIGHT) -> np.ndarray:
    """The exact pixel (height, width, RGB): radiance x ∫_P f (n.l) dω with f = GGX, height-correlated Smith and
    Schlick's F = F0 + (1 - F0)(1 - v.h)^5, the polygon in each pixel's shading frame (z = n, v in the xz plane)."""
    p, n, rough, f0 = pixels(spec)
    corners = light_corners(light)
    out = np.empty((len(p), 3))
    for k in range(len(p)):
        c = float(n[k] @ VIEW)
        x = VIEW - n[k] * c
        x /= np.linalg.norm(x)
        poly = (corners - p[k]) @ np.stack([x, np.cross(n[k], x), n[k]], 1)
        if np.cross(poly[0], poly[1]) @ poly.mean(0) < 0:  # counter-clockwise seen from the shading point
            poly = poly[::-1]
        theta = np.degrees(np.arccos(np.clip(c, -1, 1)))
        gt = ltc_bench.ground_truth({"theta": theta, "r": rough[k], "lights": poly[None]}, GT_SAMPLES)
        out[k] = light["intensity"] * (f0[k] * gt["lobe"][0] + (1 - f0[k]) * gt["schlick"][0])
    return out.reshape(len(spec["rows"]), len(spec["nov"]), 3)


@pytest.fixture(scope="module")
def ltc_luts(tmp_path_factory):
    """lutbake's `ltc-threejs` and `ltc-babylon` baked in one batch (one fit: the two tables share their values, the
    costly part of this module), and Babylon's asset folders: ``<luts>/<name>/areaLights/areaLightsLTC.bin`` for
    lutbake's file, the file with each mistake, and three.js's shipped tables in Babylon's layout."""
    luts = tmp_path_factory.mktemp("ltc")
    bake([preset_path("ltc-threejs"), preset_path("ltc-babylon")], luts)
    ours = (luts / "areaLightsLTC.bin").read_bytes()
    texels = np.frombuffer(ours, "<f2").reshape(64, 64, 8)
    shipped = np.concatenate(ltc_arrays(SHIPPED.read_text()), axis=-1)
    folders = {
        "lutbake": ours,
        "swap": np.concatenate([texels[..., 4:], texels[..., :4]], -1).tobytes(),
        "flipY": texels[::-1].tobytes(),
        "threejs": shipped.astype("<f2").tobytes(),
    }
    for name, data in folders.items():
        (luts / f"babylon-{name}" / "areaLights").mkdir(parents=True)
        (luts / f"babylon-{name}" / "areaLights" / "areaLightsLTC.bin").write_bytes(data)
    return luts


@pytest.fixture(scope="module")
def truth():
    """The polygon integral at every pixel of the chart (three.js's frame; Babylon's is its mirror image in z)."""
    return ground_truth({**web_harness.furnace_chart(N_NOV, N_ROUGH), "light": LIGHT, "scale": SCALE})


@pytest.fixture(scope="module")
def renders(ltc_luts, truth):
    """{variant: (height, width, RGB) float pixels}: shipped, lutbake, and lutbake's file under each mistake."""
    web_harness.require("three")
    spec = {**web_harness.furnace_chart(N_NOV, N_ROUGH), "light": LIGHT, "scale": SCALE}
    variants = {"shipped": {"lut": "shipped"}, "lutbake": {"lut": "lutbake"}}
    variants.update({m: {"lut": "lutbake", "mistake": m} for m in MISTAKES})
    out = web_harness.render_furnaces(ltc_luts, "three", [("/web/threejs/rectarea.html?driver", variants)], spec)
    out["spec"] = spec
    out["lutbake_tables"] = ltc_arrays((ltc_luts / "ltc_threejs.js").read_text())
    out["truth"] = truth
    return out


def relative(px, truth) -> np.ndarray:
    keep = truth > REL_FLOOR * truth.max()
    return np.abs(px - truth)[keep] / truth[keep]


def test_threejs_rectarea_samples_lutbakes_file_as_its_contract_says(renders):
    """three.js's pixels are its shader on the file's texels: LTC_MAT_1 / LTC_MAT_2 as 64² RGBA rows t =
    sqrt(1 - NoV), columns roughness, endpoint texels (LTC_Uv), flipY false, t1 = M^-1 (m00, m20, m02, m22)."""
    model = shader_model(*renders["lutbake_tables"], renders["spec"])
    print(f"three.js RectAreaLight vs its shader on lutbake's texels: {np.abs(renders['lutbake'] - model).max():.3g}")
    np.testing.assert_allclose(renders["lutbake"], model, rtol=0, atol=SHADER_ATOL)


def test_threejs_rectarea_renders_shipped_tables_as_the_shader_model(renders):
    model = shader_model(*ltc_arrays(SHIPPED.read_text()), renders["spec"])
    print(f"three.js RectAreaLight vs its shader on its own texels: {np.abs(renders['shipped'] - model).max():.3g}")
    np.testing.assert_allclose(renders["shipped"], model, rtol=0, atol=SHADER_ATOL)


def test_threejs_rectarea_with_lutbakes_tables_is_as_close_to_the_polygon_integral_as_threes_own(renders):
    truth = renders["truth"]
    for name in ("shipped", "lutbake"):
        worst, rms = web_harness.pixel_errors(renders[name], truth)
        rel = relative(renders[name], truth)
        print(f"three.js RectAreaLight, {name} vs exact: max {worst:.4g} RMS {rms:.3g}", end=", ")
        print(f"relative max {rel.max():.3g} RMS {np.sqrt(np.mean(rel**2)):.3g} median {np.median(rel):.3g}")
    worst, rms = web_harness.pixel_errors(renders["lutbake"], truth)
    assert worst < LUTBAKE_MAX and rms < LUTBAKE_RMS
    assert np.median(relative(renders["lutbake"], truth)) < LUTBAKE_MEDIAN_REL


@pytest.mark.parametrize("mistake", MISTAKES)
def test_threejs_rectarea_catches_a_wrong_load(renders, mistake):
    web_harness.assert_wrong_load_caught(
        "three.js RectAreaLight", mistake, renders[mistake], renders["truth"], LUTBAKE_MAX, LUTBAKE_RMS
    )


# ---------------------------------------------------------------------------------------------------- Babylon.js
# web/babylon/rectarea.js: the same chart, light and tables in Babylon.js 9.37.1's RectAreaLight, mirrored in z (its
# camera looks down +z), lit by one white RectAreaLight of intensity 1 (photometric scale 1 for area lights),
# PBRMaterial with no environment BRDF (no energy-conservation factor on the light). Babylon loads areaLightsLTC.bin
# through Tools.GetAssetUrl; the page points Tools.AssetBaseUrl at lutbake's file. Babylon's own file is not in the npm
# package (it comes from assets.babylonjs.com at run time): not measured here; three.js's shipped tables written in
# Babylon's layout stand beside lutbake's. Babylon's pixel (computeAreaSpecularLighting, specularColor = the light's
# specular = 1) is F0 t2.x times the LTC integral: its (1 - specularColor) t2.y R90 term vanishes for a white light, so
# Babylon's area light leaves out Schlick's (F90 - F0) part wherever F0 < 1; the red channel of the metal (F0 = 1) is
# where its Fresnel is the exact one and the tables are measured.
BABYLON_PAGE = "/web/babylon/rectarea.html?driver"
BABYLON_EYE = 1e4  # world units from the chart: v is within 1e-4 rad of -z everywhere (the truth is three.js's)
# Babylon's pixels vs the numpy port on the same FP16 texels: measured 1.8e-7 (lutbake's) and 2.2e-7 (three.js's)
BABYLON_SHADER_ATOL = 2e-5
# the metal's red channel against the polygon integral: measured max 2.46e-2, RMS 5.7e-3 (lutbake's), 2.48e-2 and
# 5.8e-3 (three.js's shipped, in FP16); the wrong loads measured max >= 0.999, RMS >= 0.127
BABYLON_MAX, BABYLON_RMS = 0.035, 7e-3


def mirrored(v) -> np.ndarray:
    return np.asarray(v, np.float64) * [1.0, 1.0, -1.0]


def babylon_light(light=LIGHT) -> dict:
    """The three.js light mirrored in z for rectarea.js: position, unit x and y axes (Babylon lights the side
    -(x cross y) faces: the mirror's flipped y keeps the chart on it), width, height, intensity."""
    c = light_corners(light)  # pos + hw - hh, pos - hw - hh, pos - hw + hh, pos + hw + hh
    hw, hh = (c[0] - c[1]) / 2, (c[3] - c[0]) / 2
    return {
        "position": mirrored(c.mean(axis=0)).tolist(),
        "xAxis": (mirrored(hw) / np.linalg.norm(hw)).tolist(),
        "yAxis": (-mirrored(hh) / np.linalg.norm(hh)).tolist(),
        **{k: light[k] for k in ("width", "height", "intensity")},
    }


def babylon_corners(info) -> np.ndarray:
    """The polygon Babylon's shader builds (computeAreaLightSpecularDiffuseFresnel's rectCoords) from the light's world
    position and half extents the page read back."""
    p, hw, hh = (np.asarray(info[k], np.float64) for k in ("position", "halfWidth", "halfHeight"))
    return np.array([p + hw - hh, p - hw - hh, p - hw + hh, p + hw + hh])


def babylon_model(ltc1, ltc2, spec, info) -> np.ndarray:
    """Babylon 9.37's pixel: F0 t2.x times LTCEvaluate, at each pixel's point, mirrored normal and view vector
    normalize(eye - P) (the page's own eye), with the polygon the page's light holds."""
    p, n, rough, f0 = pixels(spec)
    v = np.asarray(info["eye"], np.float64) - p
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    t2, form = ltc_shading(ltc1, ltc2, rough, p, mirrored(n), v, babylon_corners(info))
    return (f0 * t2[:, :1] * form[:, None]).reshape(len(spec["rows"]), len(spec["nov"]), 3)


def bin_tables(path) -> tuple[np.ndarray, np.ndarray]:
    """Babylon's LTC1, LTC2 texels of an areaLightsLTC.bin as DecodeLTCTextureDataAsync splits them."""
    texels = np.frombuffer(path.read_bytes(), "<f2").astype(np.float64).reshape(64, 64, 8)
    return texels[..., :4], texels[..., 4:]


@pytest.fixture(scope="module")
def babylon_renders(ltc_luts, truth):
    """{variant: pixels} of Babylon's RectAreaLight with lutbake's file, three.js's tables and the mistakes."""
    web_harness.require("@babylonjs/core")
    spec = {
        **web_harness.furnace_chart(N_NOV, N_ROUGH),
        "light": babylon_light(),
        "scale": SCALE,
        "eye": BABYLON_EYE,
    }
    variants = {name: {"assets": f"/lut/babylon-{name}"} for name in ("lutbake", "threejs", *MISTAKES)}
    infos = {}
    out = web_harness.render_furnaces(ltc_luts, "@babylonjs/core", [(BABYLON_PAGE, variants)], spec, infos)
    out.update(spec=spec, info=infos["lutbake"], truth=truth, luts=ltc_luts)
    return out


def metal_red(px) -> np.ndarray:
    return np.asarray(px)[:N_ROUGH, :, 0]


def test_babylon_rectarea_light_is_the_one_the_model_shades(babylon_renders):
    np.testing.assert_allclose(babylon_corners(babylon_renders["info"]), mirrored(light_corners(LIGHT))[[3, 2, 1, 0]])


@pytest.mark.parametrize("name", ["lutbake", "threejs"])
def test_babylon_rectarea_samples_the_file_as_its_contract_says(babylon_renders, name):
    """Babylon's pixels are its shader on the file's FP16 texels: 8 per texel, LTC1 then LTC2, rows t = sqrt(1 - NoV),
    columns roughness, endpoint texels, invertY false; the Fresnel F0 t2.x of a white light."""
    tables = bin_tables(babylon_renders["luts"] / f"babylon-{name}" / "areaLights" / "areaLightsLTC.bin")
    model = babylon_model(*tables, babylon_renders["spec"], babylon_renders["info"])
    print(f"Babylon RectAreaLight vs its shader on {name}'s texels: {np.abs(babylon_renders[name] - model).max():.3g}")
    np.testing.assert_allclose(babylon_renders[name], model, rtol=0, atol=BABYLON_SHADER_ATOL)


def test_babylon_rectarea_with_lutbakes_tables_is_as_close_to_the_polygon_integral_as_threes(babylon_renders):
    truth = metal_red(babylon_renders["truth"])
    for name in ("threejs", "lutbake"):
        worst, rms = web_harness.pixel_errors(metal_red(babylon_renders[name]), truth)
        all_worst, all_rms = web_harness.pixel_errors(babylon_renders[name], babylon_renders["truth"])
        print(
            f"Babylon RectAreaLight, {name} tables vs exact: metal R (F0 = 1) max {worst:.4g} RMS {rms:.3g}; ", end=""
        )
        print(f"every pixel (Babylon's Fresnel) max {all_worst:.4g} RMS {all_rms:.3g}")
    worst, rms = web_harness.pixel_errors(metal_red(babylon_renders["lutbake"]), truth)
    assert worst < BABYLON_MAX and rms < BABYLON_RMS


@pytest.mark.parametrize("mistake", MISTAKES)
def test_babylon_rectarea_catches_a_wrong_file(babylon_renders, mistake):
    web_harness.assert_wrong_load_caught(
        "Babylon RectAreaLight",
        mistake,
        metal_red(babylon_renders[mistake]),
        metal_red(babylon_renders["truth"]),
        BABYLON_MAX,
        BABYLON_RMS,
    )
