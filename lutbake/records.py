"""lutbake's own records, family by family (lutbake.registry): each name a config may choose, its one-line
description, its citation and the object it names, imported lazily (``Lazy``), so ``lutbake list``, ``--help`` and
config checking import no Warp. The kinds (lutbake.kinds) and the engine layouts (lutbake.layouts) register their own
records where they are declared. A plugin adds records of the same families through lutbake.plugins.

Adding a Fresnel term: its ``@wp.func`` in lutbake/terms/fresnel.py and its record here; an NDF: its terms in
lutbake/terms/ndf.py (D, Lambda, CDF) and its Distribution and record in lutbake/terms/distributions.py and here.
"""

from __future__ import annotations

from .registry import Lazy, Record, family

NDF = family("ndf", "normal distribution function D(m), with its Smith Lambda and samplers (one Distribution)")
MASKING = family("masking", "masking-shadowing G2")
FRESNEL = family("fresnel", "Fresnel reflectance F(f0, v.h)")
MODEL = family("model", "the specular term set of the dfg-like kinds (lecture 003)")
DIFFUSE = family("diffuse", "diffuse BRDF models (kinds diffuse, diffuse_3d, btf)")
FACET_FRESNEL = family("facet_fresnel", "the facet transmission of the microfacet diffuse model")
ANISO_MODEL = family("aniso_model", "anisotropic specular lobes (kind specular_aniso)")
LTC_LOBE = family("ltc_lobe", "the lobes the ltc kind fits")
HEMISPHERE_ESTIMATOR = family("hemisphere_estimator", "how the specular kinds estimate their integral per texel")
ANISO_ESTIMATOR = family("aniso_estimator", "how kind specular_aniso estimates its integral per texel")


def _terms(module: str, **names: str) -> dict[str, Lazy]:
    return {k: Lazy(f"lutbake.{module}:{v}") for k, v in names.items()}


def _add(fam, name, description, citation, aliases=(), **fields):
    fam.add(Record(fam.name, name, description, citation, tuple(aliases), fields))


# -- normal distributions: D and its polar CDF pair (lutbake.terms.ndf), the Smith Lambda (lutbake.terms.masking) and,
# for GGX, the visible-normal sampler; lutbake.terms.distributions builds one Distribution of them (the object).
# Blinn-Phong has no closed-form Smith Lambda. Walter et al. 2007 (Sec. 5.2) suggest Beckmann's at the same alpha, but
# that is only close for small alpha: at alpha = 1 (s = 0, D = 1/pi) it gave E(F = 1) = 1.77 at grazing view. So
# Blinn-Phong pairs with the V-cavity G only (no Lambda; kinds.dfg checks it).
for _name, _desc, _cite, _lambda, _vndf in (
    ("ggx", "GGX / Trowbridge-Reitz", "Walter et al. 2007, Eq. 33", "Lambda_ggx", "sample_vndf_ggx"),
    ("beckmann", "Beckmann, normalised with 1/pi", "Walter et al. 2007, Eq. 25", "Lambda_beckmann", None),
    (
        "blinn_phong",
        "normalized Blinn-Phong (s + 2)/(2 pi) (n.h)^s, s = 2/alpha^2 - 2 (masking = v_cavity only: no closed-form "
        "Smith Lambda)",
        "Walter et al. 2007, Eq. 30",
        None,
        None,
    ),
):
    _add(
        NDF,
        _name,
        _desc,
        _cite,
        obj=Lazy("lutbake.terms.distributions:NDFS", _name),
        D=Lazy(f"lutbake.terms.ndf:D_{_name}"),
        Lambda=_lambda and Lazy(f"lutbake.terms.masking:{_lambda}"),
        tan2_from_u=Lazy(f"lutbake.terms.ndf:tan2_from_u_{_name}"),
        u_from_tan2=Lazy(f"lutbake.terms.ndf:u_from_tan2_{_name}"),
        sample_vndf=_vndf and Lazy(f"lutbake.terms.ndf:{_vndf}"),
        smith=_lambda is not None,
        vndf=_vndf is not None,
    )

# -- masking-shadowing; ``smith``: goes only with an NDF that has a Smith Lambda (every form but the V-cavity, which
# goes with any NDF); ``transmission``: defined for the rough-glass BSDF
for _name, _desc, _cite, _smith, _trans in (
    (
        "smith_height_correlated",
        "Smith G2 = 1/(1 + Lambda(v) + Lambda(l)), height-correlated",
        "Heitz 2014, Eq. 99",
        1,
        1,
    ),
    ("smith_separable", "Smith G2 = G1(v) G1(l), separable", "Heitz 2014, Eq. 98", 1, 1),
    ("v_cavity", "Cook-Torrance V-cavity min(1, 2 NoH NoV / VoH, 2 NoH NoL / VoH)", "Cook & Torrance 1982", 0, 0),
    (
        "smith_joint_approx",
        "UE4's Vis_SmithJointApprox as G2 = 2 NoL NoV / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a)), a = alpha (an "
        "approximation of height-correlated Smith GGX; NDF-independent)",
        "Karis 2014, UE4 ShadingModels.ush",
        1,
        0,
    ),
    (
        "schlick_ggx_ibl",
        "separable Schlick-GGX G2 = G1(v) G1(l), G1 = NoX / (NoX (1 - k) + k), k = alpha / 2 (its IBL k; Godot's "
        "integrate_dfg.glsl; NDF-independent)",
        "Karis 2013, Eq. 4",
        1,
        0,
    ),
):
    _add(MASKING, _name, _desc, _cite, smith=bool(_smith), transmission=bool(_trans))

# -- Fresnel: ``F(f0 or n, ..., c)``; ``param``: "f0" (F(f0, c)), "nk" (F(n, k, c): a complex index) or "nka"
# (F(n, k, a, alpha, c): Lazanyi's fitted a); ``linear_in_f0``:
# F = f0 + (1 - f0) Fc(c), so the dfg kind factors f0 out (Fc = F(0, c), or the record's own ``Fc``)
for _name, _desc, _cite, _param, _linear in (
    ("schlick", "f0 + (1 - f0)(1 - c)^5", "Schlick 1994, Eq. 24", "f0", True),
    ("schlick_sg", "f0 + (1 - f0) 2^((-5.55473 c - 6.98316) c): spherical-Gaussian Schlick", "Lagarde 2012", "f0", 1),
    ("improved_sg", "f0 + (1 - f0) 2^(-9.60232 c^8 - 8.58092 c)", "Gotanda 2014 course notes, Eq. 3", "f0", True),
    ("dielectric_f0", "exact dielectric Fresnel written with f0", "Gotanda 2014 course notes, Eq. 2", "f0", False),
    ("conductor", "exact Fresnel of a complex index n + ik", "Born & Wolf 1999, Sec. 14.4", "nk", False),
    ("lazanyi", "metal approximation (n, k, fitted a)", "Lazanyi & Szirmay-Kalos 2005", "nka", False),
):
    _fields = {"F": Lazy(f"lutbake.terms.fresnel:F_{_name}"), "param": _param, "linear_in_f0": bool(_linear)}
    if _name == "schlick":
        _fields["Fc"] = Lazy("lutbake.terms.fresnel:Fc_schlick")
    _add(FRESNEL, _name, _desc, _cite, **_fields)

# -- the specular term sets of the dfg-like kinds: (integrand form, the NDF its estimators sample, masking)
for _name, _desc, _cite, _form, _ndf, _masking in (
    (
        "microfacet",
        "D G2 F / (4 (n.l)(n.v)) with the config's ndf and masking (default)",
        "Walter et al. 2007, Eq. 20",
        "microfacet",
        None,
        None,
    ),
    (
        "cook_torrance",
        "Beckmann D (with 1/pi), V-cavity G, Schlick F: the same as model = microfacet, ndf = beckmann, masking = "
        "v_cavity",
        "Cook & Torrance 1982 (lecture 003)",
        "microfacet",
        "beckmann",
        "v_cavity",
    ),
    (
        "blinn_phong",
        "the lecture's normalized Blinn-Phong lobe f = F (s + 8)/(8 pi) (n.h)^s, s = 2/alpha^2 - 2 (no G; the "
        "lecture's (s + 8)/8 is this times pi, per unit irradiance)",
        "Blinn 1977 (lecture 003)",
        "blinn_phong",
        "blinn_phong",
        "none",
    ),
    (
        "ashikhmin_shirley",
        "isotropic (nu = nv = s = 2/alpha^2 - 2): f = F sqrt((nu+1)(nv+1))/(8 pi) (n.h)^s / ((v.h) max(n.l, n.v))",
        "Ashikhmin & Shirley 2000",
        "ashikhmin_shirley",
        "blinn_phong",
        "none",
    ),
):
    _add(MODEL, _name, _desc, _cite, form=_form, ndf=_ndf and NDF.lookup(_ndf), masking=_masking)

# -- diffuse models: ``Fd`` the closed form (rho, NoL, NoV, LoV, sigma[, f0]) where there is one; ``f0_factor``
for _name, _desc, _cite, _fd, _with_f0 in (
    ("lambert", "Lambert, rho / pi", "Lambert 1760", "Fd_lambert", False),
    (
        "oren_nayar",
        "classic Oren-Nayar as taught in lecture 003 (A with 0.57)",
        "Oren & Nayar 1994",
        "Fd_oren_nayar",
        False,
    ),
    ("oren_nayar_improved", "improved Oren-Nayar", "Gotanda 2014 course notes, Eq. 5", "Fd_oren_nayar_improved", False),
    (
        "oren_nayar_fresnel",
        "Oren-Nayar with Fresnel ((1 - f0) counted once)",
        "Gotanda 2014 course notes, Eq. 7",
        "Fd_oren_nayar_fresnel",
        True,
    ),
    (
        "fitted",
        "Gotanda's fitted microfacet diffuse (course-notes reading)",
        "Gotanda 2014 course notes, Eq. 8",
        "Fd_gotanda_fitted",
        True,
    ),
    (
        "fitted_slides",
        "Eq. 8 with the slides' reading of F_r's second factor",
        "Gotanda 2014 slides, Eq. 8",
        "Fd_gotanda_fitted_slides",
        True,
    ),
    (
        "microfacet",
        "the microfacet diffuse model integrated over m (GGX, height-correlated Smith)",
        "Gotanda 2014 course notes, Eq. 4",
        None,
        True,
    ),
    (
        "eon",
        "energy-preserving Oren-Nayar, sigma = its roughness r; E = 1 for rho = 1 (exact-albedo variant)",
        "Portsmouth et al. 2024 (OpenPBR's diffuse)",
        "Fd_eon",
        False,
    ),
):
    # f0_factor: how E scales with f0 (every model is g(f0) times an f0-free function); None: its facet form's.
    # Fd: the closed form Fd(rho, NoL, NoV, LoV, sigma[, f0]) (lutbake.integrands.diffuse), where there is one
    _fields = {"with_f0": _with_f0, "f0_factor": None if _name == "microfacet" else "(1 - f0)" if _with_f0 else "1"}
    if _fd is not None and _name != "lambert":
        _fields["Fd"] = Lazy(f"lutbake.terms.diffuse:{_fd}")
    _add(DIFFUSE, _name, _desc, _cite, **_fields)

F0_NONE = "none: f0 does not factor out; the table holds E at the baked f0 only (kind diffuse_3d has an f0 axis)"
for _name, _desc, _t, _factor in (
    (
        "eq6",
        "Eq. 6 on each facet: 21/20 (1 - f0)(1 - (1 - m.l)^5)(1 - (1 - m.v)^5); E scales with (1 - f0)",
        "T_pow5",
        "(1 - f0)",
    ),
    (
        "schlick",
        "(1 - F(m.l))(1 - F(m.v)), F Schlick: (1 - f0)^2 (1 - (1 - m.l)^5)(1 - (1 - m.v)^5); E scales with (1 - f0)^2",
        "T_pow5",
        "(1 - f0)^2",
    ),
    (
        "dielectric_f0",
        "(1 - F(m.l))(1 - F(m.v)), F the exact dielectric Fresnel of Eq. 2 written with f0: f0 does not "
        "factor out (kind diffuse_3d bakes an f0 axis; kind diffuse bakes the given f0 only)",
        "T_dielectric_f0",
        F0_NONE,
    ),
):
    _add(
        FACET_FRESNEL,
        _name,
        _desc,
        "Gotanda 2014 course notes, Eq. 6",
        F=Lazy(f"lutbake.terms.diffuse:F_facet_{_name}"),
        T=Lazy(f"lutbake.terms.diffuse:{_t}"),
        f0_factor=_factor,
    )

_add(
    ANISO_MODEL,
    "microfacet",
    "anisotropic GGX, height-correlated Smith G2 with the anisotropic Lambda, Schlick F",
    "Heitz 2014, Eqs. 85, 99",
)
_add(
    ANISO_MODEL,
    "ashikhmin_shirley",
    "nu = 2/alpha_x^2 - 2 (tangent), nv = 2/alpha_y^2 - 2 (bitangent)",
    "Ashikhmin & Shirley 2000",
)

# -- LTC lobes: the object is the Lobe (lutbake.ltc.lobes)
for _name, _desc, _cite in (
    ("ggx", "GGX, height-correlated Smith (ltc_code's BrdfGGX; the reference case)", "Heitz et al. 2016"),
    ("beckmann", "Beckmann, height-correlated Smith with the exact Lambda", "Heitz et al. 2016"),
    (
        "charlie",
        "KHR_materials_sheen: D_charlie V_ashikhmin, alpha = sheenRoughness (gltf-charlie)",
        "Estevez & Kulla 2017",
    ),
    ("lambert", "Lambert (n.l)/pi: its LTC is the identity (a check)", "Heitz et al. 2016"),
    (
        "gotanda",
        "microfacet diffuse (Eq. 4: Lambertian GGX facets, Eq. 6 facet Fresnel, f0 = 0), GGX alpha = sigma; f "
        "tabulated per texel by lutbake's quadrature and interpolated",
        "Gotanda 2014 course notes, Eq. 4",
    ),
    (
        "eon",
        "energy-preserving Oren-Nayar (OpenPBR's diffuse), rho = 1, exact albedo (E = 1); x = base_diffuse_roughness",
        "Portsmouth et al. 2024",
    ),
    (
        "zeltner",
        "analytic volumetric sheen (an SGGX fiber slab: exact single scattering + their multiple-scattering "
        "fit), sigma = alpha^2; M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]] in the normal's frame",
        "Zeltner et al. 2022",
    ),
):
    _add(LTC_LOBE, _name, _desc, _cite, obj=Lazy("lutbake.ltc.lobes:LOBES", _name))

# -- estimators of the specular kinds (lutbake.sampling.hemisphere) and of specular_aniso (lutbake.sampling.anisotropic)
for _name, _desc, _cite in (
    (
        "gauss_legendre",
        "deterministic product Gauss-Legendre over panels in theta_h (or CDF(theta_h)) and phi, split "
        "exactly at the horizon (default; converges exponentially)",
        "Trefethen 2008",
    ),
    ("sobol_vndf", "scrambled Sobol' points, GGX visible-normal sampling", "Dupuy & Benyoub 2023"),
    ("sobol_ndf", "scrambled Sobol' points, NDF importance sampling of D(h)(n.h)", "Walter et al. 2007"),
    ("hammersley_ndf", "Hammersley points, NDF importance sampling (Filament cmgen's estimator)", "Karis 2013"),
):
    _add(HEMISPHERE_ESTIMATOR, _name, _desc, _cite)
for _name, _desc, _cite in (
    (
        "gauss_legendre",
        "panelled Gauss-Legendre to the tolerance, the view azimuth averaged inside the integrand "
        "(default; with view_azimuth = average: a fixed view azimuth takes sobol)",
        "Trefethen 2008",
    ),
    (
        "sobol",
        "scrambled 3D Sobol' points: h by anisotropic GGX VNDF sampling (microfacet) or the Ashikhmin-Shirley h "
        "sampling; phi_v = 2 pi u3 when averaged",
        "Heitz 2018",
    ),
    (
        "sobol_cosine",
        "scrambled 3D Sobol' points: l cosine-weighted (independent of the lobe's sampler); phi_v = 2 pi "
        "u3 when averaged",
        "Sobol' 1967",
    ),
):
    _add(ANISO_ESTIMATOR, _name, _desc, _cite)
