"""Panel rules shared by the microfacet-diffuse quadratures (lutbake.sampling.facets, lutbake.sampling.swapped).

- The facet polar angle is integrated in u = CDF(theta_m) of GGX's D(m)(n.m) (tan^2 theta_m = alpha^2 u / (1 - u)),
  in panels geometric in theta_m: they end where tan theta_m = alpha 4^k (k = 1 .. K, until tan theta_m >= 4; the
  last runs to 90 degrees), so the wide-angle tail gets as many nodes as the peak. The cut points
  u_k = r / (1 + r), r = 16^k, do not depend on alpha, only their number K (``n_tail_cuts``) does.
- A facet m sees a direction x on the azimuth arc |phi - phi_x| <= ``arc_half_width`` = acos(-cot theta_m cot theta_x).
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

PI64 = wp.constant(wp.float64(math.pi))
TWO_PI64 = wp.constant(wp.float64(2.0 * math.pi))
TAIL_RATIO = 4.0  # u panels end where tan(theta_m) = alpha * 4^k, k = 1 .. K (geometric in theta_m)
TAIL_RATIO64 = wp.constant(wp.float64(TAIL_RATIO))
TAIL_TAN = 4.0  # ... until tan(theta_m) >= 4 (76 degrees); the last panel runs to theta_m = 90 degrees
MAX_TAIL_CUTS = 16
TAIL_TAN64 = wp.constant(wp.float64(TAIL_TAN))


@wp.func
def n_tail_cuts(alpha: wp.float64):
    """K: the geometric u panels of ``alpha`` (module docstring), clamped to [1, MAX_TAIL_CUTS]."""
    k = int(wp.ceil(wp.log(TAIL_TAN64 / alpha) / wp.log(TAIL_RATIO64)))
    return wp.clamp(k, 1, MAX_TAIL_CUTS)


def n_tail_cuts_np(alpha) -> np.ndarray:
    """``n_tail_cuts`` on the host."""
    a = np.asarray(alpha, np.float64)
    return np.clip(np.ceil(np.log(TAIL_TAN / a) / np.log(TAIL_RATIO)), 1, MAX_TAIL_CUTS).astype(int)


@wp.func
def arc_half_width(cos_m: wp.float64, sin_m: wp.float64, cos_x: wp.float64, sin_x: wp.float64):
    """Half-width in phi of the arc where m.x >= 0, m at polar angle theta_m, x at theta_x:
    acos(-cot(theta_m) cot(theta_x)), clamped to [0, pi] (pi: the whole circle)."""
    den = sin_m * sin_x
    num = -cos_m * cos_x
    if den <= wp.abs(num):
        if num <= wp.float64(0.0):
            return PI64
        return wp.float64(0.0)
    return wp.acos(wp.clamp(num / den, wp.float64(-1.0), wp.float64(1.0)))


@wp.func
def wrap_2pi(x: wp.float64):
    return x - TWO_PI64 * wp.floor(x / TWO_PI64)


@wp.func
def om_visible_ggx(cos_x: wp.float64, alpha: wp.float64):
    """1 - u_x, u_x = CDF(theta_m) at theta_m = pi/2 - theta_x = (n.x)^2 / (alpha^2 (1 - (n.x)^2) + (n.x)^2) (beyond it
    the facet no longer sees x for every phi), without cancellation: alpha^2 (1 - (n.x)^2) / (alpha^2 (1 - (n.x)^2)
    + (n.x)^2)."""
    c2 = cos_x * cos_x
    t = alpha * alpha * (wp.float64(1.0) - c2)
    return t / (t + c2)


@wp.func
def sort4(a: wp.float64, b: wp.float64, c: wp.float64, d: wp.float64):
    """The four values in increasing order (the five compare-exchanges of a sorting network)."""
    lo1 = wp.min(a, b)
    hi1 = wp.max(a, b)
    lo2 = wp.min(c, d)
    hi2 = wp.max(c, d)
    mid1 = wp.max(lo1, lo2)
    mid2 = wp.min(hi1, hi2)
    return wp.vec4d(wp.min(lo1, lo2), wp.min(mid1, mid2), wp.max(mid1, mid2), wp.max(hi1, hi2))


@wp.func
def interval(q: int, x: wp.vec4d, end: wp.float64):
    """[x_q, x_(q+1)] of the increasing breakpoints x_0 .. x_3, end (q in 0 .. 3): the q-th panel."""
    b = end
    if q < 3:
        b = x[q + 1]
    return wp.vec2d(x[q], b)


@wp.func
def facet_cos_sin(lo: wp.float64, du: wp.float64, om_hi: wp.float64, s: wp.float64, alpha: wp.float64):
    """(cos, sin) of the facet polar angle at the smoothstep node s of the u panel [lo, lo + du] (its upper end's
    1 - u is om_hi): u = lo + du s^2 (3 - 2 s), 1 - u without cancellation, tan^2 theta_m = alpha^2 u / (1 - u)."""
    one = wp.float64(1.0)
    u = lo + du * s * s * (wp.float64(3.0) - wp.float64(2.0) * s)
    omu = om_hi + du * (one - s) * (one - s) * (one + wp.float64(2.0) * s)
    tan2 = alpha * alpha * u / omu
    cm = one / wp.sqrt(one + tan2)
    return wp.vec2d(cm, wp.sqrt(tan2) * cm)
