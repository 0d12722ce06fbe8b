"""The microfacet diffuse BRDF of Gotanda 2014 (course notes, Eq. 4), integrated over the facet normal m.

Microfacet diffuse (every facet Lambertian, rho = 1):
    f(l, v) = 1 / (pi (n.l)(n.v)) ∫_Ω (m.l)+ (m.v)+ D(m) F_facet(m.l, m.v) G2(m, l, v) dω_m
GGX D, height-correlated Smith G2 = χ+(m.l) χ+(m.v) / (1 + Λ(n.v) + Λ(n.l)) (Heitz 2014, Eq. 99): apart from
the χ+ (the clamps), G2 does not depend on m and leaves the integral:
    f = G2(l, v) / (pi (n.l)(n.v)) ∫ (m.l)+ (m.v)+ F_facet D(m) dω_m.
Quadrature (``fd_microfacet_for``), deterministic:
- u = CDF(theta_m) of D(m)(n.m) (GGX: tan^2 theta_m = alpha^2 u / (1 - u)), so D(m) dω_m = du dphi / (2 pi (n.m))
  and the integrand is (m.l)+ (m.v)+ F_facet / (2 pi (n.m)); D, however peaked, is absorbed into u.
- the facet m sees x (x = l or v) for every phi while theta_m < pi/2 - theta_x, i.e. u < u_x =
  (n.x)^2 / (alpha^2 (1 - (n.x)^2) + (n.x)^2); u is cut at u_l and u_v into three panels, each smoothstep-mapped
  (removes the sqrt-like onset of the clamp at u_x and the integrable 1/sqrt(1 - u) of 1/(n.m) at u = 1).
- for each u, (m.x) >= 0 on the arc |phi - phi_x| <= acos(-cot(theta_m) cot(theta_x)); the four arc ends cut
  [0, 2 pi) into four intervals on each of which the integrand is either 0 or smooth (no kink inside).
- each panel and interval gets an n-point Gauss-Legendre rule: 12 n^2 evaluations per (l, v).
At sigma -> 0, D -> delta(m - n) / (n.m) and f -> F_facet(n.l, n.v) / pi: Lambert x Eq. 6 for the Eq. 6 facet form.
Panels: lutbake.sampling.panels.
"""

from __future__ import annotations

import functools

import warp as wp

from ..edge import COS_EPS
from ..terms import masking
from ..terms.distributions import GGX
from .panels import (
    PI64,
    TAIL_RATIO64,
    TWO_PI64,
    arc_half_width,
    facet_cos_sin,
    interval,
    n_tail_cuts,
    om_visible_ggx,
    sort4,
    wrap_2pi,
)


@functools.lru_cache(maxsize=None)
def fd_microfacet_for(F_facet):
    """The microfacet diffuse BRDF ``fd_microfacet(l, v, alpha, f0, rule) -> float64`` (rho = 1), Eq. 4,
    integrated as in the module docstring with the n-point GL rule ``rule`` (node, weight) on [0, 1];
    ``F_facet(MoL, MoV, f0)`` is the per-facet transmission (lutbake.terms.diffuse.F_facet_*)."""
    Ff = F_facet

    @wp.func
    def fd_microfacet(l: wp.vec3, v: wp.vec3, alpha: float, f0: float, rule: wp.array(dtype=wp.vec2d)):
        NoL = l[2]
        NoV = v[2]
        if NoL <= COS_EPS or NoV <= COS_EPS:
            return wp.float64(0.0)
        one = wp.float64(1.0)
        a64 = wp.float64(alpha)
        G2 = masking.G2_smith_height_correlated(masking.Lambda_ggx(NoV, alpha), masking.Lambda_ggx(NoL, alpha))
        cl = wp.float64(NoL)
        cv = wp.float64(NoV)
        sl = wp.sqrt(wp.max(one - cl * cl, wp.float64(0.0)))
        sv = wp.sqrt(wp.max(one - cv * cv, wp.float64(0.0)))
        phl = wp.atan2(wp.float64(l[1]), wp.float64(l[0]))
        phv = wp.atan2(wp.float64(v[1]), wp.float64(v[0]))
        # the cuts u_l, u_v, sorted, as 1 - u (om_visible_ggx, without cancellation)
        oml = om_visible_ggx(cl, a64)
        omv = om_visible_ggx(cv, a64)
        om1 = wp.max(oml, omv)  # 1 - min(u_l, u_v)
        om2 = wp.min(oml, omv)  # 1 - max(u_l, u_v)
        n = rule.shape[0]
        acc = wp.float64(0.0)
        n_geo = n_tail_cuts(a64)
        prev = wp.float64(0.0)
        om_prev = one
        for g in range(n_geo + 1):
            cut = one
            om_cut = wp.float64(0.0)
            if g < n_geo:
                r2 = wp.pow(TAIL_RATIO64, wp.float64(2 * (g + 1)))
                om_cut = one / (one + r2)
                cut = r2 / (one + r2)
            # the segment [prev, cut] cut at u1 and u2 where they fall inside it
            om_a = wp.clamp(om1, om_cut, om_prev)
            om_b = wp.clamp(om2, om_cut, om_prev)
            for p in range(3):
                lo = prev
                ends = interval(p, wp.vec4d(om_prev, om_a, om_b, om_cut), om_cut)
                om_lo = ends[0]
                om_hi = ends[1]
                if p > 0:
                    lo = one - om_lo
                du = om_lo - om_hi
                if du > wp.float64(0.0):
                    for k in range(n):
                        s = rule[k][0]
                        wu = rule[k][1] * du * wp.float64(6.0) * s * (one - s)
                        # 1 - u without cancellation (u_l -> 1 for n.l -> 1 and small alpha)
                        csm = facet_cos_sin(lo, du, om_hi, s, a64)
                        cm = csm[0]
                        sm = csm[1]
                        wl = arc_half_width(cm, sm, cl, sl)
                        wv = arc_half_width(cm, sm, cv, sv)
                        # the four arc ends, sorted, cut [0, 2 pi) into four intervals
                        bs = sort4(wrap_2pi(phl - wl), wrap_2pi(phl + wl), wrap_2pi(phv - wv), wrap_2pi(phv + wv))
                        row = wp.float64(0.0)
                        for q in range(4):
                            ab = interval(q, bs, bs[0] + TWO_PI64)
                            a = ab[0]
                            dphi = ab[1] - a
                            if dphi > wp.float64(0.0):
                                for j in range(n):
                                    phi = a + dphi * rule[j][0]
                                    m = wp.vec3(float(sm * wp.cos(phi)), float(sm * wp.sin(phi)), float(cm))
                                    MoL = wp.dot(m, l)
                                    MoV = wp.dot(m, v)
                                    if MoL > 0.0 and MoV > 0.0:
                                        row = row + rule[j][1] * dphi * wp.float64(MoL * MoV * Ff(MoL, MoV, f0))
                        acc = acc + wu * row / cm
            prev = cut
            om_prev = om_cut
        return wp.float64(G2) * acc / (TWO_PI64 * PI64 * cl * cv)

    return fd_microfacet


@functools.lru_cache(maxsize=None)
def fd_microfacet_sobol_for(F_facet):
    """Eq. 4 by sampling m from GGX's D(m)(n.m) (inverse CDF, lutbake.terms.distributions.GGX.sample_ndf) at the
    2D points ``pts``: f = G2 / (pi (n.l)(n.v)) (1/N) sum_k (m.l)+ (m.v)+ F_facet / (n.m)
    (D dω_m = pdf dω_m / (n.m)): an estimator independent of the panel rule of ``fd_microfacet_for``."""
    sample = GGX.sample_ndf

    @wp.func
    def fd_microfacet_sobol(l: wp.vec3, v: wp.vec3, alpha: float, f0: float, pts: wp.array2d(dtype=float)):
        if l[2] <= COS_EPS or v[2] <= COS_EPS:
            return wp.float64(0.0)
        G2 = masking.G2_smith_height_correlated(masking.Lambda_ggx(v[2], alpha), masking.Lambda_ggx(l[2], alpha))
        acc = wp.float64(0.0)
        for k in range(pts.shape[0]):
            m = sample(v, alpha, pts[k, 0], pts[k, 1])
            MoL = wp.dot(m, l)
            MoV = wp.dot(m, v)
            if MoL > 0.0 and MoV > 0.0 and m[2] > 0.0:
                acc = acc + wp.float64(MoL * MoV * F_facet(MoL, MoV, f0) / m[2])
        n = wp.float64(pts.shape[0])
        return wp.float64(G2) * acc / (n * PI64 * wp.float64(l[2]) * wp.float64(v[2]))

    return fd_microfacet_sobol
