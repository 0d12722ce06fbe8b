"""Blender EEVEE (source/blender/draw/engines/eevee_next/shaders/eevee_lut_comp.glsl, eevee_lut.cc): brdf_ggx
(the F82-tint split sum), btdf_ggx and bsdf_ggx (the rough-glass tables) and ltc_mat_ggx / ltc_mag_ggx.

    scale_bias_f82  R = scale, G = bias, B = ∫ f/F (v.h)(1 - v.h)^6 (n.l) dω (Hoffman 2023's F82 tint, metal_bias)
    eevee_btdf      btdf_ggx[16][64][64][1] (ggx_btdf_gt_one): z = perceptual roughness k/15, y = sqrt(1 - NoV)
                    (NoV clamped to [1e-4, 0.9999]), x = sqrt((eta - 1)/(eta + 1)) (its square clamped to
                    [1e-4, 0.9999]); all endpoint texels; R = transmission_factor with Schlick s = (1 - v.h)^5
    eevee_bsdf      bsdf_ggx[16][64][64][3] (ggx_bsdf_split_sum, eta < 1): z = roughness k/15, x = eta^2 (eta
                    clamped to [1e-4, 0.9999]), y centred on the critical angle: with c = sqrt(1 - eta^2), y' = 2y - 1,
                    NoV = clamp(c + y' (y' > 0 ? 1 - c : c), 1e-4, 0.9999); R = scale, G = bias, B = transmission
                    factor with s = (1 - |t.h|)^5 (t refracted; s = 1 under TIR)
Both glass layouts fix GGX with separable Smith (the engine's G_V G_L) and the grid.
"""

from __future__ import annotations

import numpy as np

from ..axes import Axis
from .base import EngineTable, Layout, Storage, Terms
from .plain import SCALE_BIAS_CHANNELS, SCALE_BIAS_SHADER

EEVEE_SIZE = (16, 64, 64)  # UTIL_BTDF_LAYER_COUNT roughness layers x UTIL_TEX_SIZE^2
EEVEE_CLAMP = (1.0e-4, 0.9999)  # eevee_lut_comp.glsl: NoV, f0-like x^2 (btdf) and eta (bsdf) clamps
NO_TARGET = 1.0e300  # the tolerance of a kernel channel a layout drops (it never refines)
HALF_PRECISION = (1.4901161193847656e-08, 1.220703125e-04)  # 2^-26, 2^-13: a quarter of half's steps
SOURCE = "blender source/blender/draw/engines/eevee_next/shaders/eevee_lut_comp.glsl"

SCALE_BIAS_F82 = Layout(
    name="scale_bias_f82",
    kind="dfg",
    engine="Blender EEVEE (brdf_ggx), OpenPBR-style F82 tint",
    summary="scale_bias + B = ∫ f/F (v.h)(1 - v.h)^6 (n.l): the F82-tint term (Blender EEVEE)",
    channels={
        **SCALE_BIAS_CHANNELS,
        "f82": "∫ f/F (v.h)(1 - v.h)^6 (n.l) dω_l: the F82-tint term (Hoffman 2023 / Blender EEVEE metal_bias)",
    },
    shader=SCALE_BIAS_SHADER + "; F82 tint (Blender EEVEE): b = mix(f0, 1, (6/7)^5) * 7/(6/7)^6 * (1 - f82_tint), "
    "specular = prefiltered * (f0 * t.r + f90 * t.g - b * t.b)",
    integrand="scale_bias_f82",
    source=SOURCE + " (brdf_ggx)",
    split_sum="scale_bias",
)


def eevee_btdf_ior(x: np.ndarray) -> np.ndarray:
    """ggx_btdf_gt_one: f0 = clamp(x^2, 1e-4, 0.9999), ior = (1 + f0)/(1 - f0), i.e. x = sqrt((ior - 1)/(ior + 1))."""
    f = np.clip(x * x, *EEVEE_CLAMP)
    return (1.0 + f) / (1.0 - f)


def eevee_bsdf_ior_nov(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ggx_bsdf_split_sum: ior = clamp(sqrt(x), 1e-4, 0.9999) (the sine of the critical angle); with
    c = sqrt(1 - saturate(ior^2)), y' = 2y - 1 scaled by (1 - c) above 0 and by c below,
    NoV = clamp(y' + c, 1e-4, 0.9999)."""
    ior = np.clip(np.sqrt(x), *EEVEE_CLAMP)
    c = np.sqrt(1.0 - np.clip(ior * ior, 0.0, 1.0))
    yp = 2.0 * y - 1.0
    yp = yp * np.where(yp > 0.0, 1.0 - c, c)
    return ior, np.clip(yp + c, *EEVEE_CLAMP)


def glass_grid(x_rows: callable):
    """The texel grid of a 16 x 64 x 64 EEVEE glass table: ``x_rows(X, Y)`` -> (eta, NoV, y axis, extra)."""

    def grid(o: dict):
        nz, ny, nx = EEVEE_SIZE
        rough = Axis("perceptual_roughness", "z", nz, 0.0, 1.0, texel="endpoint")
        X, Y = np.meshgrid(np.arange(nx) / (nx - 1.0), np.arange(ny) / (ny - 1.0))  # [y][x]
        eta2, nov2, y_axis, extra = x_rows(X, Y)
        x_axis = Axis("ior", "x", nx, listed=tuple(float(e) for e in eta2[0]), mapping="listed")
        alpha = np.repeat(rough.alpha(), ny * nx)
        return [rough, y_axis, x_axis], np.tile(nov2.ravel(), nz), alpha, np.tile(eta2.ravel(), nz), extra

    return grid


def btdf_rows(X, Y):
    """eevee_btdf: x = sqrt((eta - 1)/(eta + 1)), y = sqrt(1 - NoV)."""
    y_axis = Axis("NoV", "y", Y.shape[0], 0.0, 1.0, texel="endpoint", mapping="one_minus_t2", clamp=EEVEE_CLAMP)
    extra = {
        "ior_axis": "x: t = i/63, eta = (1 + f)/(1 - f), f = clamp(t^2, 1e-4, 0.9999) (t = sqrt((eta - 1)/(eta + 1)))"
    }
    return eevee_btdf_ior(X), np.clip(1.0 - Y * Y, *EEVEE_CLAMP), y_axis, extra


def bsdf_rows(X, Y):
    """eevee_bsdf: x = eta^2, y centred on the critical angle (eevee_bsdf_ior_nov)."""
    eta2, nov2 = eevee_bsdf_ior_nov(X, Y)
    y_axis = Axis("nov_coordinate", "y", Y.shape[0], 0.0, 1.0, texel="endpoint")
    extra = {
        "ior_axis": "x: t = i/63, eta = clamp(sqrt(t), 1e-4, 0.9999) (t = eta^2)",
        "nov_axis": "y: t = j/63, c = sqrt(1 - eta^2), y' = 2t - 1, y' *= (y' > 0 ? 1 - c : c), "
        "NoV = clamp(y' + c, 1e-4, 0.9999) (centred on the critical angle, per IOR column)",
    }
    return eta2, nov2, y_axis, extra


def eevee_texels(o: dict) -> int:
    return int(np.prod(EEVEE_SIZE))


def transmission_only(e: np.ndarray) -> np.ndarray:
    """eevee_btdf keeps the kernel's channel 2 (the transmission factor)."""
    return e[:, 2:]


def btdf_kernel_tolerance(tol) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Only channel 2 is stored: the other kernel channels never refine."""
    return (NO_TARGET, NO_TARGET, tol.absolute), (0.0, 0.0, tol.relative)


GLASS_STORAGE = Storage(formats=("h",), dtype="float32", tolerance=HALF_PRECISION)


def glass(name: str, summary: str, channels: dict, shader: str, function: str, rows, **stored) -> Layout:
    """An EEVEE glass layout: GGX with separable Smith, the 16 x 64 x 64 grid of ``rows``, Schlick's factors
    (integrand mode ``eevee``); ``stored``: the layout's map from the kernel's three channels."""
    terms = Terms(ndf="ggx", masking="smith_separable")
    source = f"{SOURCE} ({function})"
    return Layout(
        name,
        "dielectric",
        f"Blender EEVEE ({function})",
        summary,
        channels,
        shader,
        "eevee",
        source,
        terms,
        grid=glass_grid(rows),
        texels=eevee_texels,
        storage=GLASS_STORAGE,
        split_sum=None,
        **stored,
    )


EEVEE_BTDF = glass(
    "eevee_btdf",
    "Blender EEVEE btdf_ggx[16][64][64][1]: Schlick transmission factor for eta > 1 (grid fixed)",
    {"transmission_factor": "∫ (1 - (1 - v.h)^5) f_t/(1 - F) |n.o| dω_o: transmittance = (1 - F0) * this"},
    "EEVEE bsdf_lut(): eta >= 1, coords = vec3(sqrt((eta - 1)/(eta + 1)), sqrt(1 - NoV), roughness); "
    "xy = xy * 63/64 + 0.5/64; layer = roughness * 15, two layers mixed by fract (manual trilinear); "
    "transmittance = (1 - F0) * t.r, reflectance = F0 * brdf.r + F90 * brdf.g (brdf_ggx split sum)",
    "ggx_btdf_gt_one",
    btdf_rows,
    to_stored=transmission_only,
    error_to_stored=transmission_only,
    kernel_tolerance=btdf_kernel_tolerance,
)
EEVEE_BSDF = glass(
    "eevee_bsdf",
    "Blender EEVEE bsdf_ggx[16][64][64][3]: Schlick scale, bias, transmission factor for eta < 1 (grid fixed)",
    {
        "scale": "∫ (1 - s) f_r/F |n.o| dω_o, s = (1 - |t.h|)^5 (1 under TIR): multiplies F0",
        "bias": "∫ s f_r/F |n.o| dω_o: multiplies F90",
        "transmission_factor": "∫ (1 - s) f_t/(1 - F) |n.o| dω_o: transmittance = (1 - F0) * this",
    },
    "EEVEE bsdf_lut(): eta < 1, c = sqrt(1 - eta^2), y = (NoV - c) / (NoV > c ? 1 - c : c) * 0.5 + 0.5, "
    "coords = saturate(vec3(eta^2, y, roughness)); xy = xy * 63/64 + 0.5/64; layer = roughness * 15 "
    "(manual trilinear); reflectance = F0 * t.r + F90 * t.g, transmittance = (1 - F0) * t.b",
    "ggx_bsdf_split_sum",
    bsdf_rows,
)

LAYOUTS = (SCALE_BIAS_F82, EEVEE_BTDF, EEVEE_BSDF)
TABLES = (
    EngineTable(
        "Blender EEVEE",
        "blender-eevee",
        "eevee_brdf_ggx",
        "dfg",
        "scale_bias_f82",
        {
            "size": [64, 64],
            "roughness": "perceptual",
            "masking": "smith_separable",
            "layout": "scale_bias_f82",
            "texel": "endpoint",
            "axis_order": "roughness_x",
            "nov_mapping": "one_minus_t2",
            "nov_clamp": [1e-4, 0.9999],
            "format": "h",
            "tolerance": HALF_PRECISION[0],
            "relative_tolerance": HALF_PRECISION[1],
        },
        SOURCE,
        "brdf_ggx[64][64][3] in eevee_lut.cc",
        shipped="blender_eevee_next_brdf_ggx.npz",
        shader="t = texture(lut, vec2(r, sqrt(1.0 - NoV)) * 63.0/64.0 + 0.5/64.0).rgb; F0 * t.r + F90 * t.g - b * t.b",
    ),
    EngineTable(
        "Blender EEVEE",
        "blender-eevee-btdf",
        "eevee_btdf_ggx",
        "dielectric",
        "eevee_btdf",
        {"layout": "eevee_btdf", "format": "h"},
        SOURCE,
        "btdf_ggx[16][64][64][1] in eevee_lut.cc",
        shader="xy = vec2(sqrt((eta - 1)/(eta + 1)), sqrt(1 - NoV)) * 63/64 + 0.5/64",
    ),
    EngineTable(
        "Blender EEVEE",
        "blender-eevee-bsdf",
        "eevee_bsdf_ggx",
        "dielectric",
        "eevee_bsdf",
        {"layout": "eevee_bsdf", "format": "h"},
        SOURCE,
        "bsdf_ggx[16][64][64][3] in eevee_lut.cc",
    ),
    EngineTable(
        "Blender EEVEE",
        "ltc-eevee",
        "ltc_eevee",
        "ltc",
        None,
        {"lobe": "ggx", "size": [64, 64], "format": "c"},
        "blender eevee_lut.cc ltc_mat_ggx[64][64][4], ltc_mag_ggx[64][64][2]",
        "ltc_mat_ggx, ltc_mag_ggx as C arrays (lutbake.io.ltc)",
    ),
)
