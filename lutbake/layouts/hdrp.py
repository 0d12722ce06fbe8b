"""Unity HDRP (com.unity.render-pipelines.high-definition, Runtime/Material/PreIntegratedFGD): the
PreIntegratedFGD tables that add a pre-integrated diffuse term as channel B (lutbake.integrands.engine_diffuse derives
the integrals), and LtcData.BRDF_GGX.cs.

    multiscatter_disney  R, G = the multiscatter pair, B = (1/pi) ∫ Fd_disney (n.l) dω - 0.5
                         (preIntegratedFGD_GGXDisneyDiffuse.shader: x = sqrt(NoV), endpoint texels)
    charlie_fabric       R, G = the sheen lobe's multiscatter pair / 2 pi (Charlie NDF and visibility), B =
                         FabricLambertNoPI(alpha) (preIntegratedFGD_CharlieFabricLambert.shader)
"""

from __future__ import annotations

import math

from .base import EngineChannel, EngineTable, Layout, Terms
from .gltf import SHEEN_GL_ONLY, sheen_terms

HDRP_UNIFORM_SCALE = 2.0 * math.pi  # HDRP's Charlie R, G are the integrals / 2 pi (its runtime multiplies by 2 pi)
SOURCE = "HDRP Runtime/Material/PreIntegratedFGD (PreIntegratedFGD.hlsl, preIntegratedFGD_*.shader)"
DISNEY = "disney (Burley 2012, HDRP DisneyDiffuseNoPI / 1.03571), minus 0.5"
FABRIC = "fabric lambert (HDRP FabricLambertNoPI = lerp(1, 0.5, alpha)); R, G divided by 2 pi"

MULTISCATTER_DISNEY = Layout(
    name="multiscatter_disney",
    kind="dfg",
    engine="Unity HDRP (PreIntegratedFGD_GGXDisneyDiffuse)",
    summary="multiscatter + B = (1/pi) ∫ Fd_disney (n.l) dω - 0.5: Unity HDRP PreIntegratedFGD_GGXDisneyDiffuse",
    channels={
        "fc": "∫ f/F (1 - v.h)^5 (n.l) dω_l: the f90 weight (HDRP preFGD.x)",
        "e_ss": "∫ f/F (n.l) dω_l: E with F = 1, HDRP's 'reflectivity' (preFGD.y)",
        "disney_fgd_minus_half": "(1/pi) ∫ Fd_disney(n.v, n.l, l.v, r) (n.l) dω_l - 0.5, Burley diffuse without 1/pi "
        "normalised by 1.03571 as HDRP's DisneyDiffuseNoPI (preFGD.z; diffuseFGD = z + 0.5)",
    },
    shader="uv = Remap01ToHalfTexelCoord(vec2(sqrt(NoV), perceptualRoughness), 64); t = texture(lut, "
    "uv).rgb; specularFGD = mix(t.r, t.g, f0); diffuseFGD = t.b + 0.5; reflectivity = t.g",
    integrand="multiscatter",
    source=SOURCE,
    engine_channel=EngineChannel("disney", 1.0, DISNEY),
    unit_range=False,
    above_one="B = Disney FGD - 0.5 spans [-0.028, 1.0036] on endpoint texels (NoV = 0 rows)",
    split_sum="multiscatter",
)
CHARLIE_FABRIC = Layout(
    name="charlie_fabric",
    kind="dfg",
    engine="Unity HDRP (PreIntegratedFGD_CharlieFabricLambert)",
    summary="sheen lobe: R = ∫ D_charlie V_charlie Fc (n.l) / 2pi, G = ∫ D_charlie V_charlie (n.l) / 2pi, "
    "B = FabricLambertNoPI(alpha): Unity HDRP PreIntegratedFGD_CharlieFabricLambert (gauss_legendre only)",
    channels={
        "fc_over_2pi": "(1/2pi) ∫ D_charlie V_charlie (1 - v.h)^5 (n.l) dω_l, Estevez & Kulla 2017 NDF and Lambda fit "
        "(HDRP preFGD.x)",
        "e_over_2pi": "(1/2pi) ∫ D_charlie V_charlie (n.l) dω_l: the sheen albedo / 2pi (HDRP preFGD.y, its "
        "'reflectivity' as stored)",
        "fabric_lambert": "FabricLambertNoPI(alpha) = lerp(1, 0.5, alpha) (HDRP preFGD.z = diffuseFGD)",
    },
    shader="uv = vec2(NoV, perceptualRoughness) (texel centres); t = texture(lut, uv).rgb; specularFGD = "
    "mix(t.r, t.g, f0) * 2 pi; diffuseFGD = t.b; reflectivity = t.g (HDRP, as stored: the albedo / 2pi)",
    integrand="sheen_fgd",
    source=SOURCE,
    terms=Terms(ndf="charlie", masking="charlie", fresnel="none"),
    terms_record=sheen_terms("charlie_fabric", "charlie (Estevez-Kulla Lambda fit), R and G"),
    gauss_legendre_only=SHEEN_GL_ONLY,
    engine_channel=EngineChannel("fabric", HDRP_UNIFORM_SCALE, FABRIC),
    split_sum=None,
)

LAYOUTS = (MULTISCATTER_DISNEY, CHARLIE_FABRIC)
TABLES = (
    EngineTable(
        "Unity HDRP",
        "unity-hdrp",
        "preIntegratedFGD_GGXDisneyDiffuse",
        "dfg",
        "multiscatter_disney",
        {
            "size": [64, 64],
            "roughness": "perceptual",
            "masking": "smith_height_correlated",
            "layout": "multiscatter_disney",
            "texel": "endpoint",
            "nov_mapping": "square",
        },
        SOURCE,
        "the PreIntegratedFGD render target (64 x 64, built at runtime)",
        shader=(
            "t = texture(lut, vec2(sqrt(NoV), r) * 63.0/64.0 + 0.5/64.0).rgb; specularFGD = lerp(t.x, t.y, f0); "
            "diffuseFGD = t.z + 0.5"
        ),
    ),
    EngineTable(
        "Unity HDRP",
        "unity-hdrp-charlie",
        "preIntegratedFGD_CharlieFabricLambert",
        "dfg",
        "charlie_fabric",
        {"size": [64, 64], "roughness": "perceptual", "layout": "charlie_fabric", "texel": "center"},
        SOURCE,
        "the PreIntegratedFGD render target (64 x 64, built at runtime)",
        shader="t = texture(lut, vec2(NoV, r)).rgb; specularFGD = lerp(t.x, t.y, f0) * 2π; diffuseFGD = t.z",
    ),
    EngineTable(
        "Unity HDRP",
        "ltc-hdrp",
        "LtcData_BRDF_GGX",
        "ltc",
        None,
        {"lobe": "ggx", "size": [64, 64], "alpha_min": 1e-3, "format": "cs"},
        "HDRP Runtime/Material/LTCAreaLight/LtcData.BRDF_GGX.cs",
        "LtcData.BRDF_GGX.cs (s_LtcMatrixData_BRDF_GGX)",
    ),
)
