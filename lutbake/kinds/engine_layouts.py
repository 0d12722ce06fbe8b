"""The dfg layouts that add an engine's pre-integrated diffuse term as channel B (Unity HDRP PreIntegratedFGD):
what they declare (names, channels, reconstruction, base layout). The integrals, derived in
lutbake.integrands.engine_diffuse, are computed there; lutbake.kinds.dfg merges these into its layouts.
"""

from __future__ import annotations

LAYOUTS = {
    "multiscatter_disney": "multiscatter + B = (1/pi) ∫ Fd_disney (n.l) dω - 0.5: Unity HDRP "
    "PreIntegratedFGD_GGXDisneyDiffuse",
    "charlie_fabric": "sheen lobe: R = ∫ D_charlie V_charlie Fc (n.l) / 2pi, G = ∫ D_charlie V_charlie (n.l) / 2pi, "
    "B = FabricLambertNoPI(alpha): Unity HDRP PreIntegratedFGD_CharlieFabricLambert (gauss_legendre only)",
}
CHANNELS = {
    "multiscatter_disney": {
        "fc": "∫ f/F (1 - v.h)^5 (n.l) dω_l: the f90 weight (HDRP preFGD.x)",
        "e_ss": "∫ f/F (n.l) dω_l: E with F = 1, HDRP's 'reflectivity' (preFGD.y)",
        "disney_fgd_minus_half": "(1/pi) ∫ Fd_disney(n.v, n.l, l.v, r) (n.l) dω_l - 0.5, Burley diffuse without 1/pi "
        "normalised by 1.03571 as HDRP's DisneyDiffuseNoPI (preFGD.z; diffuseFGD = z + 0.5)",
    },
    "charlie_fabric": {
        "fc_over_2pi": "(1/2pi) ∫ D_charlie V_charlie (1 - v.h)^5 (n.l) dω_l, Estevez & Kulla 2017 NDF and Lambda fit "
        "(HDRP preFGD.x)",
        "e_over_2pi": "(1/2pi) ∫ D_charlie V_charlie (n.l) dω_l: the sheen albedo / 2pi (HDRP preFGD.y, its "
        "'reflectivity' as stored)",
        "fabric_lambert": "FabricLambertNoPI(alpha) = lerp(1, 0.5, alpha) (HDRP preFGD.z = diffuseFGD)",
    },
}
RECONSTRUCTION = {
    "multiscatter_disney": "uv = Remap01ToHalfTexelCoord(vec2(sqrt(NoV), perceptualRoughness), 64); t = texture(lut, "
    "uv).rgb; specularFGD = mix(t.r, t.g, f0); diffuseFGD = t.b + 0.5; reflectivity = t.g",
    "charlie_fabric": "uv = vec2(NoV, perceptualRoughness) (texel centres); t = texture(lut, uv).rgb; specularFGD = "
    "mix(t.r, t.g, f0) * 2 pi; diffuseFGD = t.b; reflectivity = t.g (HDRP, as stored: the albedo / 2pi)",
}
BASE_LAYOUT = {"multiscatter_disney": "multiscatter", "charlie_fabric": "sheen_fgd"}
DIFFUSE_TERMS = {
    "multiscatter_disney": "disney (Burley 2012, HDRP DisneyDiffuseNoPI / 1.03571), minus 0.5",
    "charlie_fabric": "fabric lambert (HDRP FabricLambertNoPI = lerp(1, 0.5, alpha)); R, G divided by 2 pi",
}
