"""Bevy (bevy_pbr, src/render/pbr_functions.wgsl, dfg.ktx2 via environment_map): the scale_bias pair
(lutbake.layouts.plain), 64², texel centres, half floats in a zstd-compressed KTX2."""

from __future__ import annotations

from .base import EngineTable

LAYOUTS = ()
TABLES = (
    EngineTable(
        "Bevy",
        "bevy",
        "bevy_dfg",
        "dfg",
        "scale_bias",
        {
            "size": [64, 64],
            "roughness": "perceptual",
            "masking": "smith_height_correlated",
            "layout": "scale_bias",
            "texel": "center",
            "dtype": "half",
            "format": "ktx2zst",
        },
        "bevy crates/bevy_pbr/src/render/pbr_lighting.wgsl (F_AB), environment_map_light",
        "dfg.ktx2 (RGBA16F, zstd supercompressed)",
        shipped="bevy_dfg.ktx2",
        shader="textureSampleLevel(dfg_lut, dfg_lut_sampler, vec2<f32>(NdotV, perceptual_roughness), 0.0).rg",
    ),
)
