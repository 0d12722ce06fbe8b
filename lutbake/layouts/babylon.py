"""Babylon.js (@babylonjs/core 9.31, Misc/brdfTextureTools.js): the three BRDF lookup tables Babylon ships as base64
PNGs and loads with ``isRGBD = true`` (decoded by Misc/rgbdTextureTools ExpandRGBDTexture: rgb = pow(png.rgb, 2.2) /
png.a, Shaders/ShadersInclude/helperFunctions fromRGBD, into a half-float target):

- ``scene.environmentBRDFTexture`` ("MS-BRDF height-correlated", 256², RGBD): Filament's three channels
  (lutbake.layouts.filament multiscatter_cloth): R = ∫ f/F Fc (n.l), G = ∫ f/F (n.l), B = ∫ D_charlie V_ashikhmin
  (n.l) (the sheen lookup, getSheenReflectanceFromBRDFLookup); sampled at vec2(NdotV, perceptualRoughness)
  (pbrBRDFFunctions getBRDFLookup), texel centres, the PNG's first row at v = 0 (invertY = false): roughness 0 first.
  E = (R90 - R0) x + R0 y (getReflectanceFromBRDFLookup, BRDF_V_HEIGHT_CORRELATED); GGX, height-correlated Smith
  (smithVisibility_GGXCorrelated).
- ``scene.openPBREnvironmentBRDFTexture`` ("3-channel F82 LUT", 128²): the layout ``babylon_f82`` below, the F82-tint
  split sum of Blender EEVEE's brdf_ggx (lutbake.layouts.eevee scale_bias_f82: the same three integrals) stored as
  x = bias, y = scale + bias and z = 16 x the F82 term (BRDF_Z_SCALE; openpbrIblFunctions: environmentBrdf.z /
  BRDF_Z_SCALE), read by getF82DirectionalAlbedo: E = (F90 - F0) x + F0 y - b z / 16.
- ``scene.environmentFuzzBRDFTexture`` (32², RGB): Zeltner, Burley & Chiang 2022's published LTC fit of their
  random-walk volume (tizian/ltc-sheen ltc_table_sheen_volume: M^-1 = [[A, 0, B], [0, A, 0], [0, 0, 1]] in the
  normal's frame, R_i the volume's reflectance), rows = NdotV = max(0.01, j/31), columns = alpha = max(0.01, i/31)
  (endpoints), each channel coded linearly between its extremes; getFuzzBRDFLookup reads it at
  vec2(sqrt(fuzz_roughness), NdotV) as A = mix(0.005, 0.88, r), B = mix(-0.18, 0.002, g), R_i = mix(0, 0.75, b), but
  after the RGBD decode's pow(x, 2.2) (up to 0.25 off in A; tests/test_sheen_volume.py, docs/presets.md). lutbake
  integrates the paper's analytic approximation (LTC lobe ``zeltner``, lutbake.terms.sheen_volume), not the random
  walk. The preset ``babylon-fuzz`` writes Babylon's (A, B, R_i) layout from that fit (``BABYLON_FUZZ`` below: the
  mix() ranges, the channels, the shader line, as data; lutbake.io.ltc writes and reads it as format
  ``babylon_fuzz``), sampled where Babylon samples: linear NoV and alpha axes at texel centres.
lutbake's presets write float tables (DDS RGBA16F) Babylon loads with ``isRGBD = false`` and ``invertY = false``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .base import IBL, EngineTable, Layout
from .eevee import SCALE_BIAS_F82

BRDF_Z_SCALE = 16.0  # pbrBRDFFunctions: the F82 term is stored times 16 (its largest value is 1/16 of E's)
SOURCE = "@babylonjs/core 9.31.3 Misc/brdfTextureTools.js, Shaders/ShadersInclude/pbrBRDFFunctions.js"


def f82_stored(e: np.ndarray) -> np.ndarray:
    """(scale, bias, F82 term) -> (bias, scale + bias, 16 x F82 term): Babylon's x, y, z."""
    return np.stack([e[:, 1], e[:, 0] + e[:, 1], BRDF_Z_SCALE * e[:, 2]], axis=1)


def f82_errors(err: np.ndarray) -> np.ndarray:
    """Bounds of f82_stored's channels from those of (scale, bias, F82 term): (err_b, err_s + err_b, 16 err_F82)."""
    return np.stack([err[:, 1], err[:, 0] + err[:, 1], BRDF_Z_SCALE * err[:, 2]], axis=1)


def f82_integrals(t: np.ndarray) -> np.ndarray:
    """The inverse of f82_stored: (x, y, z) -> (y - x, x, z / 16)."""
    return np.stack([t[:, 1] - t[:, 0], t[:, 0], t[:, 2] / BRDF_Z_SCALE], axis=1)


BABYLON_F82 = Layout(
    name="babylon_f82",
    kind="dfg",
    engine="Babylon.js (scene.openPBREnvironmentBRDFTexture)",
    summary="multiscatter pair + B = 16 ∫ f/F (v.h)(1 - v.h)^6 (n.l): the F82-tint LUT of Babylon.js's OpenPBR "
    "material (E = (F90 - F0) R + F0 G - b B / 16)",
    channels={
        "fc": "∫ f/F (1 - v.h)^5 (n.l) dω_l: the f90 - f0 weight (Babylon environmentBrdf.x)",
        "e_ss": "∫ f/F (n.l) dω_l: E with F = 1 (environmentBrdf.y)",
        "f82_x16": "16 ∫ f/F (v.h)(1 - v.h)^6 (n.l) dω_l: the F82-tint term times BRDF_Z_SCALE (environmentBrdf.z)",
    },
    shader="{uv}; t = texture(openPBREnvironmentBRDF, uv).rgb; b = (F0 + (1 - F0) (6/7)^5) (1 - edgeTint) "
    "17.6512785 (getF82B); E = (F90 - F0) t.x + F0 t.y - b t.z / 16 (getF82DirectionalAlbedo); energy compensation "
    "= 1 + F_avg (1 / t.y - 1)",
    integrand=SCALE_BIAS_F82.integrand,
    source=SOURCE + ", openpbrIblFunctions.js",
    to_stored=f82_stored,
    from_stored=f82_integrals,
    error_to_stored=f82_errors,
    split_sum="multiscatter",
)


@dataclass(frozen=True)
class CodedChannel:
    """One channel of a texture a shader reads as value = mix(lo, hi, stored): stored = (value - lo) / (hi - lo)."""

    name: str
    lo: float
    hi: float
    meaning: str

    def encode(self, value: np.ndarray) -> np.ndarray:
        return (np.asarray(value, np.float64) - self.lo) / (self.hi - self.lo)

    def decode(self, stored: np.ndarray) -> np.ndarray:
        return self.lo + (self.hi - self.lo) * np.asarray(stored, np.float64)


@dataclass(frozen=True)
class LtcCoding:
    """An engine texture of an ``ltc`` table fitted in the normal's frame (M^-1 = [[A, 0, B], [0, A, 0], [0, 0, 1]],
    lutbake.ltc.fit normal_frame_matrices): (A, B, magnitude) each coded linearly into [0, 1] (``channels``, in
    texture order r, g, b; a = 1). ``values`` reads (A, B, R) from the table's ltc_code packing (slice 0 = M^-1 /
    M^-1_11 as (m00, m20, m02, m22): A = 1 / m22, B = m02 / m22; slice 1 x = magnitude)."""

    name: str
    engine: str
    channels: tuple[CodedChannel, ...]
    shader: str
    source: str

    @staticmethod
    def values(data: np.ndarray) -> np.ndarray:
        """(2, ny, nx, 4) ltc table -> (ny, nx, 3) float64 (A, B, R)."""
        t1, t2 = np.asarray(data[0], np.float64), np.asarray(data[1], np.float64)
        return np.stack([1.0 / t1[..., 3], t1[..., 2] / t1[..., 3], t2[..., 0]], axis=-1)

    def encode(self, values: np.ndarray) -> np.ndarray:
        """(.., 3) (A, B, R) -> (.., 4) stored RGBA (a = 1), unclamped."""
        coded = [c.encode(values[..., k]) for k, c in enumerate(self.channels)]
        return np.stack(coded + [np.ones(values.shape[:-1])], axis=-1)

    def decode(self, stored: np.ndarray) -> np.ndarray:
        """(.., >= 3) stored -> (.., 3) (A, B, R): the shader's mix()."""
        return np.stack([c.decode(stored[..., k]) for k, c in enumerate(self.channels)], axis=-1)

    def outside(self, values: np.ndarray) -> dict[str, dict]:
        """Per channel whose values leave [lo, hi]: the texel count, the values' extent and the range (the shader's
        mix() extrapolates a float texture's stored value outside [0, 1] linearly, so the values read back exactly;
        an 8-bit or UNORM copy would clamp them)."""
        out = {}
        for k, c in enumerate(self.channels):
            v = values[..., k]
            bad = (v < c.lo) | (v > c.hi)
            if bad.any():
                out[c.name] = {
                    "texels": int(bad.sum()),
                    "min": float(v.min()),
                    "max": float(v.max()),
                    "range": [c.lo, c.hi],
                }
        return out


BABYLON_FUZZ = LtcCoding(
    name="babylon_fuzz",
    engine="Babylon.js (scene.environmentFuzzBRDFTexture)",
    channels=(  # pbrBRDFFunctions getFuzzBRDFLookup: ARange, BRange, RiRange
        CodedChannel("A", 0.005, 0.88, "M^-1_00 = M^-1_11 of the normal-frame LTC (r: A = mix(0.005, 0.88, r))"),
        CodedChannel("B", -0.18, 0.002, "M^-1_02 of the normal-frame LTC (g: B = mix(-0.18, 0.002, g))"),
        CodedChannel(
            "R", 0.0, 0.75, "the lobe's directional albedo R_i, the LTC's magnitude (b: R_i = mix(0, 0.75, b))"
        ),
    ),
    shader="vec2 UV = vec2(perceptualRoughness, NdotV) (getFuzzBRDFLookup(NdotV, sqrt(fuzz_roughness)): the column "
    "coordinate is the table's alpha); {uv}; t = texture2D(environmentFuzzBrdfSampler, uv); A = mix(0.005, 0.88, t.r); "
    "B = mix(-0.18, 0.002, t.g); R_i = mix(0.0, 0.75, t.b); M^-1 = [[A, 0, B], [0, A, 0], [0, 0, 1]] in the normal's "
    "frame",
    source=SOURCE,
)

LAYOUTS = (BABYLON_F82,)
REFLECTION = "@babylonjs/core 9.37.1 Shaders/ShadersInclude/pbrBlockReflection (getLodFromAlphaG), Materials/Textures"
IBL_CONVENTIONS = IBL(
    "Babylon.js",
    ndf="ggx",
    masking="smith_height_correlated",
    roughness="perceptual",
    curve="babylon",
    lobe="ggx_nl",
    source="pbrBlockReflection: reflectionLOD = log2(size * alphaG) * lodGenerationScale (0.8) + lodGenerationOffset "
    "(0), alphaG = r^2; environmentBrdfSampler at vec2(NdotV, perceptualRoughness); lobe ggx_nl: lutbake's choice "
    "(Babylon's HDRFiltering measured apart: docs/in-engines.md)",
)
DFG = EngineTable(
    "Babylon.js",
    "babylon",
    "babylon_environment_brdf",
    "dfg",
    "multiscatter_cloth",
    {
        "size": [256, 256],
        "roughness": "perceptual",
        "masking": "smith_height_correlated",
        "layout": "multiscatter_cloth",
        "texel": "center",
        "row_order": "lo_first",
        "dtype": "half",
        "format": "dds",
    },
    SOURCE,
    "scene.environmentBRDFTexture (isRGBD = false, invertY = false)",
    shipped="babylon_environment_brdf.npz",
    shader="t = texture(environmentBrdfSampler, vec2(NdotV, perceptualRoughness)).rgb; (R90 - R0) * t.x + R0 * t.y",
    encoding="rgbd",  # the shipped PNG (Misc/brdfTextureTools.js loadBRDFTexture: isRGBD = true)
    ibl=IBL_CONVENTIONS,
)
TABLES = (
    DFG,
    replace(DFG, preset="babylon-ibl", shipped=None),  # the same table in the one-run preset (audited as "babylon")
    EngineTable(
        "Babylon.js",
        "babylon-ibl",
        "babylon_specular",
        "environment_specular",
        None,
        {"curve": "babylon", "lobe": "ggx_nl", "orientation": "gl", "format": "dds", "dtype": "half"},
        REFLECTION,
        "scene.environmentTexture = new CubeTexture(url, scene, {prefiltered: true, forcedExtension: '.dds'}) "
        "(lodGenerationScale 0.8, offset 0; its spherical polynomial, the irradiance, Babylon computes from the cube)",
        shader="reflectionLOD = getLodFromAlphaG(vReflectionMicrosurfaceInfos.x, alphaG) * 0.8 + 0.0; "
        "sampleReflectionLod(reflectionSampler, reflectionCoords, reflectionLOD)",
        ibl=IBL_CONVENTIONS,
    ),
    EngineTable(
        "Babylon.js",
        "babylon-openpbr",
        "babylon_openpbr_brdf",
        "dfg",
        "babylon_f82",
        {
            "size": [128, 128],
            "roughness": "perceptual",
            "masking": "smith_height_correlated",
            "layout": "babylon_f82",
            "texel": "center",
            "row_order": "lo_first",
            "dtype": "half",
            "format": "dds",
        },
        SOURCE,
        "scene.openPBREnvironmentBRDFTexture (isRGBD = false, invertY = false)",
        shipped="babylon_openpbr_brdf.npz",
        shader=(
            "t = texture(openPBREnvironmentBRDF, vec2(NdotV, perceptualRoughness)).rgb; "
            "(F90 - F0) * t.x + F0 * t.y - b * t.z / 16"
        ),
        encoding="rgbd",
    ),
    EngineTable(
        "Babylon.js",
        "babylon-fuzz",
        "babylon_fuzz_brdf",
        "ltc",
        None,
        {
            "lobe": "zeltner",
            "size": [32, 32],
            "nov_mapping": "linear",
            "texel": "center",
            "dtype": "half",
            "format": "babylon_fuzz",
        },
        SOURCE,
        "scene.environmentFuzzBRDFTexture (isRGBD = false, invertY = false)",
        shipped="babylon_environment_fuzz_brdf.npz",
        shader=(
            "t = texture(environmentFuzzBrdfSampler, vec2(alpha, NdotV)).rgb; A = mix(0.005, 0.88, t.r); "
            "B = mix(-0.18, 0.002, t.g); R = mix(0.0, 0.75, t.b)"
        ),
        encoding="rgbd",
    ),
    EngineTable(
        "Babylon.js",
        "ltc-babylon",
        "areaLightsLTC",
        "ltc",
        None,
        {"lobe": "ggx", "size": [64, 64], "dtype": "half", "format": "babylon_ltc"},
        "@babylonjs/core 9.37.1 Lights/LTC/ltcTextureTool.js, Lights/areaLight.pure.js, "
        "Shaders/ShadersInclude/ltcHelperFunctions.js",
        "areaLightsLTC.bin, fetched through Tools.GetAssetUrl (Tools.AssetBaseUrl = its folder's parent)",
    ),
)
