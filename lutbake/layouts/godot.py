"""Godot 4 (servers/rendering/renderer_rd/shaders/environment/integrate_dfg.glsl): the multiscatter_cloth channels
(lutbake.layouts.filament) with separable Schlick-GGX masking (k = alpha / 2), 128², image row 0 = the roughest row
(imageStore(..., (SIZE - 1) - pos.y)), half floats."""

from __future__ import annotations

from .base import EngineTable

LAYOUTS = ()
TABLES = (
    EngineTable(
        "Godot",
        "godot",
        "godot_dfg",
        "dfg",
        "multiscatter_cloth",
        {
            "size": [128, 128],
            "roughness": "perceptual",
            "masking": "schlick_ggx_ibl",
            "layout": "multiscatter_cloth",
            "texel": "center",
            "row_order": "hi_first",
            "dtype": "half",
        },
        "godot servers/rendering/renderer_rd/shaders/environment/integrate_dfg.glsl",
        "the DFG texture integrate_dfg.glsl computes at startup",
        shader=(
            "t = textureLod(dfg, vec2(NoV, 1.0 - r), 0.0).rg; "
            "(f90 - f0) * t.x + f0 * t.y, f90 = clamp(50.0 * f0.g, metallic, 1.0)"
        ),
    ),
)
