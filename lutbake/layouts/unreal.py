"""Unreal Engine 4/5: PreIntegratedGF (Engine/Shaders/Private/BRDF.ush EnvBRDF; the R16G16 texture Epic ships,
Karis 2013): the scale_bias pair (lutbake.layouts.plain) with UE4's Smith joint approximation, 128 NoV x 32
roughness, texel centres, half floats."""

from __future__ import annotations

from .base import EngineTable

LAYOUTS = ()
TABLES = (
    EngineTable(
        "Unreal Engine",
        "unreal",
        "preintegrated_gf",
        "dfg",
        "scale_bias",
        {
            "size": [128, 32],
            "roughness": "perceptual",
            "masking": "smith_joint_approx",
            "layout": "scale_bias",
            "texel": "center",
            "dtype": "half",
            "format": "dds",
        },
        "Karis 2013; Engine/Content/EngineMaterials/PreintegratedGF (BRDF.ush EnvBRDF)",
        "PreintegratedGF as R16G16_FLOAT DDS",
        shader=(
            "AB = PreIntegratedGF.SampleLevel(s, float2(NoV, Roughness), 0).rg; "
            "SpecularColor * AB.x + saturate(50 * SpecularColor.g) * AB.y"
        ),
    ),
)
