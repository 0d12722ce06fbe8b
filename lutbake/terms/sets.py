"""Term sets: the host-side records that pair each named NDF / masking form with its ``@wp.func``s,
plus the composed ``wp.func``s a table kernel closes over (cached by key)."""

from __future__ import annotations

import functools
from dataclasses import dataclass

import warp as wp

from ..edge import COS_EPS
from . import masking, ndf


@dataclass(frozen=True)
class Ndf:
    name: str
    description: str
    D: object
    Lambda: object
    tan2_from_u: object
    u_from_tan2: object
    vndf: object | None = None  # visible-normal sampler, where one exists


NDFS = {
    "ggx": Ndf(
        "ggx",
        "GGX / Trowbridge-Reitz (Walter et al. 2007)",
        ndf.D_ggx,
        masking.Lambda_ggx,
        ndf.tan2_from_u_ggx,
        ndf.u_from_tan2_ggx,
        ndf.sample_vndf_ggx,
    ),
    "beckmann": Ndf(
        "beckmann",
        "Beckmann, normalised with 1/pi (Walter et al. 2007, Eq. 25)",
        ndf.D_beckmann,
        masking.Lambda_beckmann,
        ndf.tan2_from_u_beckmann,
        ndf.u_from_tan2_beckmann,
    ),
    # Blinn-Phong has no closed-form Smith Lambda. Walter et al. 2007 (Sec. 5.2) suggest Beckmann's at the same
    # alpha, but that is only close for small alpha: at alpha = 1 (s = 0, D = 1/pi) it gave E(F = 1) = 1.77 at
    # grazing view. So Blinn-Phong pairs with the V-cavity G only (Lambda = None; dfg.check_spec enforces it).
    "blinn_phong": Ndf(
        "blinn_phong",
        "normalized Blinn-Phong (s + 2)/(2 pi) (n.h)^s, s = 2/alpha^2 - 2 "
        "(masking = v_cavity only: no closed-form Smith Lambda)",
        ndf.D_blinn_phong,
        None,
        ndf.tan2_from_u_blinn_phong,
        ndf.u_from_tan2_blinn_phong,
    ),
}
SMITH_NDFS = tuple(n for n, d in NDFS.items() if d.Lambda is not None)

# The lecture's models (003) as term sets of the dfg-like kinds (key ``model``). "microfacet" takes ``ndf`` and
# ``masking`` from the config; the others fix them: (integrand form, NDF whose CDF the estimators sample, masking).
MODELS = {
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


MASKINGS = {
    "smith_height_correlated": "Smith G2 = 1/(1 + Lambda(v) + Lambda(l)), height-correlated (Heitz 2014, Eq. 99)",
    "smith_separable": "Smith G2 = G1(v) G1(l), separable (Heitz 2014, Eq. 98)",
    "v_cavity": "Cook-Torrance V-cavity min(1, 2 NoH NoV / VoH, 2 NoH NoL / VoH) (lecture 003)",
    "smith_joint_approx": "UE4's Vis_SmithJointApprox as G2 = 2 NoL NoV / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a)), "
    "a = alpha (an approximation of height-correlated Smith GGX; NDF-independent)",
}


def pair_allowed(ndf_name: str, masking_name: str) -> bool:
    """Smith masking needs the NDF's Lambda; V-cavity goes with any NDF."""
    return masking_name == "v_cavity" or NDFS[ndf_name].Lambda is not None


@functools.lru_cache(maxsize=None)
def G2_for(ndf_name: str, masking_name: str):
    """The composed masking-shadowing ``G2(NoV, NoL, NoH, VoH, alpha)`` for an NDF and a masking form."""
    Lam = NDFS[ndf_name].Lambda
    if masking_name == "smith_height_correlated":

        @wp.func
        def G2(NoV: float, NoL: float, NoH: float, VoH: float, alpha: float):
            return masking.G2_smith_height_correlated(Lam(NoV, alpha), Lam(NoL, alpha))
    elif masking_name == "smith_separable":

        @wp.func
        def G2(NoV: float, NoL: float, NoH: float, VoH: float, alpha: float):
            return masking.G2_smith_separable(Lam(NoV, alpha), Lam(NoL, alpha))
    elif masking_name == "v_cavity":

        @wp.func
        def G2(NoV: float, NoL: float, NoH: float, VoH: float, alpha: float):
            return masking.G2_v_cavity(NoH, NoV, NoL, VoH, VoH)
    elif masking_name == "smith_joint_approx":

        @wp.func
        def G2(NoV: float, NoL: float, NoH: float, VoH: float, alpha: float):
            return masking.G2_smith_joint_approx(NoV, NoL, alpha)
    else:
        raise KeyError(masking_name)
    return G2


@functools.lru_cache(maxsize=None)
def pdf_ndf_for(ndf_name: str):
    """Density of h under NDF sampling: p(h) = D(h) (n.h)."""
    D = NDFS[ndf_name].D

    @wp.func
    def pdf_ndf(v: wp.vec3, h: wp.vec3, alpha: float):
        return D(h, alpha) * h[2]

    return pdf_ndf


@functools.lru_cache(maxsize=None)
def sample_ndf_for(ndf_name: str):
    """h from the NDF's inverse CDF: tan^2 theta = CDF^-1(u1) (float64), phi = 2 pi u2."""
    t2u = NDFS[ndf_name].tan2_from_u

    @wp.func
    def sample_ndf(v: wp.vec3, alpha: float, u1: float, u2: float):
        tan2 = t2u(wp.float64(u1), wp.float64(alpha))
        c = wp.float64(1.0) / wp.sqrt(wp.float64(1.0) + tan2)
        s = float(wp.sqrt(tan2) * c)
        phi = 2.0 * wp.pi * u2
        return wp.vec3(s * wp.cos(phi), s * wp.sin(phi), float(c))

    return sample_ndf


@functools.lru_cache(maxsize=None)
def pdf_vndf_for(ndf_name: str):
    """Density of h under visible-normal sampling: p(h) = G1(v) max(0, v.h) D(h) / (n.v)."""
    nd = NDFS[ndf_name]
    D, Lam = nd.D, nd.Lambda

    @wp.func
    def pdf_vndf(v: wp.vec3, h: wp.vec3, alpha: float):
        VoH = wp.dot(v, h)
        if VoH <= COS_EPS or v[2] <= COS_EPS:
            return 0.0
        return masking.G1_smith(Lam(v[2], alpha)) * VoH * D(h, alpha) / v[2]

    return pdf_vndf
