"""Filament (google/filament): the DFG table cmgen bakes (``--ibl-dfg --ibl-dfg-multiscatter --ibl-dfg-cloth``),
libs/ibl/src/CubemapIBL.cpp DFV / DFV_Multiscatter / DFV_Charlie and shaders/src/light_indirect.fs prefilteredDFG:

    R = ∫ f/F Fc (n.l) dω,  G = ∫ f/F (n.l) dω,  B = ∫ D_charlie V_ashikhmin (n.l) dω (the cloth DV)
E = mix(R, G, f0) for the specular lobe, B times the prefiltered Charlie environment for cloth. cmgen writes image
row 0 = the roughest row (hi_first) and samples roughness one texel past each row's centre (texel_offset); the
corrected preset keeps the centres.

Preset ``filament-ibl`` bakes the corrected table with the specular cube of an environment as the one KTX 1 file
``Engine.createIblFromKtx1`` loads (cmgen's ``<name>_ibl.ktx``: the prefiltered mips and, in its key ``sh``, the
irradiance SH Filament's shader evaluates). shaders/src/light_indirect.fs reads the cube at
lod = iblRoughnessOneLevel * r (2 - r), iblRoughnessOneLevel = the cube's levels - 1 (curve ``filament``), at the
world direction (orientation ``gl``: tests/test_web_filament.py).
"""

from __future__ import annotations

from dataclasses import replace

from .base import IBL, EngineTable, Layout
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
CMGEN_IBL = "filament tools/cmgen/src/cmgen.cpp iblRoughnessPrefilter, libs/ibl/src/CubemapIBL.cpp roughnessFilter"
IBL_CONVENTIONS = IBL(
    "Filament",
    ndf="ggx",
    masking="smith_height_correlated",
    roughness="perceptual",
    curve="filament",
    lobe="ggx_nl",
    source="light_indirect.fs: prefilteredRadiance lod = iblRoughnessOneLevel * r * (2 - r), prefilteredDFG at "
    "vec2(NoV, r); cmgen iblRoughnessPrefilter: mip m at r = 1 - sqrt(1 - m / (M - 1)) (lodToPerceptualRoughness), "
    "alpha = r^2; lobe ggx_nl: CubemapIBL::roughnessFilter weights each GGX sample by n.l "
    "('const float brdf_NoL = float(NoL); weight += brdf_NoL;', google/filament 5b2652fa)",
)
CORRECTED = EngineTable(
    "Filament",
    "filament-corrected",
    "filament_dfg_corrected",
    "dfg",
    "multiscatter_cloth",
    {**GRID, "roughness_mapping": "linear"},
    "filament tools/cmgen, with each row's roughness at its texel centre",
    "the DFG texture of an IBL (RGBA16F DDS)",
    shader="t = texture(dfg, vec2(NoV, 1.0 - r)).rgb; E = mix(t.r, t.g, f0); sheen DV = t.b",
    ibl=IBL_CONVENTIONS,
)
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
    CORRECTED,
    replace(CORRECTED, preset="filament-ibl"),  # the same table in the one-run preset
    EngineTable(
        "Filament",
        "filament-ibl",
        "filament_specular",
        "environment_specular",
        None,
        {"curve": "filament", "lobe": "ggx_nl", "orientation": "gl", "format": "ktx1", "dtype": "r11g11b10f"},
        CMGEN_IBL,
        "IndirectLight reflections and irradiance SH: Engine.createIblFromKtx1 (cmgen's <name>_ibl.ktx)",
        shader="lod = iblRoughnessOneLevel * r * (2.0 - r); textureLod(light_iblSpecular, r_dir, lod).rgb; "
        "irradiance = max(iblSH[0] + iblSH[1] * n.y + iblSH[2] * n.z + iblSH[3] * n.x + ..., 0.0)",
        ibl=IBL_CONVENTIONS,
    ),
)
