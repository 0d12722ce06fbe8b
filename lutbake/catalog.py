"""The names a config may choose, each with its one-line meaning: NDFs, masking forms, models, Fresnel terms,
estimators, LTC lobes. Warp-free (no Warp, SciPy or OpenImageIO), so the kind registry (lutbake.kinds), config
checking and ``lutbake list`` start at once; the modules that implement each name (lutbake.terms, .integrands,
.sampling, .ltc: Warp kernels) import its table from here, so every table exists once
(tests/test_catalog.py checks that the implementations cover exactly these names).
"""

from __future__ import annotations

# -- normal distributions (lutbake.terms.distributions: one Distribution record per name, built from these)
NDF_DESCRIPTIONS = {
    "ggx": "GGX / Trowbridge-Reitz (Walter et al. 2007)",
    "beckmann": "Beckmann, normalised with 1/pi (Walter et al. 2007, Eq. 25)",
    "blinn_phong": "normalized Blinn-Phong (s + 2)/(2 pi) (n.h)^s, s = 2/alpha^2 - 2 "
    "(masking = v_cavity only: no closed-form Smith Lambda)",
}
SMITH_NDFS = ("ggx", "beckmann")  # with a closed-form Smith Lambda (Distribution.Lambda is not None)
VNDF_NDFS = ("ggx",)  # with a visible-normal sampler (Distribution.sample_vndf is not None)
MASKINGS = {
    "smith_height_correlated": "Smith G2 = 1/(1 + Lambda(v) + Lambda(l)), height-correlated (Heitz 2014, Eq. 99)",
    "smith_separable": "Smith G2 = G1(v) G1(l), separable (Heitz 2014, Eq. 98)",
    "v_cavity": "Cook-Torrance V-cavity min(1, 2 NoH NoV / VoH, 2 NoH NoL / VoH) (lecture 003)",
    "smith_joint_approx": "UE4's Vis_SmithJointApprox as G2 = 2 NoL NoV / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a)), "
    "a = alpha (an approximation of height-correlated Smith GGX; NDF-independent)",
    "schlick_ggx_ibl": "separable Schlick-GGX G2 = G1(v) G1(l), G1 = NoX / (NoX (1 - k) + k), k = alpha / 2 "
    "(Karis 2013 Eq. 4, its IBL k; Godot's integrate_dfg.glsl; NDF-independent)",
}


def masking_allowed(ndf_name: str, masking_name: str) -> bool:
    """Smith masking needs the NDF's Lambda (SMITH_NDFS); V-cavity goes with any NDF."""
    return masking_name == "v_cavity" or ndf_name in SMITH_NDFS


DIELECTRIC_MASKINGS = ("smith_separable", "smith_height_correlated")  # defined for transmission (integrands.dielectric)


# -- the specular term sets of the dfg-like kinds (lutbake.integrands.specular)
# The lecture's models (003) as term sets of the dfg-like kinds (key ``model``). "microfacet" takes ``ndf`` and
# ``masking`` from the config; the others fix them: (integrand form, NDF whose CDF the estimators sample, masking).
SPECULAR_MODELS = {
    "microfacet": "D G2 F / (4 (n.l)(n.v)) with the config's ndf and masking (default)",
    "cook_torrance": "Cook & Torrance 1982 as in the lecture: Beckmann D (with 1/pi), V-cavity G, Schlick F; "
    "the same as model = microfacet, ndf = beckmann, masking = v_cavity",
    "blinn_phong": "the lecture's normalized Blinn-Phong lobe f = F (s + 8)/(8 pi) (n.h)^s, s = 2/alpha^2 - 2 "
    "(no G; the lecture's (s + 8)/8 is this times pi, per unit irradiance)",
    "ashikhmin_shirley": "Ashikhmin & Shirley 2000, isotropic (nu = nv = s = 2/alpha^2 - 2): "
    "f = F sqrt((nu+1)(nv+1))/(8 pi) (n.h)^s / ((v.h) max(n.l, n.v))",
}


def model_terms(model: str, ndf_name: str, masking_name: str) -> tuple[str, str, str]:
    """(integrand form, ndf, masking) a model integrates: the form is "microfacet", "blinn_phong" or
    "ashikhmin_shirley"; Cook-Torrance is the microfacet form with Beckmann and V-cavity."""
    if model == "microfacet":
        return "microfacet", ndf_name, masking_name
    if model == "cook_torrance":
        return "microfacet", "beckmann", "v_cavity"
    if model in ("blinn_phong", "ashikhmin_shirley"):
        return model, "blinn_phong", "none"
    raise KeyError(model)


# the sheen lobe alone: no GGX term (sheen_integrand_for); *_clamped: V clamped to [0, 1] (the viewer's shaders)
SHEEN_LAYOUTS = ("charlie", "sheen_albedo", "charlie_clamped", "sheen_albedo_clamped", "sheen_fgd")

FRESNELS = {
    "schlick": "f0 + (1 - f0)(1 - c)^5 (Schlick 1994)",
    "schlick_sg": "f0 + (1 - f0) 2^((-5.55473 c - 6.98316) c): spherical-Gaussian Schlick (Lagarde 2012)",
    "improved_sg": "f0 + (1 - f0) 2^(-9.60232 c^8 - 8.58092 c): Gotanda 2014, Eq. 3",
    "dielectric_f0": "exact dielectric Fresnel written with f0: Gotanda 2014, Eq. 2",
    "conductor": "exact Fresnel of a complex index n + ik",
    "lazanyi": "Lazanyi & Szirmay-Kalos 2005 metal approximation (n, k, fitted a)",
}

# -- diffuse models (lutbake.integrands.diffuse)
FACET_FRESNEL = {
    "eq6": "Eq. 6 on each facet: 21/20 (1 - f0)(1 - (1 - m.l)^5)(1 - (1 - m.v)^5); E scales with (1 - f0)",
    "schlick": "(1 - F(m.l))(1 - F(m.v)), F Schlick: (1 - f0)^2 (1 - (1 - m.l)^5)(1 - (1 - m.v)^5); "
    "E scales with (1 - f0)^2",
    "dielectric_f0": "(1 - F(m.l))(1 - F(m.v)), F the exact dielectric Fresnel of Eq. 2 written with f0: f0 does not "
    "factor out (kind diffuse_3d bakes an f0 axis; kind diffuse bakes the given f0 only)",
}
DIFFUSE_MODELS = {
    "lambert": "Lambert, rho / pi",
    "oren_nayar": "classic Oren-Nayar as taught in lecture 003 (A with 0.57)",
    "oren_nayar_improved": "improved Oren-Nayar, Gotanda 2014 Eq. 5",
    "oren_nayar_fresnel": "Oren-Nayar with Fresnel, Gotanda 2014 Eq. 7 ((1 - f0) counted once)",
    "fitted": "Gotanda's fitted microfacet diffuse, Eq. 8 (course-notes reading)",
    "fitted_slides": "Eq. 8 with the slides' reading of F_r's second factor",
    "microfacet": "the microfacet diffuse model, Eq. 4, integrated over m (GGX, height-correlated Smith)",
    "eon": "energy-preserving Oren-Nayar (Portsmouth et al. 2024, OpenPBR's diffuse), sigma = its roughness r; "
    "E = 1 for rho = 1 (exact-albedo variant)",
}


F0_NONE = "none: f0 does not factor out; the table holds E at the baked f0 only (kind diffuse_3d has an f0 axis)"


def f0_factor(model: str, facet_fresnel: str) -> str:
    """How f0 enters a model: every model here is g(f0) times an f0-free function."""
    if model in ("lambert", "oren_nayar", "oren_nayar_improved", "eon"):
        return "1"
    if model == "microfacet" and facet_fresnel == "schlick":
        return "(1 - f0)^2"
    if model == "microfacet" and facet_fresnel == "dielectric_f0":
        return F0_NONE
    return "(1 - f0)"


# -- anisotropic lobes (lutbake.integrands.anisotropic)
ANISO_MODELS = {
    "microfacet": "anisotropic GGX, height-correlated Smith G2 with the anisotropic Lambda, Schlick F (Heitz 2014)",
    "ashikhmin_shirley": "Ashikhmin & Shirley 2000, nu = 2/alpha_x^2 - 2 (tangent), nv = 2/alpha_y^2 - 2 (bitangent)",
}
ANISO_LAYOUTS = ("scale_bias", "multiscatter")
AXES_FORMULA = (
    "aspect = sqrt(1 - 0.9 |a|); alpha_x = alpha / aspect, alpha_y = alpha * aspect (a >= 0; swapped for a < 0)"
)

# -- estimators (lutbake.sampling.hemisphere, lutbake.sampling.anisotropic)
HEMISPHERE_ESTIMATORS = {
    "gauss_legendre": "deterministic product Gauss-Legendre over panels in theta_h (or CDF(theta_h)) and phi, "
    "split exactly at the horizon (default; converges exponentially)",
    "sobol_vndf": "scrambled Sobol' points, GGX visible-normal sampling (Dupuy & Benyoub 2023)",
    "sobol_ndf": "scrambled Sobol' points, NDF importance sampling of D(h)(n.h)",
    "hammersley_ndf": "Hammersley points, NDF importance sampling (Filament cmgen's estimator)",
}
ANISO_ESTIMATORS = {
    "gauss_legendre": "panelled Gauss-Legendre to the tolerance, the view azimuth averaged inside the integrand "
    "(default; with view_azimuth = average: a fixed view azimuth takes sobol)",
    "sobol": "scrambled 3D Sobol' points: h by anisotropic GGX VNDF sampling (microfacet) or the Ashikhmin-Shirley "
    "h sampling; phi_v = 2 pi u3 when averaged",
    "sobol_cosine": "scrambled 3D Sobol' points: l cosine-weighted (independent of the lobe's sampler); "
    "phi_v = 2 pi u3 when averaged",
}

# -- LTC lobes (lutbake.ltc.lobes: one Lobe record per name) and the fit's error-metric grid (lutbake.ltc.fit)
LTC_LOBES = {
    "ggx": "GGX, height-correlated Smith (ltc_code's BrdfGGX; the reference case)",
    "beckmann": "Beckmann, height-correlated Smith with the exact Lambda",
    "charlie": "KHR_materials_sheen: D_charlie V_ashikhmin, alpha = sheenRoughness (gltf-charlie)",
    "lambert": "Lambert (n.l)/pi: its LTC is the identity (a check)",
    "gotanda": "Gotanda 2014 microfacet diffuse (Eq. 4: Lambertian GGX facets, Eq. 6 facet Fresnel, f0 = 0), "
    "GGX alpha = sigma; f tabulated per texel by lutbake's quadrature and interpolated",
    "eon": "energy-preserving Oren-Nayar (Portsmouth et al. 2024; OpenPBR's diffuse), rho = 1, exact albedo "
    "(E = 1); x = base_diffuse_roughness",
    "zeltner": "Zeltner, Burley & Chiang 2022's analytic volumetric sheen (an SGGX fiber slab: exact single "
    "scattering + their multiple-scattering fit), sigma = alpha^2; M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]] in the "
    "normal's frame",
}
LTC_FIT_GRID = 32  # ltc_code Nsample: the metric's grid is N x N per sampling technique
