"""The panel rules of the hemisphere integrals' Gauss-Legendre kernels (lutbake.sampling.hemisphere_kernels), as
``@wp.func`` factories cached by their integrand record: the outer variable (the NDF's CDF u = CDF(theta_h) inside
the NDF peak, theta_h beyond: outer_variable_for), the weight g / p (over_pdf_for, facet_weight_for), the inner rules
in phi over region A and B (facet_rules_for: the sinh map at the horizon cut, the plain rule away from it) and a
panel's product rule (panel_rule_for). Shared with the dielectric kernels (lutbake.sampling.dielectric)."""

from __future__ import annotations

from typing import Any

import warp as wp

from ..runtime.warp_runtime import kernel_factory
from .arrays import Rule
from .horizon import PI64, PanelTexel, asinh64, kink_cos_phi, phi_b


@wp.struct
class OuterNode:
    """An outer node of a panel's product rule (panel_rule_for): the texel's view, alpha, param, whether the outer
    variable is the NDF's CDF (the weight is g / p), theta_h and the node's weight."""

    v: wp.vec3
    a: float
    prm: float
    in_u: wp.bool
    cos_h: wp.float64
    sin_h: wp.float64
    wk: wp.float64


@kernel_factory
def outer_variable_for(tan2_from_u, u_from_tan2):
    """The outer variable of the Gauss-Legendre kernels: u = CDF(theta_h) on panels inside the NDF peak (``in_u``),
    theta_h itself beyond. ``outer_range(t_lo, t_hi, in_u, alpha) -> (x_lo, dx)``; ``outer_node(x, w, in_u, alpha)
    -> (cos theta_h, sin theta_h, w)`` with the theta_h weight times 2 pi sin(theta_h) (du = 2 pi D cos sin dtheta,
    and g / p = g / (D cos))."""

    @wp.func
    def outer_range(t_lo: wp.float64, t_hi: wp.float64, in_u: bool, a64: wp.float64):
        if in_u:
            x_lo = u_from_tan2(wp.tan(t_lo) * wp.tan(t_lo), a64)
            return x_lo, u_from_tan2(wp.tan(t_hi) * wp.tan(t_hi), a64) - x_lo
        return t_lo, t_hi - t_lo

    @wp.func
    def outer_node(x: wp.float64, w: wp.float64, in_u: bool, a64: wp.float64):
        if in_u:
            tan2 = tan2_from_u(x, a64)
            c = wp.float64(1.0) / wp.sqrt(wp.float64(1.0) + tan2)
            return c, wp.sqrt(tan2) * c, w
        sin_h = wp.sin(x)
        return wp.cos(x), sin_h, w * wp.float64(2.0) * PI64 * sin_h

    return outer_range, outer_node


@kernel_factory
def over_pdf_for(pdf):
    """``over_pdf(g, v, h, alpha, in_u)``: g / p(h) where the outer variable is the NDF's CDF u (D cancels; 0 where
    p = 0), g where it is theta_h itself."""

    @wp.func
    def over_pdf(g: Any, v: wp.vec3, h: wp.vec3, a: float, in_u: bool):
        p = wp.float32(0.0)  # dynamic (a literal is a constant to Warp)
        if in_u:
            p = pdf(v, h, a)
        return over_p(g, p, in_u)

    return over_pdf


@wp.func
def over_p(g: Any, p: float, in_u: bool):
    """over_pdf_for's g / p given p (0 where p = 0; g where the outer variable is theta_h)."""
    if in_u:
        if p > 0.0:
            return g / p
        return g * 0.0
    return g


@kernel_factory
def facet_weight_for(integrand, pdf):
    """``facet_weight(v, h, alpha, param, in_u)``: g(h) / p(h) (over_pdf_for)."""
    over_pdf = over_pdf_for(pdf)

    @wp.func
    def facet_weight(v: wp.vec3, h: wp.vec3, a: float, prm: float, in_u: bool):
        return over_pdf(integrand(v, h, a, prm), v, h, a, in_u)

    return facet_weight


UNROLL = 4  # members per unrolled block of a members rule (facet_rules_for); members_of's size is a multiple


@kernel_factory
def members_of(nch: int, size: int):
    """The accumulator of ``size`` texels that share every node of their panel rules and differ only in the
    integrand's param (the dielectric tables' eta >= 1 at one (n.v, alpha): lutbake.sampling.dielectric): a float64
    matrix, row k member k, columns 0 .. nch - 1 its sums and column nch its param (a float32, exact in float64). A
    plain matrix, not a struct: Warp updates a local matrix in place, while a struct's matrix field is loaded whole
    for every element read (measured 2.5x the time of the single-texel rule)."""
    return wp.types.matrix(shape=(size, nch + 1), dtype=wp.float64)


@kernel_factory
def facet_rules_for(spec, members: int = 0):
    """``(add_facet, sinh_piece, plain_piece)``: the inner rule's pieces for an integrand record (the panel rules of
    this module and of lutbake.sampling.dielectric). ``add_facet(acc, f, cos phi, sin phi, w)`` adds w g / p at the
    facet (theta_h of the OuterNode f, phi); ``sinh_piece`` adds the rule over [phimax - width, phimax] by the sinh
    map, ``plain_piece`` the plain rule over [0, width]. ``members`` > 0 (an integrand with g64_parts): acc is a
    ``members_of(nch, members)`` matrix and each node's facet, v.h, weight, density and param-free part serve every
    member's param, each member's sum taking the same float operations, in the same order, as its own rule's."""
    facet_weight = facet_weight_for(spec.g, spec.distribution.pdf_ndf)
    pdf = spec.distribution.pdf_ndf
    over_pdf, g64, g_sin2 = over_pdf_for(pdf), spec.g64, spec.g_sin2
    part, rest = spec.g64_parts if members > 0 else (None, None)
    nch = spec.vec._length_

    @wp.func
    def facet_voh(f: OuterNode, cos_phi: wp.float64, sin_phi: wp.float64):
        """v.h in float64 from the node's float64 angles and v = (sqrt(1 - (n.v)^2), 0, n.v) (unit)."""
        v2 = wp.float64(f.v[2])
        v0 = wp.sqrt(wp.max(wp.float64(1.0) - v2 * v2, wp.float64(0.0)))
        return f.sin_h * cos_phi * v0 + f.cos_h * v2

    @wp.func
    def add_facet(acc: Any, f: OuterNode, cos_phi: wp.float64, sin_phi: wp.float64, w: wp.float64):
        """acc plus w g / p at the facet (theta_h of the outer node f, phi); an integrand with g64 gets v.h from
        facet_voh, one with g_sin2 (a Charlie lobe) sin^2(theta_h) from the node's float64 sin(theta_h)."""
        h = wp.vec3(float(f.sin_h * cos_phi), float(f.sin_h * sin_phi), float(f.cos_h))
        if wp.static(members > 0):
            # the param-free part and the density once a node (over_pdf's operations, in two steps)
            voh = facet_voh(f, cos_phi, sin_phi)
            shared = part(f.v, h, f.a, voh)
            p = wp.float32(0.0)
            if f.in_u:
                p = pdf(f.v, h, f.a)
            # members in blocks of UNROLL: a loop of unrolled blocks (16 unrolled copies of the integrand took 2x the
            # compile time, a plain loop 1.3x the run time)
            for k0 in range(wp.int32(members // UNROLL)):
                for kk in range(wp.static(UNROLL)):
                    k = k0 * UNROLL + kk
                    gk = over_p(rest(shared, f.v, h, f.a, float(acc[k, nch]), voh), p, f.in_u)
                    for c in range(wp.static(nch)):
                        acc[k, c] = acc[k, c] + w * wp.float64(gk[c])
        else:
            if wp.static(g64 is not None):
                gw = over_pdf(g64(f.v, h, f.a, f.prm, facet_voh(f, cos_phi, sin_phi)), f.v, h, f.a, f.in_u)
            elif wp.static(g_sin2 is not None):  # a Charlie lobe: sin^(1/alpha) of the node's float64 sin(theta_h)
                gw = over_pdf(g_sin2(f.v, h, f.a, f.prm, f.sin_h * f.sin_h), f.v, h, f.a, f.in_u)
            else:
                gw = facet_weight(f.v, h, f.a, f.prm, f.in_u)
            for c in range(wp.static(nch)):
                acc[c] = acc[c] + w * wp.float64(gw[c])
        return acc

    @wp.func
    def sinh_piece(
        acc: Any,
        f: OuterNode,
        c_star: wp.float64,
        s_star: wp.float64,
        eps: wp.float64,
        width: wp.float64,
        rules: Rule,
        off: int,
        n: int,
    ):
        """acc plus the inner rule over phi in [phimax - width, phimax] (cos, sin of phimax: c_star, s_star) by the
        sinh map (Johnston & Elliott 2005) phi = phimax - eps sinh(A (1 - x)), A = asinh(width / eps), which
        clusters the nodes at phimax on the scale eps."""
        one = wp.float64(1.0)
        big_a = asinh64(width / eps)
        # the GL nodes pair up, x_(n-1-j) = 1 - x_j, so the pair's e^(big_a (1 - x)) are ex and e^big_a / ex: one exp
        # per pair
        e_a = wp.exp(big_a)
        inv_e_a = one / e_a
        for j in range((n + 1) // 2):
            ex = wp.exp(big_a * (one - rules[off + j][0]))
            inv_ex = one / ex
            r = phi_b(ex, inv_ex, eps, big_a, c_star, s_star)
            acc = add_facet(acc, f, r[0], r[1], f.wk * rules[off + j][1] * r[2])
            if n - 1 - j > j:
                r = phi_b(e_a * inv_ex, ex * inv_e_a, eps, big_a, c_star, s_star)
                acc = add_facet(acc, f, r[0], r[1], f.wk * rules[off + n - 1 - j][1] * r[2])
        return acc

    @wp.func
    def plain_piece(acc: Any, f: OuterNode, width: wp.float64, rules: Rule, off: int, n: int):
        """acc plus the plain inner rule over phi in [0, width] (the side of a kink away from the horizon)."""
        for j in range(n):
            phi = width * rules[off + j][0]
            acc = add_facet(acc, f, wp.float64(wp.cos(phi)), wp.float64(wp.sin(phi)), f.wk * rules[off + j][1] * width)
        return acc

    return add_facet, sinh_piece, plain_piece


@kernel_factory
def panel_rule_for(spec):
    """``panel_of(t, j, rules, off, n, off_i, n_i)`` of make_gauss_legendre's ladder for an integrand record: the
    product of the outer rule rules[off : off + n] and the inner rules[off_i : off_i + n_i] over panel j of texel t
    (a PanelTexel of panel_texel; also used by benchmarks/replay_ladder.py, which integrates every panel at every
    order)."""
    acc_type = spec.acc
    outer_range, outer_node = outer_variable_for(spec.distribution.tan2_from_u, spec.distribution.u_from_tan2)
    add_facet, sinh_piece, plain_piece = facet_rules_for(spec)
    kinked = spec.nol_kink is not None or spec.kink_at_nov

    @wp.func
    def panel_sum(
        t: PanelTexel, t_lo: wp.float64, t_hi: wp.float64, rules: Rule, off: int, n: int, off_i: int, n_i: int
    ):
        """The product of the outer rule rules[off : off + n] and the inner rule rules[off_i : off_i + n_i] over the
        panel [t_lo, t_hi] of texel t: the sum of w g / p. Region A's inner nodes are the same for every texel:
        ``t.phi_a[off_i + j]`` holds them (phi_rule_a). Inside
        the kink band (kink_band) the inner domain splits at phi_k (n.l = kink): a plain rule over [0, phi_k], the
        sinh map over [phi_k, phimax]; the band's ends are panel ends, where phi_k has sqrt-like ends as phimax."""
        one = wp.float64(1.0)
        two = wp.float64(2.0)
        v = t.v
        a = t.a
        prm = t.prm
        a64 = wp.float64(a)
        cos_v = wp.float64(v[2])
        sin_v = wp.float64(v[0])
        acc = acc_type()
        in_b = t_lo >= t.theta_a
        in_u = t_hi <= t.theta_peak and wp.static(spec.ndf_peak)
        ends = in_b  # smoothstep the outer variable
        if wp.static(not spec.ndf_peak):  # sin(theta_h)^(1/alpha) at the pole: theta^(1/alpha), graded by smoothstep
            ends = in_b or t_lo <= wp.float64(0.0)
        in_k = False
        if wp.static(kinked):
            in_k = t_lo >= t.theta_klo and t_hi <= t.theta_khi and t.theta_klo >= wp.float64(0.0)
        x_lo, dx = outer_range(t_lo, t_hi, in_u, a64)
        for k in range(n):
            s = rules[off + k][0]
            x = x_lo + dx * s
            wk = rules[off + k][1] * dx
            if ends or in_k:  # smoothstep: removes the sqrt-like ends of acos(c*) at c* = +-1 (and of phi_k)
                x = x_lo + dx * s * s * (wp.float64(3.0) - two * s)
                wk = rules[off + k][1] * dx * wp.float64(6.0) * s * (one - s)
            cos_h, sin_h, wk = outer_node(x, wk, in_u, a64)
            f = OuterNode(v, a, prm, in_u, cos_h, sin_h, wk)
            phi_k = wp.float64(0.0)
            if wp.static(kinked):
                if in_k:
                    phi_k = wp.acos(wp.clamp(kink_cos_phi(t.kink, cos_v, sin_v, cos_h, sin_h), -one, one))
            if in_b:
                # c* = -cos(theta_v) cos(2 theta_h) / (sin(theta_v) sin(2 theta_h)) = cos(phimax)
                c_star = wp.clamp(-cos_v * (cos_h * cos_h - sin_h * sin_h) / (sin_v * two * sin_h * cos_h), -one, one)
                s_star = wp.sqrt(one - c_star * c_star)  # sin(phimax)
                phimax = wp.acos(c_star)
                # n.l = 2 (n.h) sin(theta_v) sin(theta_h) (cos(phi) - c*): G2's pole at n.l = -eps_l
                # lies eps_l / slope beyond phimax
                slope = two * cos_h * sin_v * sin_h * wp.max(s_star, wp.float64(1.0e-12))
                eps = wp.max(t.eps_l / slope, wp.float64(1.0e-12))
                acc = sinh_piece(acc, f, c_star, s_star, eps, phimax - phi_k, rules, off_i, n_i)
                if wp.static(kinked):
                    if in_k:
                        acc = plain_piece(acc, f, phi_k, rules, off_i, n_i)
            elif in_k:  # region A with the kink: phi_a's map (phimax = eps = pi) over [phi_k, pi], plain below
                acc = sinh_piece(acc, f, -one, wp.float64(0.0), PI64, PI64 - phi_k, rules, off_i, n_i)
                acc = plain_piece(acc, f, phi_k, rules, off_i, n_i)
            else:
                for j in range(n_i):
                    r = t.phi_a[off_i + j]  # (cos phi, sin phi, weight): phi over [0, pi], the same for every texel
                    acc = add_facet(acc, f, r[0], r[1], wk * r[2])
        return acc

    @wp.func
    def panel_of(t: PanelTexel, j: int, rules: Rule, off: int, n: int, off_i: int, n_i: int):
        """Panel j of texel t by the outer rule rules[off : off + n] and the inner rules[off_i : off_i + n_i] (the
        ladder's panel rule, lutbake.sampling.ladder.product_ladder_for)."""
        return panel_sum(t, t.edges[j], t.edges[j + 1], rules, off, n, off_i, n_i)

    return panel_of
