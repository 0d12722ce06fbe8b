"""Normal distribution functions D(m) and their sampling maps.

Every D is normalised so that the projected microfacet area is one, ∫ D(m) (n.m) dω_m = 1
(Walter et al. 2007, Eq. 4); ``lutbake validate`` measures it. ``tan2_from_u_*`` / ``u_from_tan2_*``
are the inverse and forward CDFs of the polar angle under the density D(m)(n.m) (float64: they feed
quadrature breakpoints where 1 - u underflows float32 for small alpha).
"""
import warp as wp

from ..edge import COS_EPS

INV_PI = wp.constant(0.31830988618379067)


@wp.func
def D_ggx(h: wp.vec3, alpha: float):
    """GGX / Trowbridge-Reitz (Walter et al. 2007, Eq. 33), h in the shading frame (n = +z):
    D = alpha^2 / (pi ((n.h)^2 alpha^2 + (1 - (n.h)^2))^2).
    1 - (n.h)^2 is taken as h.x^2 + h.y^2, exact near the pole where float32 n.h rounds to 1 (as
    Filament's D_GGX does with |n x h|^2); without it alpha < 1e-3 gives 0/0.
    Domain: alpha > 0 (see edge.ALPHA_MIN). Returns 0 for n.h <= 0 (back-facing normal)."""
    NoH = h[2]
    if NoH <= 0.0:
        return 0.0
    a2 = alpha * alpha
    d = NoH * NoH * a2 + (h[0] * h[0] + h[1] * h[1])
    return a2 * INV_PI / (d * d)


@wp.func
def D_beckmann(h: wp.vec3, alpha: float):
    """Beckmann (Walter et al. 2007, Eq. 25), h in the shading frame (n = +z):
    D = exp(-tan^2(theta_h) / alpha^2) / (pi alpha^2 (n.h)^4), with the 1/pi the lecture omits.
    tan^2 = (h.x^2 + h.y^2) / (n.h)^2 (exact near the pole, see D_ggx).
    Returns 0 for n.h <= COS_EPS (the limit: exp(-inf) wins over 1/cos^4)."""
    NoH = h[2]
    if NoH <= COS_EPS:
        return 0.0
    c2 = NoH * NoH
    tan2 = (h[0] * h[0] + h[1] * h[1]) / c2
    return wp.exp(-tan2 / (alpha * alpha)) * INV_PI / (alpha * alpha * c2 * c2)


@wp.func
def tan2_from_u_ggx(u: wp.float64, alpha: wp.float64):
    """Inverse CDF of GGX's D(m)(n.m) in the polar angle: tan^2 theta = alpha^2 u / (1 - u)."""
    return alpha * alpha * u / (wp.float64(1.0) - u)


@wp.func
def u_from_tan2_ggx(tan2: wp.float64, alpha: wp.float64):
    """CDF of GGX's D(m)(n.m): u = tan^2 theta / (alpha^2 + tan^2 theta)."""
    return tan2 / (alpha * alpha + tan2)


@wp.func
def tan2_from_u_beckmann(u: wp.float64, alpha: wp.float64):
    """Inverse CDF of Beckmann's D(m)(n.m): tan^2 theta = -alpha^2 log(1 - u)."""
    return -alpha * alpha * wp.log(wp.float64(1.0) - u)


@wp.func
def u_from_tan2_beckmann(tan2: wp.float64, alpha: wp.float64):
    """CDF of Beckmann's D(m)(n.m): u = 1 - exp(-tan^2 theta / alpha^2)."""
    return wp.float64(1.0) - wp.exp(-tan2 / (alpha * alpha))


@wp.func
def sample_vndf_ggx(v: wp.vec3, alpha: float, u1: float, u2: float):
    """Visible-normal sample of isotropic GGX by spherical caps (Dupuy & Benyoub 2023, Listing 3;
    equivalent to Heitz 2018). Density: pdf(h) = G1(v) max(0, v.h) D(h) / (n.v)."""
    vh = wp.normalize(wp.vec3(alpha * v[0], alpha * v[1], v[2]))
    phi = 2.0 * wp.pi * u1
    z = (1.0 - u2) * (1.0 + vh[2]) - vh[2]
    s = wp.sqrt(wp.clamp(1.0 - z * z, 0.0, 1.0))
    nh = wp.vec3(s * wp.cos(phi), s * wp.sin(phi), z) + vh
    return wp.normalize(wp.vec3(alpha * nh[0], alpha * nh[1], wp.max(nh[2], 0.0)))


@wp.func
def D_charlie(h: wp.vec3, alpha: float):
    """Charlie sheen NDF (Estevez & Kulla 2017, "Production Friendly Microfacet Sheen BRDF", Eq. 2):
    D = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi), sin^2 = h.x^2 + h.y^2 (alpha = r^2, as Filament's
    DistributionCharlie). Peaks at grazing microfacets; 0 at the pole and for n.h <= 0."""
    if h[2] <= 0.0:
        return 0.0
    inv = 1.0 / alpha
    sin2 = h[0] * h[0] + h[1] * h[1]
    return (2.0 + inv) * wp.pow(sin2, 0.5 * inv) * INV_PI * 0.5
