"""The quadrature of the microfacet diffuse BRDF's facet-normal integral (the BRDF, Gotanda 2014 course notes, Eq. 4,
and its G2 reduction are stated in lutbake.integrands.diffuse):
    I(l, v) = ∫_Ω (m.l)+ (m.v)+ F_facet(m.l, m.v) D(m) dω_m,   f = G2(l, v) I / (pi (n.l)(n.v)).
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

To a tolerance (``fd_microfacet_adaptive_for``, kind btf's default): the same panels, each u panel at the GL orders
FACET_ORDERS refined greedily (lutbake.sampling.ladder) until the sum of the panels' |Q_(k) - Q_(k-1)| is within the
texel's tolerance; the per-texel estimate is that sum plus the float32 rounding (FACET_ROUNDING). In phi_m only the
pieces on both visible arcs are integrated (the integrand is 0 on the others: 1 of the 4 where the arcs overlap
partly, 2 where both are whole), and the nodes' cos / sin are those of the piece's start (float64) rotated by the
node's offset (float32), the mirror node's (GL nodes are symmetric) the piece's end rotated back by the same offset;
the ends' cos / sin by angle addition (phi_x +- w_x). Texels that differ only in the azimuth of l share each u
node's theta_m and arc half-widths (fd_microfacet_adaptive_azimuths_for, the same values as per texel).
"""

from __future__ import annotations

import warp as wp

from ..edge import COS_EPS
from ..runtime.warp_runtime import kernel_factory
from ..terms import masking
from ..terms.distributions import GGX
from .arrays import Floats, Levels, LightView, Rows64, Rule
from .ladder import greedy_ladder_for
from .panels import (
    MAX_TAIL_CUTS,
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


@kernel_factory
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


@kernel_factory
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


@wp.struct
class FacetPair:
    """The per-texel constants of Eq. 4's m-integral: cosines, sines and azimuths of l and v (``azimuth``), alpha,
    f0, and the sorted cuts 1 - u of the clamps' onsets (om1 = 1 - min(u_l, u_v), om2 = 1 - max(u_l, u_v))."""

    l: wp.vec3
    v: wp.vec3
    cl: wp.float64
    sl: wp.float64
    cv: wp.float64
    sv: wp.float64
    azl: wp.vec3d
    azv: wp.vec3d
    alpha: wp.float64
    f0: float
    om1: wp.float64
    om2: wp.float64
    n_geo: int


@wp.func
def azimuth(x: wp.vec3):
    """(phi, cos phi, sin phi) of x's azimuth, float64."""
    phi = wp.atan2(wp.float64(x[1]), wp.float64(x[0]))
    return wp.vec3d(phi, wp.cos(phi), wp.sin(phi))


@wp.func
def facet_pair(l: wp.vec3, v: wp.vec3, alpha: float, f0: float):
    p = FacetPair()
    one = wp.float64(1.0)
    p.l = l
    p.v = v
    p.cl = wp.float64(l[2])
    p.cv = wp.float64(v[2])
    p.sl = wp.sqrt(wp.max(one - p.cl * p.cl, wp.float64(0.0)))
    p.sv = wp.sqrt(wp.max(one - p.cv * p.cv, wp.float64(0.0)))
    p.azl = azimuth(l)
    p.azv = azimuth(v)
    p.alpha = wp.float64(alpha)
    p.f0 = f0
    oml = om_visible_ggx(p.cl, p.alpha)
    omv = om_visible_ggx(p.cv, p.alpha)
    p.om1 = wp.max(oml, omv)
    p.om2 = wp.min(oml, omv)
    p.n_geo = n_tail_cuts(p.alpha)
    return p


@wp.func
def u_panel(j: int, n_geo: int, om1: wp.float64, om2: wp.float64):
    """Panel j (0 .. 3 (n_geo + 1) - 1) of u as (lo, du, 1 - (lo + du)): geometric panel j // 3
    (lutbake.sampling.panels) cut at the clamps' onsets u_1 <= u_2 into three, the (j % 3)-th of them (du = 0 where
    a cut falls outside)."""
    one = wp.float64(1.0)
    g = j // 3
    prev = wp.float64(0.0)
    om_prev = one
    if g > 0:
        r2p = wp.pow(TAIL_RATIO64, wp.float64(2 * g))
        om_prev = one / (one + r2p)
        prev = r2p / (one + r2p)
    om_cut = wp.float64(0.0)
    if g < n_geo:
        om_cut = one / (one + wp.pow(TAIL_RATIO64, wp.float64(2 * (g + 1))))
    om_a = wp.clamp(om1, om_cut, om_prev)
    om_b = wp.clamp(om2, om_cut, om_prev)
    ends = interval(j % 3, wp.vec4d(om_prev, om_a, om_b, om_cut), om_cut)
    lo = prev
    if j % 3 > 0:
        lo = one - ends[0]
    return wp.vec3d(lo, ends[0] - ends[1], ends[1])


@wp.func
def on_arc(phi: wp.float64, phx: wp.float64, w: wp.float64):
    """phi within w of phx on the circle."""
    d = wrap_2pi(phi - phx)
    return d <= w or d >= TWO_PI64 - w


# a u node's (weight, cos theta_m, sin theta_m, w_l, w_v, cos w_l, sin w_l, cos w_v, sin w_v)
UNode = wp.types.vector(length=9, dtype=wp.float64)
Azimuths = wp.array(dtype=wp.vec3d)  # per texel, ``azimuth`` of l


@wp.func
def u_node(p: FacetPair, panel: wp.vec3d, rules: Rule, off: int, k: int):
    """Node k of the smoothstep-mapped u panel ``panel`` (u_panel) under the GL rule rules[off :]: its weight
    w_k du 6 s (1 - s), the facet's cos / sin theta_m and the half-widths of the arcs where m.l, m.v >= 0 (with their
    cos / sin). None of them depends on the azimuths of l and v."""
    one = wp.float64(1.0)
    s = rules[off + k][0]
    csm = facet_cos_sin(panel[0], panel[1], panel[2], s, p.alpha)
    wl = arc_half_width(csm[0], csm[1], p.cl, p.sl)
    wv = arc_half_width(csm[0], csm[1], p.cv, p.sv)
    w = rules[off + k][1] * panel[1] * wp.float64(6.0) * s * (one - s)
    return UNode(w, csm[0], csm[1], wl, wv, wp.cos(wl), wp.sin(wl), wp.cos(wv), wp.sin(wv))


@wp.struct
class ArcEnds:
    """The four arc ends (arc_ends): wrapped angles, cosines, sines."""

    e: wp.vec4d
    c: wp.vec4d
    s: wp.vec4d


@wp.func
def arc_ends(azl: wp.vec3d, azv: wp.vec3d, node: UNode):
    """The arcs' ends phi_l - w_l, phi_l + w_l, phi_v - w_v, phi_v + w_v wrapped to [0, 2 pi), their cosines and
    sines, these by angle addition from (cos, sin) of the azimuths and the half-widths."""
    c = wp.vec4d(azl[1] * node[5], azl[1] * node[5], azv[1] * node[7], azv[1] * node[7])
    cc = wp.vec4d(azl[2] * node[6], -azl[2] * node[6], azv[2] * node[8], -azv[2] * node[8])
    s = wp.vec4d(azl[2] * node[5], azl[2] * node[5], azv[2] * node[7], azv[2] * node[7])
    ss = wp.vec4d(-azl[1] * node[6], azl[1] * node[6], -azv[1] * node[8], azv[1] * node[8])
    e = wp.vec4d(
        wrap_2pi(azl[0] - node[3]), wrap_2pi(azl[0] + node[3]), wrap_2pi(azv[0] - node[4]), wrap_2pi(azv[0] + node[4])
    )
    r = ArcEnds()
    r.e = e
    r.c = c + cc
    r.s = s + ss
    return r


@wp.func
def end_cos_sin(x: wp.float64, ends: ArcEnds):
    """(cos, sin) of the arc end x, one of ends.e (sort4 returns them exactly)."""
    k = 3
    if x == ends.e[0]:
        k = 0
    elif x == ends.e[1]:
        k = 1
    elif x == ends.e[2]:
        k = 2
    return wp.vec2d(ends.c[k], ends.s[k])


@kernel_factory
def phi_row_for(F_facet):
    """``phi_row(l, v, azl, azv, node, f0, rules, off, n)``: the n-point rule in phi_m at the u node ``node``
    (u_node; azl, azv: ``azimuth`` of l, v): the sum of w (m.l)+ (m.v)+ F_facet over the pieces between the arcs'
    ends that lie on both arcs (on the others the integrand is 0). The GL nodes are symmetric (x_(n-1-i) = 1 - x_i):
    node i's cos / sin are the piece's start rotated by the offset dphi x_i, node n - 1 - i's its end rotated back
    by the same offset (float64 ends, float32 offset: one float32 cos / sin pair per two nodes); the ends' cos / sin
    by angle addition (phi_x +- w_x) from the azimuths' and the half-widths' (arc_ends)."""
    Ff = F_facet

    @wp.func
    def facet_term(l: wp.vec3, v: wp.vec3, node: UNode, c: wp.float64, s: wp.float64, f0: float):
        # (m.l)+ (m.v)+ F_facet at the facet (theta_m of node, azimuth of cos c and sin s)
        m = wp.vec3(float(node[2] * c), float(node[2] * s), float(node[1]))
        MoL = wp.dot(m, l)
        MoV = wp.dot(m, v)
        t = wp.float64(0.0)
        if MoL > 0.0 and MoV > 0.0:
            t = wp.float64(MoL * MoV * Ff(MoL, MoV, f0))
        return t

    @wp.func
    def phi_row(
        l: wp.vec3, v: wp.vec3, azl: wp.vec3d, azv: wp.vec3d, node: UNode, f0: float, rules: Rule, off: int, n: int
    ):
        wl = node[3]
        wv = node[4]
        row = wp.float64(0.0)
        ends = arc_ends(azl, azv, node)
        bs = sort4(ends.e[0], ends.e[1], ends.e[2], ends.e[3])
        for q in range(4):
            ab = interval(q, bs, bs[0] + TWO_PI64)
            a = ab[0]
            dphi = ab[1] - a
            mid = a + wp.float64(0.5) * dphi
            if dphi > wp.float64(0.0) and on_arc(mid, azl[0], wl) and on_arc(mid, azv[0], wv):
                csa = end_cos_sin(a, ends)
                csb = end_cos_sin(bs[(q + 1) % 4], ends)  # ab[1] (bs[0] + 2 pi for q = 3)
                ca = csa[0]
                sa = csa[1]
                cb = csb[0]
                sb = csb[1]
                h = n // 2
                for i in range(n - h):  # node i from the start; for i < h also node n - 1 - i from the end
                    dl = float(dphi * rules[off + i][0])
                    cd = wp.float64(wp.cos(dl))
                    sd = wp.float64(wp.sin(dl))
                    w = rules[off + i][1] * dphi
                    row = row + w * facet_term(l, v, node, ca * cd - sa * sd, sa * cd + ca * sd, f0)
                    if i < h:
                        w = rules[off + n - 1 - i][1] * dphi
                        row = row + w * facet_term(l, v, node, cb * cd + sb * sd, sb * cd - cb * sd, f0)
        return row

    return phi_row


@kernel_factory
def facet_panel_for(F_facet):
    """``facet_panel(pair, j, rules, off, n)``: the n x n product rule (rules[off : off + n]) over u panel j
    (``u_panel``): the sum of w (m.l)+ (m.v)+ F_facet / (n.m) over its nodes (times G2 / (2 pi^2 (n.l)(n.v)) it is
    the panel's share of f); 0 for an empty panel. In phi_m only the pieces between the arcs' ends that lie on both
    arcs are integrated (phi_row_for)."""
    phi_row = phi_row_for(F_facet)

    @wp.func
    def facet_panel(p: FacetPair, j: int, rules: Rule, off: int, n: int):
        panel = u_panel(j, p.n_geo, p.om1, p.om2)
        acc = wp.float64(0.0)
        if panel[1] <= wp.float64(0.0):
            return acc
        for k in range(n):
            node = u_node(p, panel, rules, off, k)
            acc = acc + node[0] * phi_row(p.l, p.v, p.azl, p.azv, node, p.f0, rules, off, n) / node[1]
        return acc

    return facet_panel


@kernel_factory
def facet_panel_azimuths_for(F_facet):
    """``facet_panel_azimuths(pair, lv, azl, first, end, j, rules, off, n, out, col)``: ``facet_panel`` for every
    texel first .. end - 1 of lv (l, v): texels that differ from ``pair``'s only in the azimuth of l (azl[t]), so
    each u node (u_node) is computed once for all of them; panel j's sum of texel t is written to out[col, t]
    (the same float operations per texel as facet_panel, so the same values)."""
    phi_row = phi_row_for(F_facet)

    @wp.func
    def facet_panel_azimuths(
        p: FacetPair,
        lv: LightView,
        azl: Azimuths,
        first: int,
        end: int,
        j: int,
        rules: Rule,
        off: int,
        n: int,
        out: Rows64,
        col: int,
    ):
        panel = u_panel(j, p.n_geo, p.om1, p.om2)
        for t in range(first, end):
            out[col, t] = wp.float64(0.0)
        if panel[1] > wp.float64(0.0):
            for k in range(n):
                node = u_node(p, panel, rules, off, k)
                for t in range(first, end):
                    row = phi_row(lv[t, 0], p.v, azl[t], p.azv, node, p.f0, rules, off, n)
                    out[col, t] = out[col, t] + node[0] * row / node[1]

    return facet_panel_azimuths


MAX_U_PANELS = 3 * (MAX_TAIL_CUTS + 1)  # slots of u_panel: geometric panels x 3 (the cuts at u_l, u_v)
# the float32 terms and node directions (m rounded to float32, cos / sin of the phi offsets in float32) carry a
# rounding no difference of two orders sees: measured at tolerance 1e-10 against the converged numpy reference
# (tests/test_btf_tolerance.py), max 2.4e-7 relative (median 5e-8) over 198 texels of the 16 x 32^3 grid; the
# estimate adds twice that
FACET_ROUNDING = wp.constant(wp.float64(5.0e-7))
QUADRATURE_SHARE = wp.constant(wp.float64(0.9))  # of the tolerance; the rest is left to FACET_ROUNDING
# the orders of the ladder: from 6 (6 -> 8 or 6 -> 9, as lutbake.sampling.rules.ADAPTIVE_ORDERS) two coarse rules
# agreed by coincidence on 1 % of the 16 x 32^3 btf's texels (measured: error 4.3e-5 at an estimate 8e-6); from 8
# every estimate bounds the error against the numpy reference (tests/test_btf_tolerance.py)
FACET_ORDERS = (8, 12, 16, 24, 32, 48, 64)


@wp.func
def facet_scale(p: FacetPair, alpha: float):
    """G2 / (2 pi^2 (n.l)(n.v)): f = scale * (the sum of the panels' facet_panel)."""
    G2 = masking.G2_smith_height_correlated(masking.Lambda_ggx(p.v[2], alpha), masking.Lambda_ggx(p.l[2], alpha))
    return wp.float64(G2) / (TWO_PI64 * PI64 * p.cl * p.cv)


@wp.func
def facet_estimate(scale: wp.float64, qe: wp.vec2d):
    """(f, error estimate) from the ladder's (sum of panels, sum of |Q_(k) - Q_(k-1)|): plus the float32 rounding."""
    f = scale * qe[0]
    return wp.vec2d(f, scale * qe[1] + FACET_ROUNDING * wp.abs(f))


@kernel_factory
def fd_microfacet_adaptive_for(F_facet):
    """``fd_microfacet_adaptive(l, v, alpha, f0, rules, levels, tol) -> vec2d(f, error estimate)``: Eq. 4 on the
    panels of ``fd_microfacet_for``, each u panel (with its phi pieces) at GL orders ``levels``, refined greedily
    (lutbake.sampling.ladder) until the sum of the panels' |Q_(k) - Q_(k-1)| is within QUADRATURE_SHARE of the
    texel's tolerance max(tol[0], tol[1] |f|). The estimate is that sum plus FACET_ROUNDING |f| (float32 terms)."""
    integrate, _, _, Sums, _ = greedy_ladder_for(facet_panel_for(F_facet), MAX_U_PANELS)

    @wp.func
    def fd_microfacet_adaptive(
        l: wp.vec3,
        v: wp.vec3,
        alpha: float,
        f0: float,
        rules: Rule,
        levels: Levels,
        tol: wp.vec2d,
    ):
        zero = wp.float64(0.0)
        if l[2] <= COS_EPS or v[2] <= COS_EPS:
            return wp.vec2d(zero, zero)
        p = facet_pair(l, v, alpha, f0)
        scale = facet_scale(p, alpha)  # f = scale * (sum over panels)
        t_abs = Sums(QUADRATURE_SHARE * tol[0] / scale)
        t_rel = Sums(QUADRATURE_SHARE * tol[1])
        total, err = integrate(p, 3 * (p.n_geo + 1), rules, levels, t_abs, t_rel, wp.float64(0.0))
        return facet_estimate(scale, wp.vec2d(total[0], err[0]))

    return fd_microfacet_adaptive


@kernel_factory
def fd_microfacet_adaptive_azimuths_for(F_facet):
    """``fd_microfacet_adaptive_azimuths(lv, alpha, f0, rules, levels, tol, first, end, azl, panels, out)``:
    ``fd_microfacet_adaptive`` of the texels first .. end - 1 of lv (l, v), which differ only in the azimuth of l
    (equal n.l, v and alpha): every panel's first two levels by facet_panel_azimuths (the u nodes computed once for
    all of them), then each texel's greedy refinement on its own (the ladder's climb). The same float operations
    per texel as fd_microfacet_adaptive, so the same values. Scratch: azl (the azimuths of l), panels (2
    MAX_U_PANELS rows: panel j at levels[1], then at levels[0], one column per texel); out[t] = (f, error
    estimate)."""
    _, climb, Panels, Sums, Orders = greedy_ladder_for(facet_panel_for(F_facet), MAX_U_PANELS)
    panel_azimuths = facet_panel_azimuths_for(F_facet)

    @wp.func
    def fd_microfacet_adaptive_azimuths(
        lv: LightView,
        alpha: Floats,
        f0: float,
        rules: Rule,
        levels: Levels,
        tol: wp.vec2d,
        first: int,
        end: int,
        azl: Azimuths,
        panels: Rows64,
        out: Rows64,
    ):
        zero = wp.float64(0.0)
        if lv[first, 0][2] <= COS_EPS or lv[first, 1][2] <= COS_EPS:
            for t in range(first, end):
                out[t, 0] = zero
                out[t, 1] = zero
            return
        for t in range(first, end):
            azl[t] = azimuth(lv[t, 0])
        p = facet_pair(lv[first, 0], lv[first, 1], alpha[first], f0)
        n_panels = 3 * (p.n_geo + 1)
        top = wp.min(1, levels.shape[0] - 1)
        for j in range(n_panels):
            panel_azimuths(p, lv, azl, first, end, j, rules, levels[top][0], levels[top][1], panels, j)
            panel_azimuths(p, lv, azl, first, end, j, rules, levels[0][0], levels[0][1], panels, MAX_U_PANELS + j)
        for t in range(first, end):
            pt = facet_pair(lv[t, 0], lv[t, 1], alpha[t], f0)
            scale = facet_scale(pt, alpha[t])
            fine0 = Panels()
            coarse0 = Panels()
            lev = Orders()
            for j in range(n_panels):
                fine0[j, 0] = panels[j, t]
                coarse0[j, 0] = panels[MAX_U_PANELS + j, t]
                lev[j] = top
            t_abs = Sums(QUADRATURE_SHARE * tol[0] / scale)  # as fd_microfacet_adaptive
            t_rel = Sums(QUADRATURE_SHARE * tol[1])
            total, err = climb(pt, n_panels, rules, levels, t_abs, t_rel, wp.float64(0.0), fine0, coarse0, lev)
            fe = facet_estimate(scale, wp.vec2d(total[0], err[0]))
            out[t, 0] = fe[0]
            out[t, 1] = fe[1]

    return fd_microfacet_adaptive_azimuths
