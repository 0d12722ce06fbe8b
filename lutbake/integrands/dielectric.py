"""Integrands of the rough dielectric BSDF (Walter, Marschner, Li & Torrance 2007, "Microfacet models for refraction
through rough surfaces", Eqs. 20-21) in the half-vector measure, for the energy tables of lutbake.kinds.dielectric.

For a view v (n.v = mu > 0, on the incident side, relative index eta = eta_o / eta_i), both lobes are written over
the same microfacet normal h (v.h > 0, n.h > 0):
    reflection    o = l = reflect(v, h),  dω_l = 4 (v.h) dω_h                       (Walter Eq. 14)
    transmission  o = t = refract(v, h, eta),  dω_h / dω_t = eta^2 |t.h| / (v.h + eta t.h)^2   (Walter Eq. 17)
so that
    E_R(mu) = ∫ f_r |n.l| dω_l = ∫ F(v.h) D(h) G2(v, l) (v.h) / mu  [n.l > 0] dω_h
    E_T(mu) = ∫ f_t |n.t| dω_t = ∫ (1 - F(v.h)) D(h) G2(v, t) (v.h) / mu  [n.t < 0, no TIR] dω_h
(the Jacobian cancels f_t's |i.h||o.h| eta_o^2 / (eta_i i.h + eta_o o.h)^2 exactly). G2(v, o) is the Smith term
"generalised for transmission": evaluated with |n.o| on either side (separable G1(v) G1(o), or height-correlated
1 / (1 + Lambda(v) + Lambda(o)), the form pbrt-v4's DielectricBxDF uses for both lobes).

A *Fresnel mode* picks the channels (each a weight of the two lobes at the same h):
    exact        (F w_R, (1 - F) w_T, F w_R + (1 - F) w_T)        E_R, E_T, E_R + E_T
    exact_metal  (F w_R, (1 - F) w_T, w_R)                         E_R, E_T and E(F = 1) (OpenPBR's metal table)
    eevee        ((1 - s) w_R, s w_R, (1 - s) w_T)                 Blender EEVEE's split sum with Schlick:
                 s = (1 - |x.h|)^5, x = v for eta >= 1 (ggx_btdf_gt_one), x = t for eta < 1 (ggx_bsdf_split_sum;
                 s = 1 under total internal reflection, where EEVEE's refract() returns 0)
with w_R = D G2(v, l) (v.h) / mu [n.l > 0] and w_T = D G2(v, t) (v.h) / mu [n.t < 0].
Precision: v.h, cos theta_t, n.t and the exact Fresnel term are float64 (``g64`` takes v.h from the panel rules'
float64 angles; ``g`` rounds it from float32 v and h), the rest float32: next to total internal reflection
eta^2 - 1 + (v.h)^2 cancels and float32's rounding of v.h reaches cos theta_t amplified by 1/eta^2
(docs/transmission.md).
"""

from __future__ import annotations

import numpy as np
import warp as wp

from ..edge import COS_EPS
from ..records import MASKING
from ..runtime.warp_runtime import kernel_factory
from ..terms import fresnel
from ..terms.dielectric import F_dielectric64, cos_transmitted, cos_transmitted64
from ..terms.distributions import NDFS
from ..terms.frame import reflect
from .specular import SpecularIntegrand

FRESNEL_MODES = {
    "exact": "(E_R, E_T, E_R + E_T) with the exact dielectric Fresnel (Walter et al. 2007, Eq. 22; TIR included)",
    "exact_metal": "(E_R, E_T, E with F = 1): OpenPBR's dielectric and metal tables from one integral",
    "eevee": "Blender EEVEE's Schlick split sum: (scale, bias, transmission_factor), s = (1 - |x.h|)^5",
}


@wp.struct
class Facet:
    """The eta-free part of the integrand at a facet h (integrand_for's ``facet64``): ``ok`` (n.v, v.h and n.h past
    COS_EPS), w = D(h) (v.h) / (n.v) and the reflection lobe's w_r = w G2(v, l) [n.l > 0]."""

    ok: wp.bool
    w: float
    w_r: float


@kernel_factory
def integrand_for(ndf_name: str, masking_name: str, mode: str):
    """``(g, g64, facet64, lobes64)``: ``g(v, h, alpha, eta) -> wp.vec3`` (module docstring; 0 for v.h, n.v <= COS_EPS
    or n.h <= 0) and ``g64(v, h, alpha, eta, v.h as float64)``, the same given v.h to float64 (the panel rules know
    it), in two parts: g64 = lobes64(facet64(v, h, alpha, v.h), v, h, alpha, eta, v.h), the first free of eta (texels
    that differ only in eta share it: lutbake.sampling.dielectric.make_adaptive_members)."""
    if mode not in FRESNEL_MODES:
        raise KeyError(f"unknown Fresnel mode {mode!r}; valid: {', '.join(FRESNEL_MODES)}")
    transmission = [r.name for r in MASKING if r.fields["transmission"]]
    if masking_name not in transmission:
        raise KeyError(f"masking {masking_name!r} is not defined for transmission; valid: {', '.join(transmission)}")
    D = NDFS[ndf_name].D
    G2 = NDFS[ndf_name].G2(masking_name)

    @wp.func
    def facet64(v: wp.vec3, h: wp.vec3, alpha: float, c: wp.float64):
        """The eta-free part (Facet) given v.h = c to float64."""
        fc = Facet()
        NoV = v[2]
        VoH = float(c)
        if NoV <= COS_EPS or VoH <= COS_EPS or h[2] <= 0.0:
            return fc
        fc.ok = True
        fc.w = D(h, alpha) * VoH / NoV
        NoL = reflect(v, h)[2]
        fc.w_r = fc.w * 0.0  # dynamic (a literal is a constant to Warp)
        if NoL > COS_EPS:
            fc.w_r = fc.w * G2(NoV, NoL, h[2], VoH, alpha)
        return fc

    @wp.func
    def lobes64(fc: Facet, v: wp.vec3, h: wp.vec3, alpha: float, eta: float, c: wp.float64):
        """The channels from the facet's part: the refraction (cos theta_t, n.t) and the Fresnel term from v.h = c in
        float64 (lutbake.terms.dielectric.cos_transmitted64: near total internal reflection float32's v.h is
        amplified by 1/eta^2), the rest in float32."""
        if not fc.ok:
            return wp.vec3()
        NoV = v[2]
        VoH = float(c)
        w = fc.w
        w_r = fc.w_r
        e = wp.float64(eta)
        ct = cos_transmitted64(e, c)  # -1 under total internal reflection
        w_t = w * 0.0
        if ct >= wp.float64(0.0):
            # t = (v.h / eta - cos theta_t) h - v / eta (lutbake.terms.dielectric.refract), n.t in float64
            NoT = float((wp.float64(v[2]) / e) - (c / e - ct) * wp.float64(h[2]))
            if NoT > COS_EPS:
                w_t = w * G2(NoV, NoT, h[2], VoH, alpha)
        if wp.static(mode == "eevee"):
            x = VoH
            if eta < 1.0:
                x = float(wp.max(ct, wp.float64(0.0)))  # t.h = -cos theta_t; 0 under TIR: s = 1
            s = fresnel.Fc_schlick(x)
            return wp.vec3((1.0 - s) * w_r, s * w_r, (1.0 - s) * w_t)
        F = float(F_dielectric64(e, c, ct))
        if wp.static(mode == "exact_metal"):
            return wp.vec3(F * w_r, (1.0 - F) * w_t, w_r)
        return wp.vec3(F * w_r, (1.0 - F) * w_t, F * w_r + (1.0 - F) * w_t)

    @wp.func
    def integrand64(v: wp.vec3, h: wp.vec3, alpha: float, eta: float, c: wp.float64):
        """The integrand given v.h = c to float64 (facet64, then lobes64)."""
        return lobes64(facet64(v, h, alpha, c), v, h, alpha, eta, c)

    @wp.func
    def integrand(v: wp.vec3, h: wp.vec3, alpha: float, eta: float):
        return integrand64(v, h, alpha, eta, wp.float64(wp.dot(v, h)))

    return integrand, integrand64, facet64, lobes64


@kernel_factory
def mirror_for(mode: str):
    """The exact alpha -> 0 limit (lutbake.edge): D -> delta about n, so h = n, v.h = mu, G2 -> 1, and each lobe
    keeps its Fresnel weight at mu: E_R = F(mu, eta), E_T = 1 - F(mu, eta) (0 under total internal reflection)."""

    @wp.func
    def mirror(v: wp.vec3, eta: float):
        mu = v[2]
        if mu <= COS_EPS:
            return wp.vec3()
        ct = cos_transmitted(eta, mu)
        w_t = wp.where(ct > COS_EPS, 1.0, 0.0)
        if wp.static(mode == "eevee"):
            x = mu
            if eta < 1.0:
                x = wp.max(ct, 0.0)  # the refracted cosine; 0 under TIR: s = 1
            s = fresnel.Fc_schlick(x)
            return wp.vec3(1.0 - s, s, (1.0 - s) * w_t)
        F = fresnel.F_dielectric(eta, mu)
        if wp.static(mode == "exact_metal"):
            return wp.vec3(F, (1.0 - F) * w_t, 1.0)
        return wp.vec3(F, (1.0 - F) * w_t, F + (1.0 - F) * w_t)

    return mirror


@kernel_factory
def dielectric_integrand(ndf_name: str, masking_name: str, mode: str, nch: int = 3) -> SpecularIntegrand:
    """The integrand record (lutbake.integrands.specular.SpecularIntegrand: g, vec, distribution, mirror) of a
    (terms, Fresnel mode) key; the kernels' per-texel ``param`` is the relative IOR eta."""
    g, g64, facet64, lobes64 = integrand_for(ndf_name, masking_name, mode)
    return SpecularIntegrand(
        ("dielectric", ndf_name, masking_name, mode),
        g,
        wp.vec3,
        wp.vec3d,
        3,
        nch,
        NDFS[ndf_name],
        mirror_for(mode),
        g64=g64,
        g64_parts=(facet64, lobes64),
    )


def integrate(key: tuple, nov, alpha, eta, samples: int | None = None, seed: int = 0, device: str = "cpu"):
    """Host helper (checks, tests, benchmarks): float64 (len, 3) integrals of the (ndf, masking, Fresnel mode)
    integrand by ``estimator`` at texels (nov, alpha, eta); alpha through the edge policy as in a table."""
    from ..sampling.dielectric_layout import estimator_of

    ndf_name, masking_name, mode, estimator = key
    integrand = dielectric_integrand(ndf_name, masking_name, mode)
    inputs = {
        "nov": np.asarray(nov, np.float32),
        "alpha": integrand.alpha_input(np.asarray(alpha, np.float32)),
        "param": np.asarray(eta, np.float32),
    }
    return estimator_of(estimator, samples, seed).evaluate(integrand, inputs, device)
