"""Filament (google/filament): the DFG table cmgen bakes (``--ibl-dfg --ibl-dfg-multiscatter --ibl-dfg-cloth``),
libs/ibl/src/CubemapIBL.cpp DFV / DFV_Multiscatter / DFV_Charlie and shaders/src/light_indirect.fs prefilteredDFG:

    R = ∫ f/F Fc (n.l) dω,  G = ∫ f/F (n.l) dω,  B = ∫ D_charlie V_ashikhmin (n.l) dω (the cloth DV)
E = mix(R, G, f0) for the specular lobe, B times the prefiltered Charlie environment for cloth. cmgen writes image
row 0 = the roughest row (hi_first) and samples roughness one texel past each row's centre (texel_offset); the
corrected preset keeps the centres.
"""

from __future__ import annotations

from .base import EngineTable, Layout
from .plain import MULTISCATTER_CHANNELS, MULTISCATTER_SHADER

MULTISCATTER_CLOTH = Layout(
    name="multiscatter_cloth",
    kind="dfg",
    engine="Filament (cmgen --ibl-dfg-cloth), Godot, Babylon.js",
    summary="multiscatter + B = ∫ D_charlie V_ashikhmin (n.l): cloth DV (Filament --ibl-dfg-cloth)",
    channels={
        **MULTISCATTER_CHANNELS,
        "cloth_dv": "∫ D_charlie(h; alpha) V_ashikhmin (n.l) dω_l, no Fresnel: sheen/cloth directional albedo "
        "(Estevez & Kulla 2017 NDF, Ashikhmin 2007 visibility 1/(4 (n.l + n.v - (n.l)(n.v))))",
    },
    shader=MULTISCATTER_SHADER + "; cloth/sheen: sheen = prefiltered_charlie * sheen_color * t.b",
    integrand="multiscatter_cloth",
    source="filament libs/ibl/src/CubemapIBL.cpp (DFV_Multiscatter, DFV_Charlie)",
    terms_extra={"cloth": "D_charlie + V_ashikhmin"},
    gauss_legendre_only="layout 'multiscatter_cloth' needs estimator 'gauss_legendre': the QMC estimators draw "
    "h from the GGX NDF and miss the Charlie NDF's grazing lobe of the cloth channel",
    unit_range=False,
    above_one="the cloth DV (Ashikhmin visibility) exceeds 1 at grazing angles",
    split_sum="multiscatter",
)

GRID = {
    "kind": "dfg",
    "size": [128, 128],
    "roughness": "perceptual",
    "ndf": "ggx",
    "masking": "smith_height_correlated",
    "layout": "multiscatter_cloth",
    "texel": "center",
    "row_order": "hi_first",
    "dtype": "half",
    "format": "dds",
}
LAYOUTS = (MULTISCATTER_CLOTH,)
TABLES = (
    EngineTable(
        "Filament",
        "filament",
        "filament_dfg",
        "dfg",
        "multiscatter_cloth",
        {**GRID, "roughness_mapping": "texel_offset"},
        "filament tools/cmgen (--ibl-dfg), libs/ibl/src/CubemapIBL.cpp",
        "the DFG texture of an IBL (RGBA16F DDS, image row order)",
        shipped="filament_dfg.npz",
        shader="t = texture(dfg, vec2(NoV, 1.0 - (r - 1.0/128.0))).rgb; E = mix(t.r, t.g, f0); sheen DV = t.b",
    ),
    EngineTable(
        "Filament",
        "filament-corrected",
        "filament_dfg_corrected",
        "dfg",
        "multiscatter_cloth",
        {**GRID, "roughness_mapping": "linear"},
        "filament tools/cmgen, with each row's roughness at its texel centre",
        "the DFG texture of an IBL (RGBA16F DDS)",
        shader="t = texture(dfg, vec2(NoV, 1.0 - r)).rgb; E = mix(t.r, t.g, f0); sheen DV = t.b",
    ),
)
