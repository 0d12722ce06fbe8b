"""three.js (src/renderers/shaders/ShaderChunk/lights_physical_pars_fragment, DFGLUTData.js; the LTC tables of
RectAreaLightUniformsLib / LTC_1, LTC_2): the scale_bias pair (lutbake.layouts.plain) at 16², roughness along x,
half floats written as a JS module; the LTC fit as ltc_code's two textures in JS."""

from __future__ import annotations

from .base import EngineTable

SOURCE = "three.js src/renderers/shaders (DFGLUTData.js, lights_physical_pars_fragment.glsl.js)"
LAYOUTS = ()
TABLES = (
    EngineTable(
        "three.js",
        "threejs",
        "DFGLUTData",
        "dfg",
        "scale_bias",
        {
            "size": [16, 16],
            "roughness": "perceptual",
            "masking": "smith_height_correlated",
            "layout": "scale_bias",
            "texel": "center",
            "axis_order": "roughness_x",
            "dtype": "half",
            "format": "threejs_dfg",
        },
        SOURCE,
        "DFGLUTData.js (a 16 x 16 RG half-float DataTexture; this file replaces three's as it is)",
        shipped="threejs_dfg_lut.js",
        shader="fab = texture2D(dfgLUT, vec2(roughness, dotNV)).rg; specularColor * fab.x + specularF90 * fab.y",
    ),
    EngineTable(
        "three.js",
        "ltc-threejs",
        "ltc_threejs",
        "ltc",
        None,
        {"lobe": "ggx", "size": [64, 64], "format": "js"},
        "three.js examples/jsm/lights/RectAreaLightUniformsLib.js (LTC_MAT_1, LTC_MAT_2)",
        "LTC_1, LTC_2 float arrays in a JS module",
    ),
)
