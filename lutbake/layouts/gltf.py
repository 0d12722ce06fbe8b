"""The glTF Sample Viewer (KhronosGroup/glTF-Sample-Viewer) and KHR_materials_sheen: lut_ggx (the scale_bias pair,
1024² 16-bit PNG), lut_charlie (the sheen lobe's DFG in B) and lut_sheen_E (the sheen albedo for albedo scaling).

The sheen layouts integrate the KHR_materials_sheen lobe alone (no GGX, F = 1; lutbake.integrands.specular
sheen_integrand_for): ``charlie`` B = ∫ D_charlie V_ashikhmin (n.l) dω (source/shaders/ibl_filtering.frag LUT()),
``sheen_albedo`` R = E = ∫ D_charlie V_charlie (n.l) dω (the spec's albedo scaling), G = the same with V_ashikhmin;
``*_clamped`` clamp V to [0, 1] as the viewer's V_Ashikhmin / V_Sheen do. The roughness axis holds alpha =
sheenRoughness itself (KHR_materials_sheen's D and Lambda fit take it as is).

Preset ``gltf-ibl`` bakes lut_ggx with the viewer's environment cubes (source/Renderer/shaders/ibl.glsl): the specular
cube u_GGXEnvSampler at lod = roughness (u_MipCount - 1), the Lambertian cube u_LambertianEnvSampler, looked up at
u_EnvRotation * direction (orientation ``gl``).
"""

from __future__ import annotations

from dataclasses import replace

from .base import IBL, EngineTable, Layout, Terms

SHEEN_TERMS = Terms(ndf="charlie", masking="ashikhmin", fresnel="none")
SHEEN_GL_ONLY = (
    "layout {layout!r} needs estimator 'gauss_legendre': the QMC estimators draw h from the GGX NDF and miss the "
    "Charlie NDF's grazing lobe (got {estimator!r})"
)
CLAMPED = " (V clamped to [0, 1], as the glTF Sample Viewer)"
CHARLIE_DV = (
    "∫ D_charlie(h; alpha) V_ashikhmin (n.l) dω_l, no Fresnel: the sheen lobe's DFG for IBL "
    "(Estevez & Kulla 2017 NDF, Ashikhmin & Premoze 2007 visibility 1/(4 (n.l + n.v - (n.l)(n.v))))"
)
CHARLIE_SHADER = (
    "{uv}; KHR_materials_sheen IBL (glTF Sample Viewer getIBLRadianceCharlie): "
    "sheen = prefiltered_charlie * sheenColor * texture(lut, uv).b, at uv = vec2(NdotV, sheenRoughness)"
)
SHEEN_ALBEDO_SHADER = (
    "{uv}; KHR_materials_sheen albedo scaling: E = texture(lut, uv).r at uv = vec2(NdotV, "
    "sheenRoughness); sheenAlbedoScaling = 1 - max3(sheenColor) * E (or min over E(NdotV), E(NdotL)); "
    "f = f_sheen + (f_diffuse + f_specular) * sheenAlbedoScaling; .g is E with Ashikhmin visibility"
)
ABOVE_ONE = "Ashikhmin's visibility is not energy conserving: the charlie integral reaches ~2.8"


def sheen_terms(layout: str, masking: str) -> dict:
    """The lutbake:terms record of a layout that integrates the sheen lobe alone."""
    return {
        "model": "sheen",
        "ndf": "charlie (alpha = the roughness axis' alpha)",
        "masking": masking,
        "fresnel": "none (F = 1)",
        "layout": layout,
        "gauss_legendre_panels": "the GGX CDF in theta_h (panelling only; the integrand is the sheen lobe)",
    }


def sheen_layout(name: str, integrand: str, summary: str, channels: dict, shader: str, masking: str, split_sum):
    """A layout of the sheen lobe alone (gauss_legendre only, terms fixed, values above 1)."""
    return Layout(
        name=name,
        kind="dfg",
        engine="glTF Sample Viewer (KHR_materials_sheen)",
        summary=summary,
        channels=channels,
        shader=shader,
        integrand=integrand,
        source="KHR_materials_sheen; glTF-Sample-Viewer source/shaders/ibl_filtering.frag, brdf.glsl",
        terms=SHEEN_TERMS,
        terms_record=sheen_terms(name, masking),
        gauss_legendre_only=SHEEN_GL_ONLY,
        unit_range=False,
        above_one=ABOVE_ONE,
        split_sum=split_sum,
    )


ZERO_RG = {"zero_r": "0 (the viewer's lut_charlie leaves R empty)", "zero_g": "0"}
SHEEN_E = {
    "sheen_e": "E(n.v) = ∫ D_charlie V_charlie (n.l) dω_l: directional albedo of the KHR_materials_sheen BRDF with its "
    "Charlie visibility 1/((1 + Lambda(n.v) + Lambda(n.l)) 4 (n.v)(n.l)) (Estevez & Kulla 2017 fit)",
    "sheen_e_ashikhmin": "∫ D_charlie V_ashikhmin (n.l) dω_l: the same with the spec's cheaper Ashikhmin visibility "
    "(may exceed 1: not energy conserving, as the spec warns)",
}
ALBEDO_MASKING = "R: charlie (Estevez-Kulla Lambda fit), G: ashikhmin"

CHARLIE = sheen_layout(
    "charlie",
    "charlie",
    "sheen lobe alone: R = G = 0, B = ∫ D_charlie V_ashikhmin (n.l): the glTF Sample Viewer's lut_charlie "
    "(KHR_materials_sheen IBL; gauss_legendre only)",
    {**ZERO_RG, "charlie_dv": CHARLIE_DV},
    CHARLIE_SHADER,
    "ashikhmin",
    "sheen",
)
SHEEN_ALBEDO = sheen_layout(
    "sheen_albedo",
    "sheen_albedo",
    "sheen lobe alone: R = E = ∫ D_charlie V_charlie (n.l) (KHR_materials_sheen albedo scaling, "
    "Charlie visibility), G = the same with V_ashikhmin (gauss_legendre only)",
    SHEEN_E,
    SHEEN_ALBEDO_SHADER,
    ALBEDO_MASKING,
    None,
)
CHARLIE_CLAMPED = sheen_layout(
    "charlie_clamped",
    "charlie_clamped",
    "charlie with V_ashikhmin clamped to [0, 1]: the glTF Sample Viewer's LUT() integrand exactly",
    {**ZERO_RG, "charlie_dv": "∫ D_charlie min(V_ashikhmin, 1) (n.l) dω_l"},
    CHARLIE_SHADER,
    "ashikhmin" + CLAMPED,
    "sheen",
)
SHEEN_ALBEDO_CLAMPED = sheen_layout(
    "sheen_albedo_clamped",
    "sheen_albedo_clamped",
    "sheen_albedo with each V clamped to [0, 1], as the glTF Sample Viewer's V_Sheen / V_Ashikhmin",
    {
        "sheen_e": "∫ D_charlie min(V_charlie, 1) (n.l) dω_l",
        "sheen_e_ashikhmin": "∫ D_charlie min(V_ashikhmin, 1) (n.l) dω_l",
    },
    SHEEN_ALBEDO_SHADER,
    ALBEDO_MASKING + CLAMPED,
    None,
)

LAYOUTS = (CHARLIE, SHEEN_ALBEDO, CHARLIE_CLAMPED, SHEEN_ALBEDO_CLAMPED)
VIEWER = "glTF-Sample-Viewer source/shaders/ibl_filtering.frag LUT(), assets/images"


def viewer_sheen_table(preset: str, table: str, layout: str, size: int, loads: str, shader: str) -> EngineTable:
    """A glTF Sample Viewer sheen table: kind dfg in ``layout``, size x size, alpha on the roughness axis, texel
    centres, EXR."""
    keys = {"size": [size, size], "roughness": "alpha", "layout": layout, "texel": "center", "format": "exr"}
    return EngineTable("glTF Sample Viewer", preset, table, "dfg", layout, keys, VIEWER, loads, shader=shader)


IBL_SOURCE = "glTF-Sample-Viewer source/Renderer/shaders/ibl.glsl (getIBLRadianceGGX, getDiffuseLight)"
IBL_CONVENTIONS = IBL(
    "glTF Sample Viewer",
    ndf="ggx",
    masking="smith_height_correlated",
    roughness="perceptual",
    curve="linear",
    lobe="ggx_nl",
    source="ibl.glsl: lod = roughness * float(u_MipCount - 1); f_ab = texture(u_GGXLUT, vec2(NdotV, roughness)); "
    "lobe ggx_nl: lutbake's choice (glTF-IBL-Sampler's weighting not compared)",
)
CUBE_KEYS = {"orientation": "gl", "format": "ktx2", "dtype": "half"}  # textureLod(sampler, u_EnvRotation * R, lod)
LUT_GGX = EngineTable(
    "glTF Sample Viewer",
    "gltf",
    "lut_ggx",
    "dfg",
    "scale_bias",
    {
        "size": [1024, 1024],
        "roughness": "perceptual",
        "masking": "smith_height_correlated",
        "layout": "scale_bias",
        "texel": "center",
        "row_order": "lo_first",
        "format": "png16",
    },
    VIEWER,
    "assets/images/lut_ggx.png (16-bit linear PNG)",
    shipped="khronos_lut_ggx_u8.npz",
    shader=(
        "t = texture(u_GGXLUT, vec2(NdotV, r)).rg; k_S * t.r + t.g, k_S = F0 + (max(1 - r, F0) - F0) (1 - NdotV)^5"
    ),
    ibl=IBL_CONVENTIONS,
)
TABLES = (
    LUT_GGX,
    replace(LUT_GGX, preset="gltf-ibl", shipped=None),  # the same table in the one-run preset (audited as "gltf")
    EngineTable(
        "glTF Sample Viewer",
        "gltf-ibl",
        "gltf_specular",
        "environment_specular",
        None,
        {"curve": "linear", "lobe": "ggx_nl", **CUBE_KEYS},
        IBL_SOURCE,
        "u_GGXEnvSampler (a cube with mips)",
        shader="lod = roughness * float(u_MipCount - 1); textureLod(u_GGXEnvSampler, u_EnvRotation * reflection, lod)",
        ibl=IBL_CONVENTIONS,
    ),
    EngineTable(
        "glTF Sample Viewer",
        "gltf-ibl",
        "gltf_diffuse",
        "environment_irradiance",
        None,
        CUBE_KEYS,
        IBL_SOURCE,
        "u_LambertianEnvSampler (a cube, E / pi)",
        shader="texture(u_LambertianEnvSampler, u_EnvRotation * n).rgb",
        ibl=IBL_CONVENTIONS,
    ),
    viewer_sheen_table(
        "gltf-charlie",
        "lut_charlie",
        "charlie",
        128,
        "assets/images/lut_charlie.png (the viewer's own is 8-bit; the integral exceeds 1: EXR)",
        "texture(u_CharlieLUT, vec2(NdotV, sheenRoughness)).b",
    ),
    viewer_sheen_table(
        "gltf-sheen-e",
        "lut_sheen_E",
        "sheen_albedo",
        64,
        "assets/images/lut_sheen_E.png (the sheen albedo scaling)",
        "texture(u_SheenELUT, vec2(NdotV, sheenRoughness)).r",
    ),
)
