"""Bevy (bevy_pbr, src/render/pbr_functions.wgsl, dfg.ktx2 via environment_map): the scale_bias pair
(lutbake.layouts.plain), 64², texel centres, half floats in a zstd-compressed KTX2; and its environment map light
(preset ``bevy-ibl``): the specular and diffuse cubes, sampled by light_probe/environment_map.wgsl at
vec3(R.xy, -R.z) (orientation ``d3d_left_handed``: the lookup vector is the world direction with z negated)."""

from __future__ import annotations

from dataclasses import replace

from .base import IBL, EngineTable

ENVIRONMENT_MAP = "bevy crates/bevy_pbr/src/light_probe/environment_map.wgsl (compute_radiances)"
IBL_CONVENTIONS = IBL(
    "Bevy",
    ndf="ggx",
    masking="smith_height_correlated",
    roughness="perceptual",
    curve="linear",
    lobe="ggx_nl",
    source="environment_map.wgsl: radiance_level = perceptual_roughness * (textureNumLevels - 1); pbr_lighting.wgsl "
    "F_AB at vec2(NdotV, perceptual_roughness); lobe ggx_nl: lutbake's choice (Bevy's own filter not compared)",
)
# the cube keys Bevy's shader fixes: the linear curve over the mips it has, the (x, y, -z) lookup
CUBE_KEYS = {"orientation": "d3d_left_handed", "format": "ktx2", "dtype": "half"}
LAYOUTS = ()
DFG = EngineTable(
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
    ibl=IBL_CONVENTIONS,
)
TABLES = (
    DFG,
    replace(DFG, preset="bevy-ibl", shipped=None),  # the same table in the one-run preset (audited as "bevy")
    EngineTable(
        "Bevy",
        "bevy-ibl",
        "bevy_specular",
        "environment_specular",
        None,
        {"curve": "linear", "lobe": "ggx_nl", **CUBE_KEYS},
        ENVIRONMENT_MAP,
        "EnvironmentMapLight.specular_map (a KTX2 cube with mips)",
        shader="radiance_level = perceptual_roughness * f32(textureNumLevels(specular_map) - 1u); "
        "textureSampleLevel(specular_map, environment_map_sampler, vec3(R.xy, -R.z), radiance_level).rgb",
        ibl=IBL_CONVENTIONS,
    ),
    EngineTable(
        "Bevy",
        "bevy-ibl",
        "bevy_diffuse",
        "environment_irradiance",
        None,
        CUBE_KEYS,
        ENVIRONMENT_MAP,
        "EnvironmentMapLight.diffuse_map (a KTX2 cube, E / pi)",
        shader="irradiance = textureSampleLevel(diffuse_map, environment_map_sampler, vec3(N.xy, -N.z), 0.0).rgb",
        ibl=IBL_CONVENTIONS,
    ),
)
