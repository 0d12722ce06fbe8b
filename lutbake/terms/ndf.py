"""Normal distribution functions D(m) and their sampling maps.

Every D is normalised so that the projected microfacet area is one, ∫ D(m) (n.m) dω_m = 1
(Walter et al. 2007, Eq. 4); ``lutbake validate`` measures it. ``tan2_from_u_*`` / ``u_from_tan2_*``
are the inverse and forward CDFs of the polar angle under the density D(m)(n.m) (float64: they feed
quadrature breakpoints where 1 - u underflows float32 for small alpha).
"""

from typing import Any

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
def sample_vndf_ggx_aniso(v: wp.vec3, alpha_x: float, alpha_y: float, u1: float, u2: float):
    """Visible-normal sample of anisotropic GGX (Heitz 2018, JCGT 7(4); spherical caps, Dupuy & Benyoub 2023):
    stretch v by (ax, ay, 1), sample the visible hemisphere, unstretch. pdf = G1(v) max(0, v.h) D(h) / (n.v)."""
    vh = wp.normalize(wp.vec3(alpha_x * v[0], alpha_y * v[1], v[2]))
    phi = 2.0 * wp.pi * u1
    z = (1.0 - u2) * (1.0 + vh[2]) - vh[2]
    s = wp.sqrt(wp.clamp(1.0 - z * z, 0.0, 1.0))
    nh = wp.vec3(s * wp.cos(phi), s * wp.sin(phi), z) + vh
    return wp.normalize(wp.vec3(alpha_x * nh[0], alpha_y * nh[1], wp.max(nh[2], 0.0)))


@wp.func
def sample_vndf_ggx(v: wp.vec3, alpha: float, u1: float, u2: float):
    """Visible-normal sample of isotropic GGX by spherical caps (Dupuy & Benyoub 2023, Listing 3;
    equivalent to Heitz 2018): the anisotropic sampler at alpha_x = alpha_y = alpha.
    Density: pdf(h) = G1(v) max(0, v.h) D(h) / (n.v)."""
    return sample_vndf_ggx_aniso(v, alpha, alpha, u1, u2)


# --- normalized Blinn-Phong ---------------------------------------------------------------------------
# Shininess s <-> alpha: alpha = sqrt(2 / (s + 2)), s = 2 / alpha^2 - 2 (Walter et al. 2007, Sec. 5.2; the
# lecture's "roughness = sqrt(2 / (2 + shininess))"): with it Blinn-Phong and Beckmann of the same alpha nearly
# coincide, and (s + 2) / (2 pi) = 1 / (pi alpha^2).


@wp.func
def log1p64(x: wp.float64):
    if wp.abs(x) < wp.float64(1.0e-4):
        return x * (wp.float64(1.0) - x * (wp.float64(0.5) - x / wp.float64(3.0)))
    return wp.log(wp.float64(1.0) + x)


@wp.func
def expm1_64(y: wp.float64):
    if wp.abs(y) < wp.float64(1.0e-4):
        return y * (wp.float64(1.0) + y * (wp.float64(0.5) + y / wp.float64(6.0)))
    return wp.exp(y) - wp.float64(1.0)


@wp.func
def log_cos64(h: wp.vec3):
    """log(n.h) for a unit h in float64, as 0.5 log(1 - x) with x = h.x^2 + h.y^2: float32 n.h rounds to 1 within
    ~3e-4 rad of the pole, where (n.h)^s with s ~ 1e8 still varies, and log(n.h) from a rounded n.h has a relative
    error ~6e-8 / |log(n.h)| that the exponent s amplifies."""
    x = wp.float64(h[0]) * wp.float64(h[0]) + wp.float64(h[1]) * wp.float64(h[1])
    if x > wp.float64(0.5):  # n.h < 0.71: log(n.h) directly (|log| > 0.34, no cancellation; finite at n.h -> 0+)
        return wp.log(wp.max(wp.float64(h[2]), wp.float64(1.0e-30)))
    return wp.float64(0.5) * log1p64(-x)


@wp.func
def log_cos(h: wp.vec3):
    """log_cos64 rounded to float32."""
    return float(log_cos64(h))


@wp.func
def shininess_from_alpha(alpha: float):
    """Blinn-Phong exponent s = 2 / alpha^2 - 2 (>= 0 for alpha <= 1; clamped to 0 above)."""
    return wp.max(2.0 / (alpha * alpha) - 2.0, 0.0)


@wp.func
def D_blinn_phong(h: wp.vec3, alpha: float):
    """Normalized Blinn-Phong NDF (Blinn 1977; normalisation as in Walter et al. 2007, Eq. 30):
    D = (s + 2) / (2 pi) (n.h)^s, s = 2 / alpha^2 - 2, so (s + 2) / (2 pi) = 1 / (pi alpha^2).
    Projected area ∫ D (n.h) dω = 1. Returns 0 for n.h <= 0. Domain alpha in (0, 1] (s >= 0)."""
    if h[2] <= 0.0:
        return 0.0
    a = wp.min(alpha, 1.0)
    s = shininess_from_alpha(a)
    return INV_PI / (a * a) * wp.exp(s * log_cos(h))


@wp.func
def tan2_from_u_blinn_phong(u: wp.float64, alpha: wp.float64):
    """Inverse CDF of Blinn-Phong's D(m)(n.m) in the polar angle: u = 1 - cos^(s+2) theta, i.e.
    cos theta = (1 - u)^(1/(s+2)) (the lecture's / Ashikhmin-Shirley's cos = xi^(1/(s+2)) with xi = 1 - u),
    written as tan^2 = expm1(-alpha^2 log(1 - u)) since 2 / (s + 2) = alpha^2."""
    return expm1_64(-alpha * alpha * wp.log(wp.float64(1.0) - u))


@wp.func
def u_from_tan2_blinn_phong(tan2: wp.float64, alpha: wp.float64):
    """CDF of Blinn-Phong's D(m)(n.m): u = 1 - (1 + tan^2)^(-1/alpha^2)."""
    return -expm1_64(-log1p64(tan2) / (alpha * alpha))


# --- anisotropic GGX (Heitz 2014, JCGT 3(2), Eq. 85; tangent = +x, bitangent = +y) -----------------------


@wp.func
def D_ggx_aniso(h: wp.vec3, alpha_x: float, alpha_y: float):
    """Anisotropic GGX: D = 1 / (pi ax ay ((h.x/ax)^2 + (h.y/ay)^2 + (h.z)^2)^2); 0 for n.h <= 0.
    ax = ay = alpha gives D_ggx."""
    if h[2] <= 0.0:
        return 0.0
    x = h[0] / alpha_x
    y = h[1] / alpha_y
    d = x * x + y * y + h[2] * h[2]
    return INV_PI / (alpha_x * alpha_y * d * d)


# --- Ashikhmin-Shirley 2000 ("An anisotropic Phong BRDF model", JGT 5(2)) -------------------------------


@wp.func
def D_ashikhmin_shirley(h: wp.vec3, nu: float, nv: float):
    """The half-vector density of Ashikhmin & Shirley 2000 (their p_h, Sec. 3):
    p_h = sqrt((nu + 1)(nv + 1)) / (2 pi) (n.h)^((nu h.x^2 + nv h.y^2) / (1 - (n.h)^2)),
    nu along the tangent (+x), nv along the bitangent (+y). Normalised as a solid-angle density,
    ∫ p_h dω = 1 (NOT the projected area: isotropic nu = nv = s gives (s+1)/(2 pi) cos^s, vs (s+2)/(2 pi) for
    Blinn-Phong). The exponent is computed as (nu h.x^2 + nv h.y^2) * log(n.h) / x, x = h.x^2 + h.y^2, with a
    series for small x (no 0/0 at the pole)."""
    if h[2] <= 0.0:
        return 0.0
    x = h[0] * h[0] + h[1] * h[1]
    r = 0.0  # log(n.h) / x
    if x < 0.01:
        r = -0.5 * (1.0 + x * (0.5 + x * (1.0 / 3.0 + x * (0.25 + x * (0.2 + x / 6.0)))))
    else:
        r = wp.log(h[2]) / x
    return wp.sqrt((nu + 1.0) * (nv + 1.0)) * 0.5 * INV_PI * wp.exp((nu * h[0] * h[0] + nv * h[1] * h[1]) * r)


# --- exp(-x) I0(x), the scaled modified Bessel function of order 0 --------------------------------------------------
# Cephes' i0e (S. L. Moshier, Cephes Math Library, i0.c; the same tables as numpy.i0): Chebyshev series of exp(-x) I0(x)
# in t = x / 2 - 2 on [0, 8] and of exp(-x) sqrt(x) I0(x) in t = 32 / x - 2 beyond, summed by Clenshaw's recurrence
# (Cephes chbevl); relative error ~1e-16 (tests/test_terms.py: against scipy.special.i0e).
I0E_A = (
    -4.4153416464793395e-18,
    3.3307945188222384e-17,
    -2.431279846547955e-16,
    1.715391285555133e-15,
    -1.1685332877993451e-14,
    7.676185498604936e-14,
    -4.856446783111929e-13,
    2.95505266312964e-12,
    -1.726826291441556e-11,
    9.675809035373237e-11,
    -5.189795601635263e-10,
    2.6598237246823866e-09,
    -1.300025009986248e-08,
    6.046995022541919e-08,
    -2.670793853940612e-07,
    1.1173875391201037e-06,
    -4.4167383584587505e-06,
    1.6448448070728896e-05,
    -5.754195010082104e-05,
    0.00018850288509584165,
    -0.0005763755745385824,
    0.0016394756169413357,
    -0.004324309995050576,
    0.010546460394594998,
    -0.02373741480589947,
    0.04930528423967071,
    -0.09490109704804764,
    0.17162090152220877,
    -0.3046826723431984,
    0.6767952744094761,
)
I0E_B = (
    -7.233180487874754e-18,
    -4.830504485944182e-18,
    4.46562142029676e-17,
    3.461222867697461e-17,
    -2.8276239805165836e-16,
    -3.425485619677219e-16,
    1.7725601330565263e-15,
    3.8116806693526224e-15,
    -9.554846698828307e-15,
    -4.150569347287222e-14,
    1.54008621752141e-14,
    3.8527783827421426e-13,
    7.180124451383666e-13,
    -1.7941785315068062e-12,
    -1.3215811840447713e-11,
    -3.1499165279632416e-11,
    1.1889147107846439e-11,
    4.94060238822497e-10,
    3.3962320257083865e-09,
    2.266668990498178e-08,
    2.0489185894690638e-07,
    2.8913705208347567e-06,
    6.889758346916825e-05,
    0.0033691164782556943,
    0.8044904110141088,
)
_I0E_A = wp.constant(wp.types.vector(length=len(I0E_A), dtype=wp.float64)(*I0E_A))
_I0E_B = wp.constant(wp.types.vector(length=len(I0E_B), dtype=wp.float64)(*I0E_B))


@wp.func
def chebyshev_sum(t: wp.float64, c: Any):
    """Cephes chbevl: sum_k c_k T_k(t / 2) - c_0 / 2 (Clenshaw's recurrence from the last coefficient)."""
    b0 = c[0]
    b1 = wp.float64(0.0)
    b2 = wp.float64(0.0)
    for k in range(1, c.length):
        b2 = b1
        b1 = b0
        b0 = t * b1 - b2 + c[k]
    return wp.float64(0.5) * (b0 - b2)


@wp.func
def bessel_i0e(x: wp.float64):
    """exp(-|x|) I0(x) (Cephes i0e; I0 is even)."""
    x = wp.abs(x)
    if x <= wp.float64(8.0):
        return chebyshev_sum(x * wp.float64(0.5) - wp.float64(2.0), _I0E_A)
    return chebyshev_sum(wp.float64(32.0) / x - wp.float64(2.0), _I0E_B) / wp.sqrt(x)


@wp.func
def as_exponent(a: float):
    """Ashikhmin-Shirley exponent of an axis alpha by the Blinn-Phong mapping: max(2 / a^2 - 2, 0)."""
    return wp.max(2.0 / (a * a) - 2.0, 0.0)


@wp.func
def sample_ashikhmin_shirley(nu: float, nv: float, u1: float, u2: float):
    """h from p_h (Ashikhmin & Shirley 2000, Eq. 9): in the first quadrant
    phi = atan(sqrt((nu + 1)/(nv + 1)) tan(pi xi / 2)), cos theta = (1 - u2)^(1 / (nu cos^2 phi + nv sin^2 phi + 1));
    u1 picks the quadrant (4 u1 = q + xi) and the lobe's symmetry in x and y mirrors phi into it."""
    t = 4.0 * u1
    q = wp.min(wp.floor(t), 3.0)
    xi = t - q
    phi = wp.atan(wp.sqrt((nu + 1.0) / (nv + 1.0)) * wp.tan(0.5 * wp.pi * xi))
    if q == 1.0:
        phi = wp.pi - phi
    elif q == 2.0:
        phi = wp.pi + phi
    elif q == 3.0:
        phi = 2.0 * wp.pi - phi
    cp = wp.cos(phi)
    sp = wp.sin(phi)
    e = nu * cp * cp + nv * sp * sp + 1.0
    # cos = exp(L), L = log(1 - u2) / e; sin^2 = 1 - exp(2 L) = -expm1(2 L), by its series for small |2 L|
    # (with e ~ 1e8, float32 cos rounds to 1 and 1 - cos^2 would lose the whole lobe)
    L2 = 2.0 * wp.log(wp.max(1.0 - u2, 1.0e-30)) / e
    s2 = 0.0
    if L2 > -1.0e-3:
        s2 = -L2 * (1.0 + L2 * (0.5 + L2 / 6.0))
    else:
        s2 = 1.0 - wp.exp(L2)
    c = wp.exp(0.5 * L2)
    s = wp.sqrt(wp.clamp(s2, 0.0, 1.0))
    return wp.vec3(s * cp, s * sp, c)


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


@wp.func
def D_charlie_sin2(sin2: wp.float64, alpha: float):
    """D_charlie from sin^2(theta_h) in float64: (2 + 1/alpha) sin2^(1/(2 alpha)) / (2 pi), the power taken in float64.
    The power multiplies sin2's relative rounding by 1 / (2 alpha): from a float32 h (D_charlie) 6e-8 becomes 3e-4
    at alpha = 1e-4, from the quadrature node's float64 angles ~1e-12 (lutbake.sampling.facet_rules.facet_rules_for).
    The caller checks n.h > 0; sin2 in [0, 1]."""
    inv = wp.float64(1.0) / wp.float64(alpha)
    half = wp.float64(0.5)
    return float((wp.float64(2.0) + inv) * wp.pow(sin2, half * inv) * wp.float64(INV_PI) * half)
