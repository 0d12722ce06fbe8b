"""Filament renders lutbake's files in its own renderer (npm `filament` pinned in web/package-lock.json: the WebAssembly
build, in headless Chromium, WebGL2 on SwiftShader): web/filament/furnace.js builds a glTF (GLB) chart of 1-pixel quads,
one metallic-roughness material per row, loads it through gltfio (its built-in ubershader materials: no matc, no
.filamat), lights it only by an image-based light read from a KTX 1 file lutbake wrote (lutbake.io.ktx1, cmgen's
layout: ``Engine.createIblFromKtx1``, the file's ``sh`` key given to ``IndirectLight.Builder.irradianceSh``),
intensity 1, exposure 1, post-processing off, and reads a float render target back.

(a) The white furnace: a constant cube of radiance 1 (R11F_G11F_B10F, 64² to 16² as cmgen's mips) and the SH of a
constant (c_0 = 1). Each pixel is then Filament's IBL specular (surface_light_indirect: E = mix(dfg.x, dfg.y, f0),
energyCompensation = 1 + f0 (1/dfg.y - 1)) of its DFG texel pair at (NoV, perceptual roughness clamped to
MIN_PERCEPTUAL_ROUGHNESS). Filament compiles its DFG into the library; web/filament/gl.js keeps the bits it uploads
(the web build's table is 64², RGB16F) and can write lutbake's table into the same texture (what a Filament built with
lutbake's dfg.inc would upload). Compared with: the CPU model of the same texels (the contract), the exact answer (the
converged integral in place of the table), lutbake's bakes of the `filament` conventions.

(b) The environment: a smooth, non-uniform cube (R = 0.6 + 0.35 x, G = 0.6 + 0.35 y, B = 0.6 + 0.35 z on the world
direction; every mip the same function at its texel centres) with its SH from lutbake.environment.sh (form
``filament``): mirror-like white metal pixels reflect the cube in directions all around the sphere (the pixel is the
radiance at the reflected direction: f0 = 1 makes E times its energy compensation 1), rough white dielectric pixels see
the SH (diffuse) and the cube's last mip at their normal (specular). The same file with its ±X faces swapped, its rows
flipped, or its SH in another form must fail.

(c) Preset ``filament-ibl``'s KTX 1 (the studio light's specular cube at 32² to 8², its key ``sh``) on (b)'s chart: each
pixel against the CPU model of Filament's lookup of the file's own texels (trilinear at lod = (M - 1) r (2 - r), the
SH polynomials of the key), at the pixels whose lookups stay inside one face (seamless filtering at face edges is the
GL implementation's, not modelled).

Skipped, with the reason, without chromium, playwright, `npm ci` in web/ or WebGL2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import web_harness
from test_gl_consumer import bilinear

from lutbake.api import bake
from lutbake.config import preset_path
from lutbake.environment import cube, sh
from lutbake.io.dds import read_dds
from lutbake.io.ktx1 import decode_ktx1_cube, encode_ktx1_cube

ENGINE_DIR = "filament"
PAGE = "/web/filament/furnace.html?driver"
WEB_DFG_SIZE = 64  # the DFG table Filament 1.53.4's WebGL build uploads (measured: 64² RGB16F; desktop builds 128²)
# Filament clamps perceptual roughness below this (its TARGET_MOBILE value; the desktop one is 0.045); measured: with
# 0.045 the r = 0.05 rows miss the model by 0.085, with 0.089 by 1.7e-4
MIN_PERCEPTUAL_ROUGHNESS = 0.089
DIELECTRIC_F0 = 0.04  # glTF's default IOR 1.5
IBL_SIZE, IBL_MIN_SIZE = 64, 16  # cmgen's mips stop at 16² (IBL_DEFAULT_MIN_LOD_SIZE)
# Filament's pixels vs the CPU model of the same texels: measured 1.7e-4, RMS 1.5e-5 (the mobile materials' arithmetic
# and SwiftShader's filtering of a half-float table, not modelled: 8-bit texel weights alone do not explain it)
TEXELS_ATOL = 4e-4
# against the exact answer: lutbake's `filament-corrected` at 64² measured max 7.5e-3, RMS 3.9e-4 (Filament's built-in
# table, cmgen's estimate with its one-texel roughness offset: 3.6e-2, 5.0e-3; docs/in-engines.md); the wrong loads
# of lutbake's table measured max >= 0.85, RMS >= 0.157
CORRECTED_MAX, CORRECTED_RMS = 1e-2, 1e-3
DFG_MISTAKES = ("flipY", "swapRG")
# (b), the float32 file: the smooth cube's bilinear interpolation between texel centres and the shader's arithmetic:
# measured max 3.4e-4 (metal; the dielectric 4.5e-5), RMS 3.8e-5; the wrong files measured max >= 0.47, RMS >= 0.11.
# The R11F_G11F_B10F (cmgen's) and RGB16F files add their rounding, at most half a step of the value: measured 0.41 %
# (R, G) and 0.86 % (B) of it, RGB16F max 4.3e-4 (as the float32 file's)
ENV_A, ENV_B = 0.6, 0.35
ENV_ATOL, ENV_RMS = 1e-3, 2e-4
ENV_MISTAKES = ("swapX", "flipRows", "shForm")
FILES = {"filament": "filament_dfg", "corrected": "filament_dfg_corrected"}  # the two bakes' DDS names
# (c): preset filament-ibl with the studio light (tests/data), its cube 32² to 8² (the quadrature: seconds)
STUDIO = Path(__file__).parent / "data" / "env_studio_64x32.exr"
PRESET_CUBE = ["filament_specular.size=32", "filament_specular.mips=3", "filament_specular.estimator=quadrature"]
PRESET_KTX = "filament-ibl/filament_specular.ktx"
PRESET_SWAPPED = "/lut/filament_preset_swapX_ibl.ktx"  # the same file with its ±X faces exchanged: must fail
# (c) against the lookup model: measured max 2.2e-2 on values up to 38 (0.53 %), at most 1.2e-3 of the spread of the
# texels a pixel reads, RMS 1.1e-3, at 91 % of the pixels: consistent with filter weights rounded to 8 bits (up to 2^-9
# of the spread); allowed 2^-8 of it plus the shader's arithmetic (dielectric pixels, spread ~0: measured 2.8e-5)
FILTER_STEP, PRESET_ATOL = 2.0**-8, 2e-4
# the other formats' rounding, half a step of the value: cmgen's R11F_G11F_B10F (R, G: 6 mantissa bits, B: 5) and RGB16F
ROUNDED = {"env_r11g11b10f": np.array([2.0**-7, 2.0**-7, 2.0**-6]), "env_half": np.full(3, 2.0**-11)}


def environment(d) -> np.ndarray:
    """The smooth environment's radiance (..., 3) at unit directions ``d``: channel c is A + B d_c."""
    return ENV_A + ENV_B * np.asarray(d, np.float64)


def cube_mips(radiance, size=IBL_SIZE, smallest=IBL_MIN_SIZE) -> list[np.ndarray]:
    """Every mip from ``size`` down to ``smallest`` holding ``radiance`` at its texel centres (GL face table)."""
    return [radiance(cube.texel_centres(n)) for n in (size >> m for m in range(8)) if n >= smallest]


def env_sh(form="filament") -> np.ndarray:
    """(9, 3) SH of the smooth environment, lutbake's exact projection of a 256 x 128 lat-long of it."""
    h = 128
    theta = (np.arange(h) + 0.5) / h * np.pi
    phi = (np.arange(2 * h) + 0.5) / (2 * h) * 2 * np.pi - np.pi
    from lutbake.environment.latlong import directions

    d = directions(theta[:, None], phi[None, :])
    return sh.convolve(sh.project(environment(d)), form)


def write_ibls(luts):
    """The KTX 1 files the page loads: the furnace's constant cube (web_harness.write_furnace_ibl, as make demo), the
    environment and its wrong versions."""
    web_harness.write_furnace_ibl(luts / web_harness.FILAMENT_WEB, IBL_SIZE, IBL_MIN_SIZE)
    mips = cube_mips(environment)
    files = {
        "env": (mips, env_sh(), "float32"),
        "env_r11g11b10f": (mips, env_sh(), "r11g11b10f"),
        "env_half": (mips, env_sh(), "half"),
        "swapX": ([m[[1, 0, 2, 3, 4, 5]] for m in mips], env_sh(), "float32"),
        "flipRows": ([m[:, ::-1] for m in mips], env_sh(), "float32"),
        "shForm": (mips, env_sh("irradiance_over_pi"), "float32"),
    }
    for name, (m, c, fmt) in files.items():
        (luts / f"filament_{name}_ibl.ktx").write_bytes(encode_ktx1_cube(m, fmt, c))


def env_chart(width=web_harness.N_NOV, rows=web_harness.N_ROUGH):
    """(b)'s chart: ``rows`` rows of white metal (roughness 0: clamped) whose reflected directions r cover the sphere
    (z_r from 0.975 down to -0.925, all azimuths; n = normalize(r + v), v = +z), then ``rows`` rows of rough white
    dielectric whose normals cover the visible hemisphere (n_z from 0.2 to 1)."""
    u = (np.arange(width) + 0.5) / width
    phi = 2 * np.pi * u[None, :]
    zr = 1 - 1.95 * (np.arange(rows)[:, None] + 0.5) / rows
    r = np.stack(np.broadcast_arrays(np.sqrt(1 - zr**2) * np.cos(phi), np.sqrt(1 - zr**2) * np.sin(phi), zr), -1)
    n_metal = r + [0, 0, 1]
    n_metal /= np.linalg.norm(n_metal, axis=-1, keepdims=True)
    nz = 0.2 + 0.8 * (np.arange(rows)[:, None] + 0.5) / rows
    n_dielectric = np.stack(
        np.broadcast_arrays(np.sqrt(1 - nz**2) * np.cos(phi), np.sqrt(1 - nz**2) * np.sin(phi), nz), -1
    )
    normals = np.concatenate([n_metal, n_dielectric])
    materials = [{"roughness": 0.0, "metalness": 1.0, "color": [1.0, 1.0, 1.0]}] * rows
    materials += [{"roughness": 1.0, "metalness": 0.0, "color": [1.0, 1.0, 1.0]}] * rows
    return {"nov": None, "width": width, "normals": normals.reshape(-1, 3).tolist(), "rows": materials}


def dfg_texels(bits, n=WEB_DFG_SIZE) -> np.ndarray:
    """Filament's DFG bits as uploaded: (n rows, row 0 at t = 0, n columns, RGB) float64."""
    return np.asarray(bits, np.uint16).view(np.float16).astype(np.float64).reshape(n, n, 3)


def table(texels):
    """``(roughness, nov) -> (N, 2)``: bilinear at vec2(NoV, perceptualRoughness), rows as uploaded."""
    return lambda rough, nov: bilinear(texels[..., :2], np.stack([nov, rough], axis=1))


def exact(rough, nov):
    """The converged (dfg.x, dfg.y) = (∫Fc·V, ∫V) = (bias, scale + bias)."""
    scale, bias = web_harness.exact_scale_bias(rough, nov).T
    return np.stack([bias, scale + bias], axis=1)


def specular(xy, f0):
    """Filament's IBL specular per unit radiance: E = mix(x, y, f0) times 1 + f0 (1/y - 1)."""
    x, y = xy[:, :1], xy[:, 1:2]
    return ((1 - f0) * x + f0 * y) * (1 + f0 * (1 / y - 1))


def furnace_model(xy, spec) -> np.ndarray:
    """Filament 1.53's furnace pixel (height, width, RGB) from ``xy(roughness, nov) -> (N, 2)``; metal f0 = base colour,
    dielectric 0.04; black or metal: no diffuse."""
    nov = np.asarray(spec["nov"])
    out = []
    for row in spec["rows"]:
        rough = np.full_like(nov, max(row["roughness"], MIN_PERCEPTUAL_ROUGHNESS))
        f0 = np.asarray(row["color"]) if row["metalness"] == 1 else np.full(3, DIELECTRIC_F0)
        out.append(specular(xy(rough, nov), f0))
    return np.stack(out)


def lit_model(xy, chart, radiance, irradiance) -> np.ndarray:
    """Filament's pixel on (b)'s chart: metal rows radiance(mix(r, n, α²), r) (α = MIN_PERCEPTUAL_ROUGHNESS²,
    getSpecularDominantDirection; f0 = 1 makes E times its energy compensation 1); dielectric rows (r = 1: the
    dominant direction is n) E ec radiance(n, 1) + (1 - E) irradiance(n). ``radiance(d, r)`` the cube's value at
    unit directions d for perceptual roughness r, ``irradiance(n)`` E / pi (the SH)."""
    rows = len(chart["rows"]) // 2
    n = np.asarray(chart["normals"]).reshape(2 * rows, -1, 3)
    metal = n[:rows]
    nov = metal[..., 2:3]
    r = 2 * nov * metal - [0, 0, 1]
    alpha = MIN_PERCEPTUAL_ROUGHNESS**2
    dominant = r + alpha**2 * (metal - r)
    out_metal = radiance(dominant / np.linalg.norm(dominant, axis=-1, keepdims=True), MIN_PERCEPTUAL_ROUGHNESS)
    d = n[rows:].reshape(-1, 3)
    x, y = xy(np.ones(len(d)), d[:, 2]).T
    e = (1 - DIELECTRIC_F0) * x + DIELECTRIC_F0 * y
    ec = 1 + DIELECTRIC_F0 * (1 / y - 1)
    out = (e * ec)[:, None] * radiance(d, 1.0) + (1 - e)[:, None] * irradiance(d)
    return np.concatenate([out_metal, out.reshape(n[rows:].shape)])


def env_model(xy, chart) -> np.ndarray:
    """(b)'s pixel: the smooth environment (every mip the same function) and its SH's closed form, A + 2/3 B n (the
    cosine convolution of a linear L, R&H 2001)."""
    return lit_model(xy, chart, lambda d, r: environment(d), lambda n: ENV_A + 2 / 3 * ENV_B * n)


def face_taps(mip: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(texels (4, ..., 3), bilinear weights (4, ..., 1), inside) of a cube mip (6, n, n, 3) at lookup vectors d
    (..., 3): GL's bilinear filter between the texel centres of the face d picks (lutbake.environment.cube.face_st;
    row t, column s); ``inside``: the four texels are all in that face (elsewhere seamless filtering takes texels of
    the next face: not modelled)."""
    n = mip.shape[1]
    face, s, t = cube.face_st(d)
    x, y = s * n - 0.5, t * n - 0.5
    inside = (x >= 0) & (x < n - 1) & (y >= 0) & (y < n - 1)
    x0 = np.clip(np.floor(x).astype(int), 0, n - 2)
    y0 = np.clip(np.floor(y).astype(int), 0, n - 2)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    texels = np.stack([mip[face, y0 + i, x0 + j] for i in (0, 1) for j in (0, 1)])
    weights = np.stack([(1 - fy) * (1 - fx), (1 - fy) * fx, fy * (1 - fx), fy * fx])
    return texels, weights, inside


def lookup_model(xy, chart, mips, coefficients) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(c)'s (pixels, inside, spread): Filament's lookup of a KTX 1's own texels, trilinear at
    lod = (M - 1) r (2 - r) (light_indirect.fs perceptualRoughnessToLod, M = the file's levels), and of its key sh,
    E / pi = max(Σ c_k p_k(n), 0) (Irradiance_SphericalHarmonics); ``inside``: every texel a pixel reads is in one
    face; ``spread``: max - min of the texels it reads (what a rounded filter weight can move the pixel by)."""
    masks, spreads = [], []

    def radiance(d, r):
        lod = (len(mips) - 1) * r * (2 - r)
        lo = min(int(lod), len(mips) - 1)
        hi, f = min(lo + 1, len(mips) - 1), lod - lo
        (ta, wa, in_a), (tb, wb, in_b) = face_taps(mips[lo], d), face_taps(mips[hi], d)
        masks.append(in_a & in_b)
        both = np.concatenate([ta, tb])
        spreads.append(both.max(axis=0) - both.min(axis=0))
        return (1 - f) * (wa * ta).sum(axis=0) + f * (wb * tb).sum(axis=0)

    px = lit_model(xy, chart, radiance, lambda n: np.maximum(sh.polynomials(n) @ coefficients, 0.0))
    inside = np.concatenate([masks[0], masks[1].reshape(masks[0].shape)])
    return px, inside, np.concatenate([spreads[0], spreads[1].reshape(spreads[0].shape)])


@pytest.fixture(scope="module")
def renders(tmp_path_factory):
    """{variant: (height, width, RGB) float pixels} and what the page reported."""
    web_harness.require(ENGINE_DIR)
    luts = tmp_path_factory.mktemp("filament")
    size = f"size=[{WEB_DFG_SIZE},{WEB_DFG_SIZE}]"
    web = luts / web_harness.FILAMENT_WEB  # as make demo bakes them
    bake([preset_path("filament"), preset_path("filament-corrected")], web, [size, "row_order=lo_first"])
    # the `filament` conventions integrated as cmgen does (1024 Hammersley points; R, G only: the QMC estimators do
    # not take the cloth channel)
    cmgen_like = ["layout=multiscatter", "estimator=hammersley_ndf", "samples=1024"]
    bake(preset_path("filament"), luts / "cmgen", [size, "row_order=lo_first", *cmgen_like])
    write_ibls(luts)
    bake([preset_path("filament-ibl")], luts / "filament-ibl", PRESET_CUBE, environment=STUDIO)
    mips, _, pairs = decode_ktx1_cube((luts / PRESET_KTX).read_bytes())
    c = np.array(pairs["sh"].split(), float).reshape(9, 3)
    swapped = encode_ktx1_cube([m[[1, 0, 2, 3, 4, 5]] for m in mips], "r11g11b10f", c)
    (luts / "filament_preset_swapX_ibl.ktx").write_bytes(swapped)
    spec = web_harness.furnace_chart()
    chart = env_chart()
    lut = {name: f"/lut/{web_harness.FILAMENT_WEB}/{file}.dds" for name, file in FILES.items()}
    variants = {"shipped": {}, "lutbake": {"dfg": lut["filament"]}, "corrected": {"dfg": lut["corrected"]}}
    variants.update({m: {"dfg": lut["corrected"], "mistake": m} for m in DFG_MISTAKES})
    variants.update({m: {**chart, "ibl": f"/lut/filament_{m}_ibl.ktx"} for m in ("env", *ROUNDED, *ENV_MISTAKES)})
    variants.update(preset={**chart, "ibl": f"/lut/{PRESET_KTX}"}, preset_swapX={**chart, "ibl": PRESET_SWAPPED})
    infos = {}
    out = web_harness.render_furnaces(luts, ENGINE_DIR, [(PAGE, variants)], spec, infos)
    out.update(spec=spec, chart=chart, info=infos["shipped"], luts=luts)
    return out


def errors(px, spec):
    return web_harness.pixel_errors(px, furnace_model(exact, spec))


def test_filament_web_build_uploads_a_64_square_rgb16f_dfg_table(renders):
    assert renders["info"]["dfgSize"] == WEB_DFG_SIZE
    assert len(renders["info"]["dfg"]) == WEB_DFG_SIZE**2 * 3


def test_filaments_built_in_table_is_lutbakes_filament_conventions_at_cmgens_estimate(renders):
    """Filament's 64² table (R = ∫Fc·V, G = ∫V) is the `filament` preset's conventions (its one-texel roughness
    offset, rows in GL order) integrated with cmgen's 1024 Hammersley points: measured identical half bits at 99.95 %
    of R (the rest one half ulp) and 100 % of G."""
    shipped = np.asarray(renders["info"]["dfg"], np.uint16).reshape(WEB_DFG_SIZE, WEB_DFG_SIZE, 3)[..., :2]
    ours = read_dds(renders["luts"] / "cmgen" / "filament_dfg.dds").data[..., :2].astype(np.float16).view(np.uint16)
    same = (ours == shipped).mean(axis=(0, 1))
    assert same[0] > 0.999 and same[1] == 1.0, same
    ulps = np.abs(ours.astype(np.int32) - shipped.astype(np.int32))
    assert ulps.max() <= 1


def test_filament_white_metal_is_white_at_every_roughness(renders):
    # the red channel of the metal rows: f0 = 1, where E times the energy compensation is y / y
    for variant in ("shipped", "lutbake", "corrected"):
        np.testing.assert_allclose(renders[variant][: web_harness.N_ROUGH, :, 0], 1.0, atol=1e-3)


def test_filament_renders_its_own_dfg_table_as_the_cpu_model(renders):
    texels = dfg_texels(renders["info"]["dfg"])
    model = furnace_model(table(texels), renders["spec"])
    print(f"Filament vs the CPU model of its own texels: {np.abs(renders['shipped'] - model).max():.3g}")
    np.testing.assert_allclose(renders["shipped"], model, rtol=0, atol=TEXELS_ATOL)


def test_filament_samples_lutbakes_table_as_its_contract_says(renders):
    """lutbake's `filament-corrected` at 64², rows lo_first (GL order: what cmgen writes to dfg.inc), written into
    Filament's DFG texture: the pixels are the CPU model of those texels at vec2(NoV, r)."""
    texels = read_dds(renders["luts"] / web_harness.FILAMENT_WEB / "filament_dfg_corrected.dds").data.astype(float)
    model = furnace_model(table(texels), renders["spec"])
    np.testing.assert_allclose(renders["corrected"], model, rtol=0, atol=TEXELS_ATOL)


def test_filament_furnace_with_lutbakes_corrected_table_is_within_its_interpolation_error(renders):
    spec = renders["spec"]
    for name in ("shipped", "lutbake", "corrected"):
        worst, rms = errors(renders[name], spec)
        print(f"Filament furnace, {name} DFG vs exact: max {worst:.4g} RMS {rms:.3g}")
    worst, rms = errors(renders["corrected"], spec)
    shipped_worst, shipped_rms = errors(renders["shipped"], spec)
    assert worst < CORRECTED_MAX and rms < CORRECTED_RMS
    assert rms < shipped_rms  # the one-texel offset of the built-in table is what the corrected table removes


@pytest.mark.parametrize("mistake", DFG_MISTAKES)
def test_filament_furnace_catches_a_wrong_dfg_load(renders, mistake):
    exact_px = furnace_model(exact, renders["spec"])
    web_harness.assert_wrong_load_caught(
        "Filament furnace", mistake, renders[mistake], exact_px, CORRECTED_MAX, CORRECTED_RMS
    )


def test_filament_loads_lutbakes_ktx1_cube_and_sh_as_written(renders):
    """The environment cube in GL's face table and Filament's world directions, and the SH of form `filament`: the
    pixels are the model of (b) with Filament's own DFG texels."""
    model = env_model(table(dfg_texels(renders["info"]["dfg"])), renders["chart"])
    worst, rms = web_harness.pixel_errors(renders["env"], model)
    print(f"Filament, lutbake's KTX1 environment vs the model: max {worst:.3g} RMS {rms:.3g}")
    assert worst < ENV_ATOL and rms < ENV_RMS


@pytest.mark.parametrize("variant", sorted(ROUNDED))
def test_filament_loads_the_r11g11b10f_and_half_files_within_their_rounding(renders, variant):
    model = env_model(table(dfg_texels(renders["info"]["dfg"])), renders["chart"])
    worst = np.abs(renders[variant] - model) - ROUNDED[variant] * model
    assert worst.max() < ENV_ATOL


@pytest.mark.parametrize("mistake", ENV_MISTAKES)
def test_filament_catches_a_wrong_environment_file(renders, mistake):
    model = env_model(table(dfg_texels(renders["info"]["dfg"])), renders["chart"])
    web_harness.assert_wrong_load_caught("Filament environment", mistake, renders[mistake], model, ENV_ATOL, ENV_RMS)


def test_the_env_files_hold_what_the_model_assumes(renders):
    mips, fmt, pairs = decode_ktx1_cube((renders["luts"] / "filament_env_r11g11b10f_ibl.ktx").read_bytes())
    assert fmt == "r11g11b10f" and [m.shape[1] for m in mips] == [64, 32, 16]
    np.testing.assert_allclose(mips[1], environment(cube.texel_centres(32)), rtol=2.0**-6)
    c = np.array(pairs["sh"].split(), float).reshape(9, 3)
    expected = np.zeros((9, 3))
    expected[0] = ENV_A
    expected[[3, 1, 2], [0, 1, 2]] = 2 / 3 * ENV_B  # x -> R, y -> G, z -> B
    np.testing.assert_allclose(c, expected, atol=1e-4)


def preset_lookup(renders):
    mips, fmt, pairs = decode_ktx1_cube((renders["luts"] / PRESET_KTX).read_bytes())
    assert fmt == "r11g11b10f" and [m.shape[1] for m in mips] == [32, 16, 8]
    c = np.array(pairs["sh"].split(), float).reshape(9, 3)
    return lookup_model(table(dfg_texels(renders["info"]["dfg"])), renders["chart"], mips, c)


def test_filament_loads_the_filament_ibl_presets_ktx1_as_its_lookup_model(renders):
    model, inside, spread = preset_lookup(renders)
    diff = np.abs(renders["preset"] - model)[inside]
    spread_inside = spread[inside]
    varied = spread_inside > 1e-2
    print(
        f"Filament, preset filament-ibl's KTX1 vs the lookup model at {inside.mean():.0%} of the pixels: max "
        f"{diff.max():.3g}, RMS {np.sqrt(np.mean(diff**2)):.3g}; of the texels' spread (where > 1e-2) at most "
        f"{(diff[varied] / spread_inside[varied]).max():.2g}"
    )
    assert inside.mean() > 0.5
    assert np.all(diff <= FILTER_STEP * spread_inside + PRESET_ATOL)


def test_filament_with_the_presets_ktx1_faces_exchanged_fails_its_model(renders):
    model, inside, spread = preset_lookup(renders)
    diff = np.abs(renders["preset_swapX"] - model)[inside]
    outside = np.mean(diff > FILTER_STEP * spread[inside] + PRESET_ATOL)
    print(f"Filament, preset filament-ibl's KTX1 with ±X exchanged: max {diff.max():.3g}, {outside:.0%} out of bounds")
    assert outside > 0.1
