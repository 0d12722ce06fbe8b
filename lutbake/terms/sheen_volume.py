"""The volumetric sheen of Zeltner, Burley & Chiang 2022 ("Practical Multiple-Scattering Sheen Using Linearly
Transformed Cosines", SIGGRAPH talk): a unit-thick, unit-density, non-absorbing slab of SGGX fiber microflakes
(Heitz, Dupuy, Crassin & Dachsbacher 2015, "The SGGX Microflake Distribution") aligned with the normal, fiber cross
section sigma = alpha^2. Its cheap analytic form (tizian/ltc-sheen fitting/src/bsdfs/sheen_approx.h, the "approx"
table's lobe): exact single scattering plus their empirical multiple-scattering term.

v (the view, tizian's wi) and l (tizian's wo) in the shading frame (n = +z, the fiber axis); every f below is
returned times n.l, as the LTC lobes (lutbake.ltc.lobes) take it.
"""

import warp as wp

INV_PI = wp.constant(0.31830988618379067)
# sheen_approx.h mb(): the multiple-scattering fit's m and b at sigma = 0, 0.1, ..., 1, each padded by one value at
# either end extrapolated so that the Catmull-Rom spline interpolates the ends
MS_M = (2.0 * 20.0 - 10.2, 20.0, 10.2, 6.14, 4.30, 3.30, 2.55, 2.02, 1.63, 1.33, 1.1, 0.95, 2.0 * 0.95 - 1.1)
MS_B = (2.0 * 3.7 - 2.23, 3.7, 2.23, 1.06, 0.293, -0.212, -0.641, -0.952, -1.2, -1.4, -1.55, -1.65, 2.0 * -1.65 + 1.55)
_MS_M = wp.constant(wp.types.vector(length=len(MS_M), dtype=float)(*MS_M))
_MS_B = wp.constant(wp.types.vector(length=len(MS_B), dtype=float)(*MS_B))


@wp.func
def sigma_sggx_fiber(w: wp.vec3, sigma: float):
    """Projected area of the fiber microflakes along w (Heitz et al. 2015, Eq. 10: sqrt(w^T S w)) with
    S = diag(1, 1, sigma^2) (sggx.h Ellipsoid::from_fiber of the fiber direction z)."""
    return wp.sqrt(w[0] * w[0] + w[1] * w[1] + sigma * sigma * w[2] * w[2])


@wp.func
def D_sggx_fiber(m: wp.vec3, sigma: float):
    """SGGX microflake distribution of S = diag(1, 1, sigma^2) (Heitz et al. 2015, Eq. 9:
    1 / (pi sqrt|S| (m^T S^-1 m)^2)) = sigma^3 / (pi (sigma^2 (m.x^2 + m.y^2) + m.z^2)^2)."""
    s2 = sigma * sigma
    d = s2 * (m[0] * m[0] + m[1] * m[1]) + m[2] * m[2]
    return s2 * sigma * INV_PI / (d * d)


@wp.func
def phase_sggx_specular(v: wp.vec3, l: wp.vec3, sigma: float):
    """The specular microflake phase function D(h) / (4 sigma(v)), h = normalize(v + l) (Heitz et al. 2015,
    Eq. 14; sggx.h eval_phase_specular); 0 for v + l = 0."""
    s = v + l
    n = wp.length(s)
    if n <= 0.0:
        return 0.0
    return 0.25 * D_sggx_fiber(s / n, sigma) / sigma_sggx_fiber(v, sigma)


@wp.func
def f_cos_sheen_single(v: wp.vec3, l: wp.vec3, sigma: float):
    """Single scattering of the slab (sheen_approx.h, unit density, thickness and albedo), times n.l:
    p(v, l) sigma(v) (1 - exp(-(L_v + L_l))) / ((n.v) (L_v + L_l)), L_w = sigma(w) / (n.w) the optical depth
    along w (not finite where the depth is: f_cos_sheen_approx)."""
    sv = sigma_sggx_fiber(v, sigma)
    depth = sv / v[2] + sigma_sggx_fiber(l, sigma) / l[2]
    return phase_sggx_specular(v, l, sigma) * sv * (1.0 - wp.exp(-depth)) / (v[2] * depth)


@wp.func
def sheen_ms_mb(sigma: float):
    """(m, b) of the multiple-scattering fit at sigma: sheen_approx.h mb(), the Catmull-Rom spline through the
    values at sigma = 0, 0.1, ..., 1."""
    r = sigma * 10.0
    i = int(wp.min(wp.floor(r), 9.0))
    y = r - float(i)
    y2 = y * y
    y3 = y2 * y
    w0 = -y + 2.0 * y2 - y3
    w1 = 2.0 - 5.0 * y2 + 3.0 * y3
    w2 = y + 4.0 * y2 - 3.0 * y3
    w3 = -y2 + y3
    m = 0.5 * (w0 * _MS_M[i] + w1 * _MS_M[i + 1] + w2 * _MS_M[i + 2] + w3 * _MS_M[i + 3])
    b = 0.5 * (w0 * _MS_B[i] + w1 * _MS_B[i + 1] + w2 * _MS_B[i + 2] + w3 * _MS_B[i + 3])
    return wp.vec2(m, b)


@wp.func
def F_t_sheen(sigma: float, c: float):
    """The multiple-scattering term's angular factor (sheen_approx.h Ft): b + (1 - b)(1 - (1 - c)^12),
    b = max(0.55, 0.44 + 0.42 sigma)."""
    b = wp.max(0.55, 0.44 + 0.42 * sigma)
    return b + (1.0 - b) * (1.0 - wp.pow(1.0 - c, 12.0))


@wp.func
def f_cos_sheen_multiple(v: wp.vec3, l: wp.vec3, sigma: float):
    """Zeltner et al.'s empirical multiple scattering (sheen_approx.h), times n.l:
    exp(b - m sqrt((n.l)^2 + (n.v)^2)) Ft(n.l) Ft(n.v) (n.l), (m, b) = sheen_ms_mb(sigma)."""
    mb = sheen_ms_mb(sigma)
    ms = wp.exp(mb[1] - mb[0] * wp.sqrt(l[2] * l[2] + v[2] * v[2]))
    return ms * F_t_sheen(sigma, l[2]) * F_t_sheen(sigma, v[2]) * l[2]


@wp.func
def f_cos_sheen_approx(v: wp.vec3, l: wp.vec3, alpha: float):
    """Zeltner et al. 2022's analytic volumetric sheen (sheen_approx.h ApproxSheenBrdf::eval_impl) times n.l:
    single + multiple scattering of the fiber slab with sigma = alpha^2; 0 for n.v <= 0 or n.l < 0, and 0 (both
    terms, as the code) where the single scattering is not finite."""
    if v[2] <= 0.0 or l[2] < 0.0:
        return 0.0
    sigma = alpha * alpha
    ss = f_cos_sheen_single(v, l, sigma)
    if not wp.isfinite(ss):
        return 0.0
    return ss + f_cos_sheen_multiple(v, l, sigma)
