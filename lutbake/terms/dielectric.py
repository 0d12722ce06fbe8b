"""Terms of the rough dielectric BSDF (Walter, Marschner, Li & Torrance 2007, "Microfacet models for refraction
through rough surfaces", EGSR) that the reflection-only terms do not cover: the refracted direction, the
generalised half vector of a transmission pair, and the BSDF values f_r and f_t themselves.

Notation (docs/transmission.md): n = +z; the incident side is the side of i (the view v of a table texel, or
the light l of a reciprocity pair); ``eta`` = eta_o / eta_i is the RELATIVE index of refraction across the
interface (eta > 1: seen from the less dense side; eta < 1: seen from inside, total internal reflection past the
critical angle, cos theta_c = sqrt(1 - eta^2)). The Fresnel term is lutbake.terms.fresnel.F_dielectric, which is
Walter et al. 2007, Eq. 22, valid for any relative eta > 0 (it returns 1 under total internal reflection).
Edge policy (lutbake.edge): every term returns 0 (or the zero vector) for back-facing or grazing inputs
(cosines <= COS_EPS) and under total internal reflection; nothing divides by an unchecked cosine.
"""

import warp as wp

from ..edge import COS_EPS


@wp.func
def cos_transmitted(eta: float, VoH: float):
    """cos theta_t = sqrt(1 - (1 - (v.h)^2) / eta^2) of the ray refracted through the facet h (Snell's law,
    Walter et al. 2007, Eq. 40); -1 flags total internal reflection (eta < 1 and v.h below cos theta_c).
    Evaluated as sqrt((eta^2 - 1 + (v.h)^2) / eta^2) (the g of F_dielectric over eta): the printed form cancels in
    float32 at small v.h (1 - 1e-8 rounds to 1), which took eta = 1 for total internal reflection at grazing v.h."""
    s = (eta * eta - 1.0 + VoH * VoH) / (eta * eta)
    if s <= 0.0:
        return -1.0
    return wp.sqrt(s)


@wp.func
def cos_transmitted64(eta: wp.float64, VoH: wp.float64):
    """cos_transmitted in float64, for a v.h known to float64: near total internal reflection eta^2 - 1 + (v.h)^2
    cancels, and float32's rounding of v.h (~6e-8) reaches cos theta_t amplified by 1/eta^2 (63 at eta = 0.126)."""
    s = (eta * eta - wp.float64(1.0) + VoH * VoH) / (eta * eta)
    if s <= wp.float64(0.0):
        return wp.float64(-1.0)
    return wp.sqrt(s)


@wp.func
def F_dielectric64(eta: wp.float64, c: wp.float64, ct: wp.float64):
    """F_dielectric (Walter et al. 2007, Eq. 22) in float64 from v.h = c and cos theta_t = ct (cos_transmitted64;
    g = eta ct): 1 under total internal reflection (ct < 0)."""
    if ct < wp.float64(0.0):
        return wp.float64(1.0)
    g = eta * ct
    a = (g - c) / (g + c)
    b = (c * (g + c) - wp.float64(1.0)) / (c * (g - c) + wp.float64(1.0))
    return wp.float64(0.5) * a * a * (wp.float64(1.0) + b * b)


@wp.func
def refract(v: wp.vec3, h: wp.vec3, eta: float):
    """The direction t refracted from v through the facet h (Walter et al. 2007, Eq. 40, with v pointing away from
    the surface on the incident side, v.h > 0):  t = (v.h / eta - cos theta_t) h - v / eta,  so t.h = -cos theta_t.
    The zero vector under total internal reflection or for v.h <= COS_EPS."""
    VoH = wp.dot(v, h)
    if VoH <= COS_EPS:
        return wp.vec3()
    ct = cos_transmitted(eta, VoH)
    if ct < 0.0:
        return wp.vec3()
    return (VoH / eta - ct) * h - v / eta


@wp.func
def half_vector_transmission(i: wp.vec3, o: wp.vec3, eta: float):
    """Generalised half vector of a transmission pair (Walter et al. 2007, Eq. 16):
    h_t = -(eta_i i + eta_o o) / |eta_i i + eta_o o|, eta_i = 1, eta_o = eta, oriented to n.h >= 0.
    The zero vector when i + eta o vanishes (eta = 1 and o = -i)."""
    hv = -(i + eta * o)
    d = wp.length(hv)
    if d <= 0.0:
        return wp.vec3()
    hv = hv / d
    if hv[2] < 0.0:
        hv = -hv
    return hv


@wp.func
def f_dielectric_reflection(D: float, G2: float, F: float, NoI: float, NoO: float):
    """BRDF part of the rough dielectric BSDF (Walter et al. 2007, Eq. 20):
    f_r = F(i.h_r) D(h_r) G2 / (4 |n.i| |n.o|), h_r = normalize(i + o). 0 for a grazing i or o."""
    if NoI <= COS_EPS or NoO <= COS_EPS:
        return 0.0
    return F * D * G2 / (4.0 * NoI * NoO)


@wp.func
def f_dielectric_transmission(
    D: float, G2: float, F: float, NoI: float, NoO: float, IoH: float, OoH: float, eta: float
):
    """BTDF part of the rough dielectric BSDF (Walter et al. 2007, Eq. 21), eta_i = 1, eta_o = eta:
    f_t = |i.h||o.h| eta_o^2 (1 - F(i.h)) D(h) G2 / (|n.i||n.o| (eta_i i.h + eta_o o.h)^2), h = h_t.
    Arguments are absolute cosines except IoH, OoH (signed: a transmission pair has i.h > 0 > o.h).
    0 for grazing directions, for i.h and o.h of the same sign, or when the denominator vanishes."""
    if NoI <= COS_EPS or NoO <= COS_EPS or IoH * OoH >= 0.0:
        return 0.0
    den = IoH + eta * OoH
    if den * den <= 0.0:
        return 0.0
    return wp.abs(IoH * OoH) * eta * eta * (1.0 - F) * D * G2 / (NoI * NoO * den * den)
