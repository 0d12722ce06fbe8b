"""Kernel factories: integrate a per-texel hemisphere integral with a chosen estimator.

The integral, for a texel with view cosine n.v and NDF alpha, is written over the microfacet
normal h (dω_l = 4 (v.h) dω_h, Walter et al. 2007, Eq. 14):

    I = ∫ f(l, v) (n.l) dω_l = ∫ g(h) dω_h,        g(h) = f(l(h), v) (n.l) 4 (v.h),   l = reflect(v, h)

``integrand(v, h, alpha, param) -> vec`` returns g(h) for every channel (0 where n.l <= 0); ``param`` is a
per-texel scalar the integrand may use (f0 for specular_3d; ignored by the others). Sampling h with
the NDF's density p(h) = D(h)(n.h) gives I = E[g / p]; for a microfacet BRDF D cancels and the
per-sample weight is G2 F (v.h) / ((n.v)(n.h)).

Estimators (each a factory ``make_*(integrand, pdf, ...)`` returning a Warp kernel):

``gauss_legendre``  (the default) deterministic product Gauss-Legendre after the NDF's change of
    variables u = CDF(theta_h), phi uniform. The reflected direction l = reflect(v, h) is above the
    horizon exactly when cos(phi) > c*(theta_h) = -cos(theta_v) cos(2 theta_h) / (sin(theta_v) sin(2 theta_h)),
    so the visible domain splits at closed-form breakpoints:
        A: theta_h < (pi/2 - theta_v)/2   every phi in [0, pi] is visible (c* <= -1)
        B: theta_h < (pi/2 + theta_v)/2   phi in [0, acos c*]           (-1 < c* < 1)
        beyond: nothing reflects above the horizon.
    Integrating each region over its exact domain removes the horizon kink. c* grows monotonically
    in theta_h; near grazing view c* ~ -cot(theta_v) / (2 theta_h) varies on every scale from theta_a
    to pi/4, so B is cut into panels growing geometrically (factor PANEL_RATIO) from both of its ends
    towards pi/4, and each panel is integrated in u = CDF(theta). The sqrt-like ends of acos c* at c* = -1 and 1 are removed by u = u0 + du smoothstep(s).
    By symmetry in phi,
        I = (1/pi) ∫_0^1 du ∫_0^phimax(u) dphi  g(h) / p(h).
    The integrand is then analytic in both variables and GL converges exponentially.
``qmc_ndf``  h from the NDF's inverse CDF at scrambled Sobol' points, weight g / p / N.
``qmc_vndf`` (GGX) h from the visible-normal distribution, p_v(h) = G1(v) max(0, v.h) D(h) / (n.v).

All accumulate in float64; per-sample terms run in float32; the domain maps run in float64 because
1 - u underflows float32 for small alpha.
"""

from __future__ import annotations

import math

import warp as wp

from ..terms.frame import view_dir

PI64 = wp.constant(wp.float64(math.pi))
TWO_PI = wp.constant(2.0 * math.pi)


PANEL_RATIO = 4.0  # panels grow geometrically in theta_h (and in pi/2 - theta_h) by this factor


@wp.func
def next_geometric(t_lo: wp.float64, t0: wp.float64):
    """Smallest t0 * R^j (j >= 0) above t_lo, for t0 > 0."""
    if t_lo < t0:
        return t0
    j = wp.floor(wp.log(t_lo / t0) / wp.log(wp.float64(PANEL_RATIO))) + wp.float64(1.0)
    return t0 * wp.pow(wp.float64(PANEL_RATIO), j)


@wp.func
def next_theta(t_lo: wp.float64, theta_a: wp.float64, theta_peak: wp.float64):
    """Upper edge of the panel starting at t_lo: the next of
    - the NDF-peak breakpoints theta_peak R^j (below pi/4): the tail of D decays like a power of theta;
    - the horizon breakpoints: theta_a (c* = -1), then geometric from theta_a up to pi/4 and from
      theta_b = pi/2 - theta_a down to pi/4 (c* ~ -cot(theta_v) / (2 theta_h) varies on every scale
      between theta_a and pi/4 at grazing view)."""
    quarter = PI64 * wp.float64(0.25)
    half = PI64 * wp.float64(0.5)
    if t_lo < quarter:
        t = wp.min(next_geometric(t_lo, theta_a), quarter)
        return wp.min(t, next_geometric(t_lo, theta_peak))
    d = wp.max((half - t_lo) / wp.float64(PANEL_RATIO), theta_a)
    return half - d


@wp.func
def asinh64(x: wp.float64):
    """asinh(x) = log(x + sqrt(x^2 + 1)) for x >= 0 (Warp has no asinh builtin)."""
    return wp.log(x + wp.sqrt(x * x + wp.float64(1.0)))


@wp.func
def horizon_scale(cos_v: wp.float64, alpha: wp.float64):
    """Distance in n.l from the horizon to the pole of Smith G2 as n.l -> 0:
    G2 ~ 2 (n.l) / ((n.l)(1 + 2 Lambda(v)) + alpha) puts it at n.l = -alpha (n.v) / sqrt((n.v)^2 + alpha^2 (1 - (n.v)^2)),
    about min(n.v, alpha). Integrands vary on this scale next to the horizon cut."""
    return alpha * cos_v / wp.sqrt(cos_v * cos_v + alpha * alpha * (wp.float64(1.0) - cos_v * cos_v))


def make_gauss_legendre(integrand, pdf, tan2_from_u, u_from_tan2, vec_type, acc_type):
    """Product Gauss-Legendre over panels in theta_h (module docstring). Per panel [t_lo, t_hi]:
    - the outer variable is u = CDF(theta_h) on the NDF-peak panel [0, atan(alpha)] (the weight is
      g / p, D cancels), and theta_h itself beyond it (the weight is 2 pi sin(theta_h) g, because
      du = 2 pi D cos sin dtheta); a panel in region B has its outer variable smoothstep-mapped;
    - the inner variable phi runs over [0, pi] in region A and [0, acos c*] in region B, through a
      sinh map that resolves G2's pole at n.l = -horizon_scale next to the cut.
    Kernel inputs: per-texel n.v, alpha and param; GL nodes/weights on [0, 1] for the outer (xu, wu) and
    inner (xp, wq) variables."""
    nch = vec_type._length_

    @wp.kernel(enable_backward=False, module="unique")
    def gauss_legendre_kernel(
        nov: wp.array(dtype=float),
        alpha: wp.array(dtype=float),
        param: wp.array(dtype=float),
        xu: wp.array(dtype=wp.float64),
        wu: wp.array(dtype=wp.float64),
        xp: wp.array(dtype=wp.float64),
        wq: wp.array(dtype=wp.float64),
        out: wp.array2d(dtype=wp.float64),
    ):
        i = wp.tid()
        a = alpha[i]
        prm = param[i]
        a64 = wp.float64(a)
        v = view_dir(nov[i])
        cos_v = wp.float64(v[2])
        sin_v = wp.float64(v[0])
        zero = wp.float64(0.0)
        one = wp.float64(1.0)
        two = wp.float64(2.0)
        eps_l = horizon_scale(cos_v, a64)
        theta_a = wp.float64(0.5) * wp.atan2(cos_v, sin_v)  # c* = -1: (pi/2 - theta_v) / 2
        theta_b = PI64 * wp.float64(0.5) - theta_a  # c* = +1: nothing beyond reflects above the horizon
        theta_peak = wp.atan(a64)
        acc = acc_type()
        t_lo = zero
        while t_lo < theta_b:
            t_hi = next_theta(t_lo, theta_a, theta_peak)
            in_b = t_lo >= theta_a
            in_u = t_hi <= theta_peak
            x_lo = t_lo
            x_hi = t_hi
            if in_u:
                x_lo = u_from_tan2(wp.tan(t_lo) * wp.tan(t_lo), a64)
                x_hi = u_from_tan2(wp.tan(t_hi) * wp.tan(t_hi), a64)
            dx = x_hi - x_lo
            for k in range(xu.shape[0]):
                s = xu[k]
                x = x_lo + dx * s
                wk = wu[k] * dx
                if in_b:  # smoothstep: removes the sqrt-like ends of acos(c*) at c* = +-1
                    x = x_lo + dx * s * s * (wp.float64(3.0) - two * s)
                    wk = wu[k] * dx * wp.float64(6.0) * s * (one - s)
                cos_h = wp.cos(x)
                sin_h = wp.sin(x)
                if in_u:
                    tan2 = tan2_from_u(x, a64)
                    cos_h = one / wp.sqrt(one + tan2)
                    sin_h = wp.sqrt(tan2) * cos_h
                else:
                    wk = wk * two * PI64 * sin_h  # du = 2 pi D cos sin dtheta, and g / p = g / (D cos)
                phimax = PI64
                eps = PI64  # sinh-map scale; >= phimax makes the map nearly linear
                if in_b:
                    # c* = -cos(theta_v) cos(2 theta_h) / (sin(theta_v) sin(2 theta_h))
                    c_star = -cos_v * (cos_h * cos_h - sin_h * sin_h) / (sin_v * two * sin_h * cos_h)
                    phimax = wp.acos(wp.clamp(c_star, -one, one))
                    # n.l = 2 (n.h) sin(theta_v) sin(theta_h) (cos(phi) - c*): G2's pole at n.l = -eps_l
                    # lies eps_l / slope beyond phimax
                    slope = two * cos_h * sin_v * sin_h * wp.max(wp.sin(phimax), wp.float64(1.0e-12))
                    eps = wp.max(eps_l / slope, wp.float64(1.0e-12))
                big_a = asinh64(phimax / eps)
                for j in range(xp.shape[0]):
                    # sinh map (Johnston & Elliott 2005): phi = phimax - eps sinh(big_a (1 - x))
                    arg = big_a * (one - xp[j])
                    phi = phimax - eps * wp.sinh(arg)
                    w = wk * wq[j] * eps * wp.cosh(arg) * big_a
                    h = wp.vec3(float(sin_h * wp.cos(phi)), float(sin_h * wp.sin(phi)), float(cos_h))
                    g = integrand(v, h, a, prm)
                    if in_u:
                        p = pdf(v, h, a)
                        if p > 0.0:
                            for c in range(wp.static(nch)):
                                acc[c] = acc[c] + w * wp.float64(g[c] / p)
                    else:
                        for c in range(wp.static(nch)):
                            acc[c] = acc[c] + w * wp.float64(g[c])
            t_lo = t_hi
        for c in range(wp.static(nch)):
            out[i, c] = acc[c] / PI64

    return gauss_legendre_kernel


def make_qmc(integrand, pdf, sample, vec_type, acc_type):
    """Quasi-Monte Carlo: ``sample(v, alpha, u1, u2) -> h`` draws from density ``pdf(v, h, alpha)``;
    the estimate is sum_k w_k g(h_k) / p(h_k) with w_k = 1/N (points: scrambled Sobol' or Hammersley)."""
    nch = vec_type._length_

    @wp.kernel(enable_backward=False, module="unique")
    def qmc_kernel(
        nov: wp.array(dtype=float),
        alpha: wp.array(dtype=float),
        param: wp.array(dtype=float),
        pts: wp.array2d(dtype=float),
        wts: wp.array(dtype=wp.float64),
        out: wp.array2d(dtype=wp.float64),
    ):
        i = wp.tid()
        a = alpha[i]
        prm = param[i]
        v = view_dir(nov[i])
        acc = acc_type()
        for k in range(pts.shape[0]):
            h = sample(v, a, pts[k, 0], pts[k, 1])
            p = pdf(v, h, a)
            if p > 0.0:
                g = integrand(v, h, a, prm)
                for c in range(wp.static(nch)):
                    acc[c] = acc[c] + wts[k] * wp.float64(g[c] / p)
        for c in range(wp.static(nch)):
            out[i, c] = acc[c]

    return qmc_kernel
