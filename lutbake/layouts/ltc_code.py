"""selfshadow/ltc_code (Heitz, Dupuy, Hill & Neubelt 2016): the two RGBA textures of fit/fitLTC.cpp packTab, ltc_1 =
the inverse matrix (m11, m13, m31, m33 normalised), ltc_2 = (magnitude, fresnel, 0, sphere), over sqrt(1 - NoV) x
roughness (kind ltc; lutbake.kinds.ltc). The engines' LTC layouts (Blender EEVEE's C arrays, HDRP's C#, three.js's
JS: lutbake.io.ltc) are tables of their engines' modules; lutbake's own presets write ltc_code's DDS pair."""

from __future__ import annotations

from .base import EngineTable

# ltc_code's webgl/ltc.js lookup (LUT_SIZE 64: LUT_SCALE = 63/64, LUT_BIAS = 0.5/64)
SHADER = "uv = vec2(r, sqrt(1.0 - NoV)) * 63.0/64.0 + 0.5/64.0; t1 = texture(ltc_1, uv); t2 = texture(ltc_2, uv)"
SOURCE = "selfshadow/ltc_code fit/fitLTC.cpp (packTab), webgl/ltc_1.dds, ltc_2.dds"
LAYOUTS = ()
TABLES = tuple(
    EngineTable(
        "ltc_code",
        f"ltc-{lobe}",
        f"ltc_{lobe}",
        "ltc",
        None,
        {"lobe": lobe, "size": [64, 64], "fit_samples": 32, "dtype": "half", "format": "ltc_dds"},
        SOURCE,
        "ltc_1.dds, ltc_2.dds (RGBA16F)",
        shipped="ltc_code_ltc.js.gz" if lobe == "ggx" else None,
        shader=SHADER,
    )
    for lobe in ("ggx", "eon", "gotanda")
)
