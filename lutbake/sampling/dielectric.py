"""Panelled Gauss-Legendre over the microfacet normal for the rough dielectric BSDF (reflection + refraction).

The integrand (lutbake.integrands.dielectric) is a function of h = (theta_h, phi) that is analytic except on a few
curves where a lobe's support ends or the Fresnel term has a square-root kink. As the ``dfg`` estimator splits at
the reflection horizon (lutbake.sampling.hemisphere, docs/estimators.md), this one integrates every smooth piece over
its exact domain. With v = (sin theta_v, 0, cos theta_v),
c = v.h = cos(theta_v) cos(theta_h) + sin(theta_v) sin(theta_h)
cos(phi) grows with cos(phi), and each curve is a breakpoint in phi at every theta_h, in closed form:
    phi_l  n.l = 0 (reflection horizon):   cos(phi) = c* = -cos(theta_v) cos(2 theta_h) / (sin(theta_v) sin(2 theta_h))
    phi_0  v.h = 0 (end of the visible normals): cos(phi) = -cot(theta_v) cot(theta_h)
    phi_c  v.h = cos(theta_c) = sqrt(1 - eta^2), eta < 1 (TIR; F's sqrt kink):
           cos(phi) = (cos theta_c - mu cos theta_h) / (sin theta_v sin theta_h)
    phi_t  n.t = 0, eta < 1 (refraction horizon): t on the horizon at azimuth psi has h = (v + eta t) / |v + eta t|, so
           cos(theta_h) = mu / sqrt(1 + eta^2 + 2 eta sin(theta_v) cos(psi)) gives psi, and phi_t = atan2(eta sin psi,
           sin theta_v + eta cos psi) (a valid refraction pair needs v.t < -eta)
Reflection lives on [0, phi_l], transmission on [0, phi_0] (eta >= 1) or [0, min(phi_c, phi_t)] (eta < 1); n.t < 0
for every h when eta > 1 (t = (c/eta - cos theta_t) h - v/eta with c/eta < cos theta_t). By symmetry in phi,
    I = (1/pi) ∫ du ∫_0^pi dphi g / p    (u = CDF of D(h)(n.h) in theta_h, p = D (n.h); theta_h itself past the peak)
The outer variable theta_h is cut at the theta_h where a phi-breakpoint enters or leaves [0, pi] (there the breakpoint
moves like a square root): theta_a = (pi/2 - theta_v)/2 and theta_b = pi/2 - theta_a (c* = -1, +1), 2 theta_a (phi_0),
|theta_c - theta_v| and theta_v + theta_c (phi_c), acos(mu / sqrt(1 + eta^2 -+ 2 eta sin theta_v)) (phi_t), and
acos(mu / cos theta_c) where phi_t meets phi_c (the transmission domain's end switches from one to the other), and
acos(mu / (2 cos theta_c)) where phi_c meets phi_l (n.l = 2 (v.h)(n.h) - mu = 0 at v.h = cos theta_c); at the NDF
peak scale atan(alpha) R^j; and geometrically from theta_a to pi/4 and from pi/4 to theta_b, as the dfg estimator,
and from |theta_c - theta_v| to pi/4 (a view near the critical angle makes phi_c vary on every scale there).
Every outer panel is smoothstep-mapped (removes the square-root ends). Inner panels run between consecutive
phi-breakpoints: a panel ending at a horizon (phi_l or phi_t) uses the sinh map of the dfg estimator towards it
(G2 has a pole at n.o = -alpha / (1 + 2 Lambda(v)) just past the cut), with x -> x^2 at its lower end when that end is a
kink; the other panels are smoothstep-mapped.
Per texel: (n.v, alpha, eta) (eta = the kernel's ``param``); GL (node, weight) rules on [0, 1] for the outer and
inner variables. float64 accumulation, float32 terms but for v.h, the refraction and the Fresnel term (the
integrand's g64, from the node's float64 angles: near total internal reflection float32's v.h is amplified by 1/eta^2).
alpha = 0 takes the integrand's closed-form mirror limit.
``DielectricGaussLegendre`` is this quadrature at a fixed order, ``DielectricAdaptive`` to a tolerance (each panel up
DIELECTRIC_ORDERS, the worst panel first: make_adaptive_dielectric; an NDF-peak point within PEAK_MERGE of another
breakpoint dropped, as the dfg estimator's), estimators of the lutbake.sampling.plan protocol; the QMC estimators of
lutbake.sampling.hemisphere serve as the second estimator unchanged (the integrand lives in the same half-vector
measure). Both evaluate the texels of one (n.v, alpha) with eta >= 1, whose panels and phi-breakpoints are the same,
in groups of up to MEMBERS (make_adaptive_members, make_gauss_legendre_members; lutbake.sampling.groups): every node
and the integrand's eta-free part once, the rest per member, each member's value the bits of its own evaluation.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import warp as wp

from ..runtime.warp_runtime import kernel_factory, unique_kernel
from . import points
from .arrays import Levels, Rows64, Rule, store_row
from .facet_rules import OuterNode, facet_rules_for, members_of, outer_variable_for
from .groups import group_rows, key_of, siblings_by_key
from .hemisphere import GaussLegendre
from .hemisphere_kernels import TERMS_ROUNDING, _texels, load
from .horizon import PANEL_RATIO, PEAK_MERGE, PI64, asinh64, next_geometric, phi_b, texel_view
from .ladder import greedy_ladder_for
from .rules import gl_levels

ZERO64 = wp.constant(wp.float64(0.0))
ONE64 = wp.constant(wp.float64(1.0))
TWO64 = wp.constant(wp.float64(2.0))
HALF64 = wp.constant(wp.float64(0.5))
MERGE64 = wp.constant(wp.float64(PEAK_MERGE))
MAX_PANELS = 96  # outer panels per texel (a guard; grazing texels at the smallest alpha use ~30)
vec4d = wp.types.vector(length=4, dtype=wp.float64)
vec7d = wp.types.vector(length=7, dtype=wp.float64)


@wp.func
def next_theta_dielectric(
    t_lo: wp.float64,
    theta_a: wp.float64,
    theta_b: wp.float64,
    theta_peak: wp.float64,
    kinks: vec7d,
    merge: wp.float64,
):
    """Upper edge of the outer panel starting at t_lo: the smallest candidate above t_lo among the horizon grading
    (theta_a R^j below pi/4; pi/2 - (pi/2 - t_lo)/R up to theta_b), the kinks and the NDF-peak points
    theta_peak R^j; a peak point within a factor ``merge`` of the next other candidate or of t_lo is skipped (D is
    analytic there: a scale, not a kink; PEAK_MERGE to a tolerance, 1 at the fixed order, as
    lutbake.sampling.horizon.next_theta)."""
    quarter = PI64 * wp.float64(0.25)
    half = PI64 * wp.float64(0.5)
    tiny = wp.float64(1.0e-12) * (wp.float64(1.0) + t_lo)
    t = half
    if t_lo < quarter:
        c = wp.min(next_geometric(t_lo, theta_a), quarter)
    else:
        c = wp.min(half - (half - t_lo) / wp.float64(PANEL_RATIO), theta_b)
    if c > t_lo + tiny:
        t = wp.min(t, c)
    for k in range(7):
        if kinks[k] > t_lo + tiny:
            t = wp.min(t, kinks[k])
    if kinks[1] > wp.float64(0.0) and t_lo < quarter:  # view near the critical angle: phi_c varies on every scale
        c = wp.min(next_geometric(t_lo, kinks[1]), quarter)
        if c > t_lo + tiny:
            t = wp.min(t, c)
    tp = next_geometric(t_lo, theta_peak)
    if tp > t_lo + tiny and tp < t and tp * merge <= t and (t_lo <= ZERO64 or t_lo * merge <= tp):
        t = tp
    return t


@wp.func
def acos_clamped(x: wp.float64):
    return wp.acos(wp.clamp(x, wp.float64(-1.0), wp.float64(1.0)))


@wp.func
def sort4(b: vec4d):
    """Ascending sort of four values (insertion sort)."""
    for i in range(1, 4):
        j = i
        while j > 0 and b[j - 1] > b[j]:
            tmp = b[j - 1]
            b[j - 1] = b[j]
            b[j] = tmp
            j = j - 1
    return b


@wp.func
def phi_refraction_horizon(cos_v: wp.float64, sin_v: wp.float64, cos_h: wp.float64, eta: wp.float64):
    """phi_t (module docstring) at this theta_h; -1 where the refraction horizon does not cross this theta_h."""
    one = wp.float64(1.0)
    if sin_v <= wp.float64(1.0e-12) or cos_h <= wp.float64(0.0):
        return -one
    cp = (cos_v * cos_v / (cos_h * cos_h) - one - eta * eta) / (wp.float64(2.0) * eta * sin_v)
    if cp < -one or cp > one or sin_v * cp >= -eta:
        return -one
    sp = wp.sqrt(wp.max(one - cp * cp, wp.float64(0.0)))
    return wp.atan2(eta * sp, sin_v + eta * cp)


@wp.func
def dnot_dphi(
    cos_v: wp.float64, sin_v: wp.float64, cos_h: wp.float64, sin_h: wp.float64, phi: wp.float64, eta: wp.float64
):
    """|d(n.t)/dphi| at phi: n.t = (c/eta - cos theta_t) cos theta_h - mu/eta with c = v.h (module docstring)."""
    c = cos_v * cos_h + sin_v * sin_h * wp.cos(phi)
    ct = wp.sqrt(wp.max(wp.float64(1.0) - (wp.float64(1.0) - c * c) / (eta * eta), wp.float64(1.0e-300)))
    dc = sin_v * sin_h * wp.sin(phi)
    return wp.abs(dc * cos_h * (wp.float64(1.0) / eta - c / (eta * eta * ct)))


Edges = wp.types.vector(length=MAX_PANELS + 1, dtype=wp.float64)


@wp.struct
class DielectricTexel:
    """A texel's constants and its outer panels: edges[0 .. n_panels] in theta_h (next_theta_dielectric)."""

    v: wp.vec3
    a: float
    eta: float
    a64: wp.float64
    cos_v: wp.float64
    sin_v: wp.float64
    eps_l: wp.float64
    cos_c: wp.float64  # cos of the critical angle (eta < 1), else 0
    theta_peak: wp.float64
    n_panels: int
    edges: Edges


@wp.func
def dielectric_texel(t: wp.vec3, merge: wp.float64):
    """The texel (n.v, alpha, eta) with its kinks and outer panels (module docstring; ``merge``:
    next_theta_dielectric's); no panel at alpha = 0."""
    v, a, eta_f, a64, cos_v, sin_v, eps_l, theta_a, theta_b, theta_peak = texel_view(t)
    # v's float32 components are unit to ~1e-8 only: sin theta_v from n.v (the texel's) in float64, as the panel
    # rule's v.h (the critical angle's cone, 1 - cos theta_c = eta^2 / 2 wide in v.h, is that narrow at eta = 1e-4)
    sin_v = wp.sqrt(wp.max(ONE64 - cos_v * cos_v, ZERO64))
    eta = wp.float64(eta_f)
    half = PI64 * HALF64
    theta_v = wp.atan2(sin_v, cos_v)
    cos_c = ZERO64
    kinks = vec7d(TWO64 * theta_a, -ONE64, -ONE64, -ONE64, -ONE64, -ONE64, -ONE64)
    if eta < ONE64:
        cos_c = wp.sqrt(ONE64 - eta * eta)
        theta_c = wp.asin(eta)
        kinks[1] = wp.abs(theta_c - theta_v)
        kinks[2] = theta_v + theta_c
        kinks[3] = acos_clamped(cos_v / wp.sqrt(ONE64 + eta * eta + TWO64 * eta * sin_v))
        kinks[4] = acos_clamped(cos_v / wp.sqrt(wp.max(ONE64 + eta * eta - TWO64 * eta * sin_v, wp.float64(1.0e-300))))
        if cos_v < cos_c:  # phi_t meets phi_c: the horizon t with v.t = -eta
            kinks[5] = wp.acos(cos_v / cos_c)
        if cos_v < TWO64 * cos_c:  # phi_c meets phi_l: F's kink reaches the reflection horizon
            kinks[6] = wp.acos(cos_v / (TWO64 * cos_c))
    edges = Edges()
    t_lo = ZERO64
    if a <= 0.0:  # alpha -> 0: the closed-form mirror limit (lutbake.edge), no quadrature
        t_lo = half
    n_panels = wp.int32(0)  # a dynamic variable (a literal 0 is a constant to Warp)
    edges[0] = t_lo
    while t_lo < half:
        t_lo = next_theta_dielectric(t_lo, theta_a, theta_b, theta_peak, kinks, merge)
        if n_panels == MAX_PANELS - 1:  # never reached (MAX_PANELS): the last panel takes the rest, none is dropped
            t_lo = half
        n_panels += 1
        edges[n_panels] = t_lo
    return DielectricTexel(v, a, eta_f, a64, cos_v, sin_v, eps_l, cos_c, theta_peak, n_panels, edges)  # field order


@kernel_factory
def panel_rule_for(spec, members: int = 0):
    """``(panel_add, panel_sum)``: ``panel_add(x, j, rules, off, n, acc)`` adds the n x n product rule
    (rules[off : off + n] in both variables) over outer panel j of texel x to ``acc``, node by node (module
    docstring); ``panel_sum(x, j, rules, off, n)``: the same from 0 (the panel rule of lutbake.sampling.ladder).
    ``members`` > 0: acc is a lutbake.sampling.facet_rules.members_of record, every member's eta on x's panels."""
    acc_type = spec.acc if members == 0 else members_of(spec.acc._length_, members)
    d = spec.distribution
    outer_range, outer_node = outer_variable_for(d.tan2_from_u, d.u_from_tan2)
    add_facet, sinh_piece, _ = facet_rules_for(spec, members)

    @wp.func
    def panel_add(x: DielectricTexel, j: int, rules: Rule, off: int, n: int, acc: Any):
        cos_v = x.cos_v
        sin_v = x.sin_v
        cos_c = x.cos_c
        eta = wp.float64(x.eta)
        inside = eta < ONE64
        t_lo = x.edges[j]
        t_hi = x.edges[j + 1]
        in_u = t_hi <= x.theta_peak
        x_lo, dx = outer_range(t_lo, t_hi, in_u, x.a64)
        for k in range(n):
            s = rules[off + k][0]
            xs = x_lo + dx * s * s * (wp.float64(3.0) - TWO64 * s)  # smoothstep
            cos_h, sin_h, wk = outer_node(xs, rules[off + k][1] * dx * wp.float64(6.0) * s * (ONE64 - s), in_u, x.a64)
            f = OuterNode(x.v, x.a, x.eta, in_u, cos_h, sin_h, wk)
            # phi-breakpoints at this theta_h (module docstring)
            den = sin_v * sin_h
            phi_l = PI64
            phi_0 = PI64
            phi_c = PI64
            phi_t = -ONE64
            if den > wp.float64(1.0e-300):
                c_star = -cos_v * (cos_h * cos_h - sin_h * sin_h) / (TWO64 * den * cos_h)
                phi_l = acos_clamped(c_star)
                phi_0 = acos_clamped(-cos_v * cos_h / den)
                if inside:
                    phi_c = acos_clamped((cos_c - cos_v * cos_h) / den)
            else:  # normal view: v.h = cos(theta_h), n.l > 0 iff theta_h < pi/4, for every phi
                if cos_h * cos_h - sin_h * sin_h <= ZERO64:
                    phi_l = ZERO64
                if inside and cos_h <= cos_c:
                    phi_c = ZERO64
            if inside:
                phi_t = phi_refraction_horizon(cos_v, sin_v, cos_h, eta)
                if phi_t > phi_c:
                    phi_t = -ONE64
            phi_tr = phi_0
            if inside:
                phi_tr = phi_c
                if phi_t >= ZERO64:
                    phi_tr = phi_t
            phi_end = wp.max(phi_l, phi_tr)
            if phi_end <= ZERO64:
                continue
            brk = sort4(vec4d(phi_l, phi_0, phi_c, phi_t))
            p_lo = ZERO64
            for m in range(5):
                p_hi = phi_end
                if m < 4:
                    p_hi = wp.min(brk[m], phi_end)
                if p_hi <= p_lo + wp.float64(1.0e-14):
                    continue
                dp = p_hi - p_lo
                horizon_end = (p_hi == phi_l and phi_l < PI64) or (p_hi == phi_t)
                kink_lo = p_lo > ZERO64
                if horizon_end:
                    # sinh map (Johnston & Elliott 2005) towards p_hi: phi = p_hi - eps sinh(A (1 - y)); cos and sin
                    # of phi from those of p_hi (float64, once a piece) and of the distance to it (phi_b)
                    c_hi = wp.cos(p_hi)
                    s_hi = wp.sin(p_hi)
                    slope = TWO64 * cos_h * sin_v * sin_h * wp.max(s_hi, wp.float64(1.0e-12))
                    if p_hi == phi_t:
                        slope = wp.max(dnot_dphi(cos_v, sin_v, cos_h, sin_h, p_hi, eta), wp.float64(1.0e-12))
                    eps = wp.max(x.eps_l / slope, wp.float64(1.0e-12))
                    big_a = asinh64(dp / eps)
                    if kink_lo:  # y -> y^2 at the kink: the nodes are not symmetric, one exp each
                        for jj in range(n):
                            y = rules[off + jj][0]
                            ex = wp.exp(big_a * (ONE64 - y * y))
                            r = phi_b(ex, ONE64 / ex, eps, big_a, c_hi, s_hi)
                            acc = add_facet(acc, f, r[0], r[1], wk * rules[off + jj][1] * TWO64 * y * r[2])
                    else:  # the paired-exp sinh rule of the dfg panels
                        acc = sinh_piece(acc, f, c_hi, s_hi, eps, dp, rules, off, n)
                else:
                    # smoothstep: phi = p_lo + d, cos and sin of p_lo in float64 (once a piece), of d in float32
                    c_lo = wp.cos(p_lo)
                    s_lo = wp.sin(p_lo)
                    for jj in range(n):
                        y = rules[off + jj][0]
                        d = float(dp * y * y * (wp.float64(3.0) - TWO64 * y))
                        cd = wp.float64(wp.cos(d))
                        sd = wp.float64(wp.sin(d))
                        w = wk * rules[off + jj][1] * dp * wp.float64(6.0) * y * (ONE64 - y)
                        acc = add_facet(acc, f, c_lo * cd - s_lo * sd, s_lo * cd + c_lo * sd, w)
                p_lo = p_hi
        return acc

    @wp.func
    def panel_sum(x: DielectricTexel, j: int, rules: Rule, off: int, n: int):
        return panel_add(x, j, rules, off, n, acc_type())

    return panel_add, panel_sum


def make_gauss_legendre_dielectric(spec):
    """The fixed-order kernel (module docstring) for an integrand record
    (lutbake.integrands.dielectric.dielectric_integrand): texel (n.v, alpha, eta), rule (GL (node, weight) on [0, 1],
    both variables), out; every panel's nodes summed into one accumulator, in order."""
    acc_type, mirror = spec.acc, spec.mirror
    panel_add = panel_rule_for(spec)[0]
    nch = spec.vec._length_

    @unique_kernel
    def gauss_legendre_dielectric_kernel(texel: wp.array(dtype=wp.vec3), rule: Rule, merge: wp.float64, out: Rows64):
        i = wp.tid()
        x = dielectric_texel(texel[i], merge)
        acc = acc_type()
        for j in range(x.n_panels):
            acc = panel_add(x, j, rule, 0, rule.shape[0], acc)
        for c in range(wp.static(nch)):
            out[i, c] = acc[c] / PI64
        if x.a <= 0.0:  # the mirror limit (lutbake.edge)
            store_row(out, i, mirror(x.v, x.eta))

    return gauss_legendre_dielectric_kernel


def make_gauss_legendre_members(spec):
    """make_gauss_legendre_dielectric for groups of up to MEMBERS texels that differ only in eta >= 1 (member_groups,
    make_adaptive_members): every node once for all members, the same bits. Inputs: texel, groups, rule, merge,
    out."""
    nch = spec.acc._length_
    member_params = member_params_for(nch)
    panel_add = panel_rule_for(spec, MEMBERS)[0]

    @unique_kernel
    def gauss_legendre_members_kernel(
        texel: wp.array(dtype=wp.vec3), groups: wp.array2d(dtype=int), rule: Rule, merge: wp.float64, out: Rows64
    ):
        g = wp.tid()
        x = dielectric_texel(texel[groups[g, 0]], merge)
        acc, count = member_params(texel, groups, g)
        for j in range(x.n_panels):
            acc = panel_add(x, j, rule, 0, rule.shape[0], acc)
        for k in range(count):
            for c in range(wp.static(nch)):
                out[groups[g, k], c] = acc[k, c] / PI64

    return gauss_legendre_members_kernel


@kernel_factory
def texel_store_for(spec):
    """``store_texel(x, i, total, e, out, err)``: texel i's values (total / pi, or the mirror limit at alpha = 0) and
    estimates (e / pi plus TERMS_ROUNDING |value|) of the kernels to a tolerance."""
    mirror = spec.mirror
    nch = spec.vec._length_

    @wp.func
    def store_texel(x: DielectricTexel, i: int, total: Any, e: Any, out: Rows64, err: Rows64):
        for c in range(wp.static(nch)):
            out[i, c] = total[c] / PI64
        if x.a <= 0.0:  # the mirror limit (lutbake.edge)
            store_row(out, i, mirror(x.v, x.eta))
        for c in range(wp.static(nch)):
            err[i, c] = e[c] / PI64 + TERMS_ROUNDING * wp.abs(out[i, c])

    return store_texel


def make_adaptive_dielectric(spec):
    """The kernel to a tolerance: the outer panels of the fixed-order kernel (with the peak merge) up the GL orders
    ``levels``, refined greedily (lutbake.sampling.ladder.greedy_ladder_for) until, per channel c, the estimate
    err = sum over panels of |Q_(k) - Q_(k-1)| / pi + TERMS_ROUNDING |I_c| (float32 terms, as
    lutbake.sampling.hemisphere_kernels.make_gauss_legendre) is within max(tol_abs[c], tol_rel[c] |I_c|). Inputs: texel,
    rules, levels (lutbake.sampling.rules.gl_levels), tol_abs, tol_rel (vec3d: per kernel channel), out, err."""
    integrate = greedy_ladder_for(panel_rule_for(spec)[1], MAX_PANELS, spec.acc._length_)[0]
    store_texel = texel_store_for(spec)

    @unique_kernel
    def adaptive_dielectric_kernel(
        texel: wp.array(dtype=wp.vec3),
        rules: Rule,
        levels: Levels,
        tol_abs: wp.vec3d,
        tol_rel: wp.vec3d,
        out: Rows64,
        err: Rows64,
    ):
        i = wp.tid()
        x = dielectric_texel(texel[i], MERGE64)
        # the estimate, TERMS_ROUNDING included, within the tolerance (in units of the sum: I = sum / pi)
        total, e = integrate(x, x.n_panels, rules, levels, PI64 * tol_abs, tol_rel, TERMS_ROUNDING)
        store_texel(x, i, total, e, out, err)

    return adaptive_dielectric_kernel


# texels sharing one first pass (make_adaptive_members): EEVEE btdf's 64 IOR columns of a (n.v, alpha) row in 4 groups
MEMBERS = 16


@kernel_factory
def member_params_for(nch: int):
    """``member_params(texel, groups, g) -> (acc, count)``: group g's accumulator (members_of), zero sums and row k's
    param the eta of member k (of the first member in an unused row), and its member count."""
    shared = members_of(nch, MEMBERS)

    @wp.func
    def member_params(texel: wp.array(dtype=wp.vec3), groups: wp.array2d(dtype=int), g: int):
        acc = shared()
        count = wp.int32(0)  # dynamic (a literal is a constant to Warp)
        for k in range(MEMBERS):
            i = groups[g, 0]
            if groups[g, k] >= 0:
                i = groups[g, k]
                count = k + 1
            acc[k, nch] = wp.float64(texel[i][2])
        return acc, count

    return member_params


def make_adaptive_members(spec):
    """make_adaptive_dielectric for groups of up to MEMBERS texels that differ only in eta >= 1: their outer panels
    and phi-breakpoints depend on (n.v, alpha) alone (module docstring: the TIR and refraction-horizon cuts exist for
    eta < 1 only), so one pass over the nodes of the first two levels serves every member (the facet, v.h, D, the
    weights: lutbake.sampling.facet_rules.facet_rules_for with ``members``), each member's sums taking the same float
    operations in the same order as its own kernel's; each member then climbs alone (lutbake.sampling.ladder's climb).
    The same bits as make_adaptive_dielectric. Inputs: texel, groups (rows of texel indices, -1 padded), rules, levels,
    tol_abs, tol_rel, first (scratch: (groups x MEMBERS, MAX_PANELS, 2, channels) float64), out, err."""
    nch = spec.acc._length_
    member_params = member_params_for(nch)
    panel_add = panel_rule_for(spec, MEMBERS)[0]
    _, climb, Panels, _, Orders = greedy_ladder_for(panel_rule_for(spec)[1], MAX_PANELS, nch)
    store_texel = texel_store_for(spec)

    @unique_kernel
    def adaptive_members_kernel(
        texel: wp.array(dtype=wp.vec3),
        groups: wp.array2d(dtype=int),
        rules: Rule,
        levels: Levels,
        tol_abs: wp.vec3d,
        tol_rel: wp.vec3d,
        first: wp.array4d(dtype=wp.float64),
        out: Rows64,
        err: Rows64,
    ):
        g = wp.tid()
        x = dielectric_texel(texel[groups[g, 0]], MERGE64)
        base, count = member_params(texel, groups, g)
        for j in range(x.n_panels):
            for lv in range(2):  # the ladder's first two levels, as its integrate
                acc = panel_add(x, j, rules, levels[lv][0], levels[lv][1], base)
                for k in range(count):
                    for c in range(wp.static(nch)):
                        first[g * MEMBERS + k, j, lv, c] = acc[k, c]
        for k in range(count):
            i = groups[g, k]
            y = dielectric_texel(texel[i], MERGE64)
            fine0 = Panels()
            coarse0 = Panels()
            lev = Orders()
            for j in range(y.n_panels):
                for c in range(wp.static(nch)):
                    fine0[j, c] = first[g * MEMBERS + k, j, 1, c]
                    coarse0[j, c] = first[g * MEMBERS + k, j, 0, c]
                lev[j] = 1
            total, e = climb(y, y.n_panels, rules, levels, PI64 * tol_abs, tol_rel, TERMS_ROUNDING, fine0, coarse0, lev)
            store_texel(y, i, total, e, out, err)

    return adaptive_members_kernel


def shareable_texels(texel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(key, shareable) of texels (n, 3) float32 (n.v, alpha, eta) for lutbake.sampling.groups: the texels of one
    (n.v, alpha) with alpha > 0 and eta >= 1 share their panels and nodes (make_adaptive_members)."""
    return key_of(texel[:, 0], texel[:, 1]), (texel[:, 2] >= np.float32(1.0)) & (texel[:, 1] > np.float32(0.0))


def member_groups(texel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(groups of up to MEMBERS, singles) of texels (n, 3) float32 (n.v, alpha, eta) (lutbake.sampling.groups)."""
    return group_rows(*shareable_texels(texel), MEMBERS)


def sibling_tiles(inputs: dict):
    """``siblings(start, stop)`` of lutbake.sampling.plan.per_texel_plan for a dielectric grid (inputs nov, alpha,
    param; lutbake.sampling.groups.siblings_by_key): a CPU tile within one IOR slice, as Turquin's and OpenPBR's 3D
    tables (IOR the slowest axis) are cut, is evaluated with the same texels of every eta >= 1 slice."""
    texel = np.stack([np.asarray(inputs[k], dtype=np.float32) for k in ("nov", "alpha", "param")], axis=1)
    return siblings_by_key(*shareable_texels(texel))


GROUP_BATCH = 64  # member groups per launch (bounds the adaptive kernel's first-pass scratch: 4.7 MB)


def launch_by_groups(inputs: dict, nch: int, n_out: int, members: tuple | None, single: tuple, device: str) -> list:
    """``n_out`` float64 arrays (texels, nch) of the texels (n.v, alpha, eta) of ``inputs``: member_groups' groups by
    ``members`` = (kernel, args, scratch(groups) -> list of extra arrays) (inputs: texel, groups, args, scratch, the
    outputs indexed by texel), the other texels by ``single`` = (kernel, args) (inputs: their texels, args, outputs);
    ``members`` None: every texel by ``single``."""
    n, texel = _texels(inputs, device)
    host = texel.numpy()
    groups, singles = member_groups(host) if members else (np.zeros((0, MEMBERS), np.int32), np.arange(n))
    outs = [np.zeros((n, nch)) for _ in range(n_out)]
    s_kernel, s_args = single
    if len(groups):
        m_kernel, m_args, scratch = members
        arrs = [wp.zeros((n, nch), dtype=wp.float64, device=device) for _ in range(n_out)]
        for b in range(0, len(groups), GROUP_BATCH):
            batch = groups[b : b + GROUP_BATCH]
            rows = wp.array(batch, dtype=int, device=device)
            args = [texel, rows, *m_args, *scratch(len(batch)), *arrs]
            wp.launch(m_kernel, dim=len(batch), inputs=args, device=device)
        member = groups[groups >= 0]
        for o, a in zip(outs, arrs):
            o[member] = a.numpy()[member]
    if len(singles):
        arrs = [wp.zeros((len(singles), nch), dtype=wp.float64, device=device) for _ in range(n_out)]
        sub = wp.array(host[singles], dtype=wp.vec3, device=device)
        wp.launch(s_kernel, dim=len(singles), inputs=[sub, *s_args, *arrs], device=device)
        for o, a in zip(outs, arrs):
            o[singles] = a.numpy()
    return outs


# the kernel factories, each cached by its spec (one compiled kernel per spec)
gl_dielectric_kernel = functools.lru_cache(maxsize=None)(make_gauss_legendre_dielectric)
gl_members_kernel = functools.lru_cache(maxsize=None)(make_gauss_legendre_members)
adaptive_dielectric_kernel = functools.lru_cache(maxsize=None)(make_adaptive_dielectric)
adaptive_members_kernel = functools.lru_cache(maxsize=None)(make_adaptive_members)


@dataclass(frozen=True)
class DielectricGaussLegendre(GaussLegendre):
    """The ``gauss_legendre`` estimator of the dielectric kinds (lutbake.sampling.hemisphere.GaussLegendre with this
    module's kernel): order n = gl_order(budget) per panel in both variables; the panel count varies per texel.
    ``merged``: the NDF-peak breakpoints merged as the adaptive kernel's (PEAK_MERGE: kind dielectric_avg's inner
    rule, whose error its probe measures); else every breakpoint (a fixed-order table's pixels as before the merge)."""

    merged: bool = False
    members: bool = True  # texels that differ only in eta >= 1 in groups (False: a grid without any; no such kernel)

    def _kernel(self, integrand):
        return gl_dielectric_kernel(integrand)

    def prepare(self, integrand, device: str) -> None:
        load(self._kernel(integrand), device)
        if self.members:
            load(gl_members_kernel(integrand), device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        """The texels that differ only in eta >= 1 in groups (make_gauss_legendre_members), the others one by one:
        the same bits either way."""
        rule = wp.array(np.stack(points.gauss_legendre(self.order), axis=1), dtype=wp.vec2d, device=device)
        args = [rule, MERGE64 if self.merged else ONE64]
        members = (gl_members_kernel(integrand), args, lambda b: []) if self.members else None
        single = (self._kernel(integrand), args)
        (out,) = launch_by_groups(inputs, integrand.kernel_channels, 1, members, single, device)
        return out


# the ladder's orders, from 8 in steps of 8 (2x first). Close first orders agreed by coincidence where the convergence
# stagnates (measured against order 64 on 3005 random + edge texels: at (n.v, alpha, eta) = (0.24, 0.042, 0.49) order 8
# is off by 9e-7, order 12 by 6e-7; error / estimate up to 10.6 from (8, 10), 2.2 from (8, 12), 1.3 from (6, 8)), and
# (6, 12) on EEVEE's btdf grazing row (n.v = 1e-4, alpha = 0.071, eta = 1.063: error 1.12e-6 under an estimate of
# 8.4e-7, its transmission channel alone driving the ladder); from (8, 16) every estimate bounds the error there
# (tests/test_dielectric.py), at ~10 % more work than from (6, 12). The first climb is 16 -> 20 (was 24): replayed
# offline on every panel's orders 6..64 (benchmarks/replay_ladder.py: 2500 random texels and the grazing row of each of
# EEVEE's btdf and bsdf, Turquin's and OpenPBR's tables) 7-9 % fewer evaluations, worst error / estimate 0.90 (from
# 16 -> 24: 0.43); 8 -> 14 saved 14-22 % but reached 0.97, and 8 -> 12 passed errors over their estimates (2.2)
# Tried 2026-12-02 (night) and dropped: from (6, 11) with twice the first difference as the first estimate, 0.73-0.79x
# the evaluations in the replay (no violation among its 1500 random texels per preset), but benchmarks/
# bench_dielectric.py's sample of a 32^3 table found a texel, (n.v, alpha, eta) = (0.172, 0.041, 0.435), where orders 6
# and 11 of one panel agree to 9.6e-8 while order 11 is 1.5e-6 off: error 1.5e-6 under an estimate of 8.3e-7
# Tried 2026-12-03 and dropped: from the Gauss-Kronrod pair (5, 11) (DielectricAdaptive.kronrod: a panel's first
# value the 11-node Kronrod rule's, its estimate |K_11 - G_5|; 25 + 121 evaluations against 64 + 256). Replayed on 6000
# random texels plus the grazing row of each glass preset (benchmarks/replay_ladder.py --glass 6000 1): 0.77-0.82x
# the evaluations, no texel past its estimate. But over whole tables (benchmarks/check_glass_ladder.py: every texel
# against this ladder at tolerance / 100) 13 texels were, 12 of EEVEE's bsdf (8 of them at its clamp eta = 1e-4, errors
# <= 1.5e-12) and 1 of OpenPBR's, among them (n.v, alpha, eta) = (0.5599, 0.2844, 0.4714) of EEVEE's bsdf, 1.35e-6 off
# under an estimate of 8.0e-7 (over the tolerance itself); and the kernel time fell only to 0.83-0.89x (EEVEE's btdf
# 1.20x)
DIELECTRIC_ORDERS = (8, 16, 20, 24, 32, 48, 64)


@dataclass(frozen=True)
class DielectricAdaptive:
    """``gauss_legendre`` to a tolerance (make_adaptive_dielectric): ``absolute`` / ``relative`` per kernel channel
    (a tuple of kernel_channels; lutbake.kinds.dielectric maps a table's tolerance onto them). ``evaluate_with_error``
    also returns each texel's error estimate per kernel channel."""

    absolute: tuple[float, ...]
    relative: tuple[float, ...]
    orders: tuple[int, ...] = DIELECTRIC_ORDERS
    kronrod: bool = False  # orders[:2] a Gauss-Kronrod pair (n, 2n + 1): measured, not honest (DIELECTRIC_ORDERS)
    name: str = "gauss_legendre"
    members: bool = True  # texels that differ only in eta >= 1 in groups (False: a grid without any; no such kernel)

    def samples(self, inputs: dict) -> np.ndarray:  # nominal: 3 panels at the first two orders (the work adapts)
        return np.full(len(inputs["nov"]), 3 * sum(n * n for n in self.orders[:2]))

    def prepare(self, integrand, device: str) -> None:
        load(adaptive_dielectric_kernel(integrand), device)
        if self.members:
            load(adaptive_members_kernel(integrand), device)

    def evaluate_with_error(self, integrand, inputs: dict, device: str) -> tuple[np.ndarray, np.ndarray]:
        """Values and estimates (n, kernel channels) each: the texels that share their (n.v, alpha) at eta >= 1 in
        groups (make_adaptive_members), the others one by one (make_adaptive_dielectric): the same bits either way."""
        assert len(self.orders) >= 2, "the ladder needs two orders for its first estimate"
        rules, levels = gl_levels(tuple(self.orders), self.kronrod)
        nch = integrand.kernel_channels
        args = [
            wp.array(rules, dtype=wp.vec2d, device=device),
            wp.array(levels, dtype=wp.vec2i, device=device),
            wp.vec3d(*self.absolute),
            wp.vec3d(*self.relative),
        ]

        def scratch(n_groups: int) -> list:
            return [wp.empty((n_groups * MEMBERS, MAX_PANELS, 2, nch), dtype=wp.float64, device=device)]

        members = (adaptive_members_kernel(integrand), args, scratch) if self.members else None
        out, err = launch_by_groups(inputs, nch, 2, members, (adaptive_dielectric_kernel(integrand), args), device)
        return out, err

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        return self.evaluate_with_error(integrand, inputs, device)[0]

    def refined(self):
        scaled = (tuple(t / 100 for t in self.absolute), tuple(t / 100 for t in self.relative))
        return replace(self, absolute=scaled[0], relative=scaled[1]), "tolerance / 100"
