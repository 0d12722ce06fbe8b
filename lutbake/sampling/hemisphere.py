"""Kernel factories: integrate a per-texel hemisphere integral with a chosen estimator.

The integral, for a texel with view cosine n.v and NDF alpha, is written over the microfacet
normal h (dω_l = 4 (v.h) dω_h, Walter et al. 2007, Eq. 14):

    I = ∫ f(l, v) (n.l) dω_l = ∫ g(h) dω_h,        g(h) = f(l(h), v) (n.l) 4 (v.h),   l = reflect(v, h)

``integrand(v, h, alpha, param) -> vec`` returns g(h) for every channel (0 where n.l <= 0); ``param`` is a
per-texel scalar the integrand may use (f0 for specular_3d; ignored by the others). Sampling h with
the NDF's density p(h) = D(h)(n.h) gives I = E[g / p]; for a microfacet BRDF D cancels and the
per-sample weight is G2 F (v.h) / ((n.v)(n.h)).

Estimators (``GaussLegendre``, ``QuasiMonteCarlo``: objects of the lutbake.sampling.plan protocol; their
kernels come from ``make_gauss_legendre`` / ``make_qmc``, which close over an integrand record of
lutbake.integrands.specular):

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
    towards pi/4, and each panel is integrated in u = CDF(theta). The sqrt-like ends of acos c* at c* = -1 and 1
    are removed by u = u0 + du smoothstep(s).
    By symmetry in phi,
        I = (1/pi) ∫_0^1 du ∫_0^phimax(u) dphi  g(h) / p(h).
    The integrand is then analytic in both variables and GL converges exponentially. An integrand only C1 along
    n.l = kink (SpecularIntegrand.nol_kink: Charlie's Lambda; kink_at_nov: n.l = n.v, Ashikhmin-Shirley's
    max(n.l, n.v), whose level line passes through h = n at phi = pi/2) gets the same treatment for that level line
    (kink_band, kink_cos_phi); a Charlie lobe's panels also grade towards theta_b (next_toward).
``sobol_ndf`` / ``hammersley_ndf``  h from the NDF's inverse CDF (Distribution.sample_ndf) at scrambled Sobol'
    (or Hammersley) points, weight g / p / N with p = D(h)(n.h) (Distribution.pdf_ndf).
``sobol_vndf`` (GGX) h from the visible-normal distribution (Distribution.sample_vndf),
    p_v(h) = G1(v) max(0, v.h) D(h) / (n.v) (Distribution.pdf_vndf).

All accumulate in float64; per-sample terms run in float32; the domain maps run in float64 because
1 - u underflows float32 for small alpha. Per gauss_legendre node the costly part was the float64 exp, cos and sin of
the inner map (two thirds of the time, measured on the 128^2 dfg): region A's inner rule is the same for every texel
(phimax = eps = pi) and is tabulated once on the host (phi_rule_a); region B's cos(phi), sin(phi) come from
cos(phimax) = c*, sin(phimax) in float64 and sin, cos of (phimax - phi) / 2 in float32, which keeps cos(phi) - c*
(the distance to the horizon cut) accurate relatively (order 32: <= 1.2e-8 from the float64 trig on the 128^2 dfg).
Edge: a texel with alpha = 0 (the integrand has a ``mirror`` and alpha < ALPHA_MIN: lutbake.edge) takes the
closed-form mirror limit ``mirror(v, param)`` instead of a quadrature.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import warp as wp

from .. import tolerance
from ..records import HEMISPHERE_ESTIMATOR
from ..runtime.warp_runtime import load_module, unique_kernel
from ..terms.frame import view_dir
from . import points
from .arrays import PhiRule, Points2, Rows64, Rule, Values64
from .ladder import product_ladder_for

PI64 = wp.constant(wp.float64(math.pi))


# the BRDF terms run in float32: a texel value carries their rounding, ~1e-7 relative (measured: orders 48 and 64
# differ by 3e-8 on the 128^2 dfg), which no difference of two orders sees; the error estimate adds it
TERMS_ROUNDING = wp.constant(wp.float64(tolerance.TERMS_ROUNDING))
MAX_PANELS = 32  # a texel's panels: <= 22 for n.v >= NOV_MIN, alpha >= ALPHA_MIN (lutbake.edge), 23 with a Charlie lobe
# an NDF-peak breakpoint within this factor of a horizon breakpoint (or of the panel's start) is dropped: a sliver
# panel costs a whole product rule at two orders (measured, 256^2 glTF grid: 5.9 -> 4.9 panels per texel; every
# estimate still bounds its error against order 64 there and on the 128^2 dfg, worst error / estimate unchanged;
# 2.0 raised it to 0.98, 2.5 past 1). To a tolerance only: at a fixed order fewer panels are fewer nodes (the
# kink-limited Cook-Torrance tables lost accuracy: 3.4e-5 -> 4.1e-5)
PEAK_MERGE = 1.6
PANEL_RATIO = 4.0  # panels grow geometrically in theta_h (and in pi/2 - theta_h) by this factor


@wp.func
def store_row(out: wp.array2d(dtype=wp.float64), i: int, m: wp.vec2):
    """out[i] = m (float64): a texel's closed-form value (the mirror limit)."""
    out[i, 0] = wp.float64(m[0])
    out[i, 1] = wp.float64(m[1])


@wp.func
def store_row(out: wp.array2d(dtype=wp.float64), i: int, m: wp.vec3):  # noqa: F811 (a Warp overload)
    out[i, 0] = wp.float64(m[0])
    out[i, 1] = wp.float64(m[1])
    out[i, 2] = wp.float64(m[2])


@wp.func
def store_row(out: wp.array2d(dtype=wp.float64), i: int, m: wp.vec4):  # noqa: F811 (a Warp overload)
    for c in range(4):
        out[i, c] = wp.float64(m[c])


Edges = wp.types.vector(length=MAX_PANELS + 1, dtype=wp.float64)  # a texel's panel ends in theta_h


@wp.struct
class PanelTexel:
    """What a texel's panels share (make_gauss_legendre): its view, alpha, param, the panel anchors (texel_view), the
    sinh map's distance eps_l to G2's pole (horizon_scale), the panel ends, region A's inner rule (phi_rule_a) and
    the integrand's kink along n.l = kink (kink_band)."""

    v: wp.vec3
    a: float
    prm: float
    theta_a: wp.float64
    theta_peak: wp.float64
    eps_l: wp.float64
    edges: Edges
    phi_a: PhiRule
    kink: wp.float64  # the n.l of the integrand's kink (SpecularIntegrand.nol_kink), 0: none
    theta_klo: wp.float64  # theta_h where the kink enters the inner domain (cos phi_k = 1 or -1), -1: no kink
    theta_khi: wp.float64  # ... and where it leaves it


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


@wp.func
def next_geometric(t_lo: wp.float64, t0: wp.float64):
    """Smallest t0 * R^j (j >= 0) above t_lo, for t0 > 0."""
    if t_lo < t0:
        return t0
    j = wp.floor(wp.log(t_lo / t0) / wp.log(wp.float64(PANEL_RATIO))) + wp.float64(1.0)
    return t0 * wp.pow(wp.float64(PANEL_RATIO), j)


@wp.func
def next_theta(t_lo: wp.float64, theta_a: wp.float64, theta_peak: wp.float64, merge: wp.float64):
    """Upper edge of the panel starting at t_lo: the next of
    - the NDF-peak breakpoints theta_peak R^j (below pi/4): the tail of D decays like a power of theta; one within
      a factor ``merge`` (> 1: PEAK_MERGE, to a tolerance; 1: none, the fixed orders) of the next horizon breakpoint
      or of t_lo is skipped (D is analytic there, a scale, not a kink);
    - the horizon breakpoints: theta_a (c* = -1), then geometric from theta_a up to pi/4 and from
      theta_b = pi/2 - theta_a down to pi/4 (c* ~ -cot(theta_v) / (2 theta_h) varies on every scale
      between theta_a and pi/4 at grazing view)."""
    quarter = PI64 * wp.float64(0.25)
    half = PI64 * wp.float64(0.5)
    if t_lo < quarter:
        t = wp.min(next_geometric(t_lo, theta_a), quarter)
        tp = next_geometric(t_lo, theta_peak)
        if tp < t and tp * merge <= t and (t_lo <= wp.float64(0.0) or t_lo * merge <= tp):
            return tp
        return t
    d = wp.max((half - t_lo) / wp.float64(PANEL_RATIO), theta_a)
    return half - d


@wp.func
def asinh64(x: wp.float64):
    """asinh(x) = log(x + sqrt(x^2 + 1)) for x >= 0 (Warp has no asinh builtin)."""
    return wp.log(x + wp.sqrt(x * x + wp.float64(1.0)))


@wp.func
def horizon_scale(cos_v: wp.float64, alpha: wp.float64):
    """Distance in n.l from the horizon to the pole of Smith G2 as n.l -> 0:
    G2 ~ 2 (n.l) / ((n.l)(1 + 2 Lambda(v)) + alpha) puts it at
    n.l = -alpha (n.v) / sqrt((n.v)^2 + alpha^2 (1 - (n.v)^2)), about min(n.v, alpha). Integrands vary on this
    scale next to the horizon cut."""
    return alpha * cos_v / wp.sqrt(cos_v * cos_v + alpha * alpha * (wp.float64(1.0) - cos_v * cos_v))


@wp.func
def texel_view(t: wp.vec3):
    """A texel (n.v, alpha, param) unpacked: (v, alpha, param, alpha as float64, cos theta_v, sin theta_v,
    horizon_scale, theta_a, theta_b, atan(alpha)), the last three the anchors of the Gauss-Legendre panels
    (theta_a = (pi/2 - theta_v)/2: c* = -1; theta_b = pi/2 - theta_a: c* = +1; atan(alpha): the NDF peak)."""
    v = view_dir(t[0])
    a64 = wp.float64(t[1])
    cos_v = wp.float64(v[2])
    sin_v = wp.float64(v[0])
    theta_a = wp.float64(0.5) * wp.atan2(cos_v, sin_v)
    theta_b = PI64 * wp.float64(0.5) - theta_a
    return v, t[1], t[2], a64, cos_v, sin_v, horizon_scale(cos_v, a64), theta_a, theta_b, wp.atan(a64)


@wp.func
def kink_cos_phi(kink: wp.float64, cos_v: wp.float64, sin_v: wp.float64, cos_h: wp.float64, sin_h: wp.float64):
    """cos(phi_k), where n.l = kink at this theta_h: n.l = cos(theta_v) cos(2 theta_h) + sin(theta_v) sin(2 theta_h)
    cos(phi) (l = reflect(v, h)), decreasing in phi over [0, pi]; outside (-1, 1) where the kink misses this
    theta_h (the horizon's c* is the case kink = 0)."""
    return (kink - cos_v * (cos_h * cos_h - sin_h * sin_h)) / wp.max(
        sin_v * wp.float64(2.0) * sin_h * cos_h, wp.float64(1.0e-300)
    )


@wp.func
def kink_band(kink: wp.float64, cos_v: wp.float64, sin_v: wp.float64):
    """The theta_h interval where the level line n.l = kink (0 < kink < 1) crosses the inner domain: n.l spans
    [cos(2 theta_h + theta_v), cos(2 theta_h - theta_v)] over phi, so (|acos(kink) - theta_v| / 2, (acos(kink) +
    theta_v) / 2), as the horizon's (theta_a, theta_b) at kink = 0; and theta_v / 2, where l = n (h bisects v and n:
    Estevez & Kulla's Lambda fit has a cusp there, (1 - n.l)^0.2); (-1, -1, -1) for no kink."""
    if kink <= wp.float64(0.0):
        return wp.vec3d(wp.float64(-1.0), wp.float64(-1.0), wp.float64(-1.0))
    theta_v = wp.atan2(sin_v, cos_v)
    t_k = wp.acos(kink)
    half = wp.float64(0.5)
    return wp.vec3d(half * wp.abs(t_k - theta_v), half * (t_k + theta_v), half * theta_v)


@wp.func
def next_toward(t_lo: wp.float64, t_end: wp.float64, scale: wp.float64, reach: wp.float64):
    """Smallest t_end - scale R^j (j >= 0) above t_lo with scale R^j < reach, else t_end: breakpoints graded
    geometrically towards t_end."""
    if scale <= wp.float64(0.0) or t_end - t_lo <= scale:
        return t_end
    r = wp.float64(PANEL_RATIO)
    d = scale * wp.pow(r, wp.floor(wp.log((t_end - t_lo) / scale) / wp.log(r)))
    if t_end - d <= t_lo:
        d = d / r
    if d >= reach:
        return t_end
    return t_end - d


@wp.func
def panel_texel(
    tx: wp.vec3, phi_a: PhiRule, merge: wp.float64, mirror_limit: bool, kink: wp.float64, grazing: bool, ndf_peak: bool
):
    """A texel (n.v, alpha, param) with its panels in theta_h (next_theta; ``merge``: PEAK_MERGE to a tolerance, 1 at
    a fixed order), split where an integrand's kink along n.l = ``kink`` (0: none) enters and leaves the inner
    domain (kink_band): (PanelTexel, n_panels). No panel where ``mirror_limit`` and alpha = 0 (the closed-form
    mirror limit takes the texel: lutbake.edge). A ``grazing`` NDF (Charlie's sin(theta_h)^(1/alpha), peaking at
    theta_h = pi/2) adds breakpoints graded towards theta_b on its scale there, alpha / (theta_a + sqrt(alpha)):
    sin^(1/alpha) ~ exp(-(pi/2 - theta_h)^2 / (2 alpha)) and pi/2 - theta_b = theta_a. Without ``ndf_peak`` (a
    sampling NDF that only panels: the sheen layouts) no breakpoints at its peak atan(alpha) R^j."""
    v, a, prm, a64, cos_v, sin_v, eps_l, theta_a, theta_b, theta_peak = texel_view(tx)
    band = kink_band(kink, cos_v, sin_v)
    peak_scale = wp.float64(0.0)
    if grazing:
        peak_scale = a64 / (theta_a + wp.sqrt(a64))
    if not ndf_peak:
        theta_peak = PI64 * wp.float64(0.25)  # no NDF-peak breakpoints: D_charlie has no peak at atan(alpha)
    edges = Edges()
    if mirror_limit and a <= 0.0:
        edges[0] = theta_b
    n_panels = wp.int32(0)  # a dynamic variable (Warp: a bare literal is a constant)
    t_lo = edges[0]
    while t_lo < theta_b:  # theta_b: c* = +1, nothing beyond reflects above the horizon
        t_next = next_theta(t_lo, theta_a, theta_peak, merge)
        for k in range(3):
            if t_lo < band[k] and band[k] < t_next:
                t_next = band[k]
        t_next = wp.min(t_next, next_toward(t_lo, theta_b, peak_scale, theta_b - PI64 * wp.float64(0.25)))
        t_lo = t_next
        if n_panels == MAX_PANELS - 1:  # never reached (MAX_PANELS): the last panel would take the rest
            t_lo = theta_b
        n_panels += 1
        edges[n_panels] = t_lo
    return PanelTexel(v, a, prm, theta_a, theta_peak, eps_l, edges, phi_a, kink, band[0], band[1]), n_panels


@wp.func
def phi_b(
    ex: wp.float64, inv_ex: wp.float64, eps: wp.float64, big_a: wp.float64, c_star: wp.float64, s_star: wp.float64
):
    """Region B's inner node at e^(big_a (1 - x)) = ex (1 / ex = inv_ex) of the sinh map phi = phimax - delta,
    delta = eps sinh(big_a (1 - x)): (cos phi, sin phi, d delta / dx). cos and sin of phi come from those of phimax
    (c*, s*, float64) and of delta / 2 (float32: relative errors ~1e-7 in sin(delta) and in 1 - cos(delta) =
    2 sin^2(delta / 2), so cos(phi) - c*, which sets n.l at the cut, keeps ~1e-7 relative accuracy, as h itself in
    float32), put back on the unit circle (one Newton step of 1/sqrt(sd^2 + cd^2) from 1): cos^2 + sin^2 of phi is 1
    to ~1e-15, as with float64 trig (sin^2 theta_h = h.x^2 + h.y^2 feeds D_charlie's sin^(1/alpha), 1/alpha up to
    1e4)."""
    half = wp.float64(0.5)
    two = wp.float64(2.0)
    hd = float(half * eps * half * (ex - inv_ex))
    sd = wp.float64(wp.sin(hd))
    cd = wp.float64(wp.cos(hd))
    nrm = wp.float64(1.5) - half * (sd * sd + cd * cd)
    sd = sd * nrm
    cd = cd * nrm
    sin_d = two * sd * cd
    omc = two * sd * sd
    return wp.vec3d(
        c_star - c_star * omc + s_star * sin_d,
        s_star - s_star * omc - c_star * sin_d,
        eps * half * (ex + inv_ex) * big_a,
    )


@functools.lru_cache(maxsize=None)
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


@functools.lru_cache(maxsize=None)
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


@functools.lru_cache(maxsize=None)
def facet_weight_for(integrand, pdf):
    """``facet_weight(v, h, alpha, param, in_u)``: g(h) / p(h) (over_pdf_for)."""
    over_pdf = over_pdf_for(pdf)

    @wp.func
    def facet_weight(v: wp.vec3, h: wp.vec3, a: float, prm: float, in_u: bool):
        return over_pdf(integrand(v, h, a, prm), v, h, a, in_u)

    return facet_weight


UNROLL = 4  # members per unrolled block of a members rule (facet_rules_for); members_of's size is a multiple


@functools.lru_cache(maxsize=None)
def members_of(nch: int, size: int):
    """The accumulator of ``size`` texels that share every node of their panel rules and differ only in the
    integrand's param (the dielectric tables' eta >= 1 at one (n.v, alpha): lutbake.sampling.dielectric): a float64
    matrix, row k member k, columns 0 .. nch - 1 its sums and column nch its param (a float32, exact in float64). A
    plain matrix, not a struct: Warp updates a local matrix in place, while a struct's matrix field is loaded whole
    for every element read (measured 2.5x the time of the single-texel rule)."""
    return wp.types.matrix(shape=(size, nch + 1), dtype=wp.float64)


@functools.lru_cache(maxsize=None)
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


@functools.lru_cache(maxsize=None)
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


def make_gauss_legendre(spec):
    """Product Gauss-Legendre over panels in theta_h (module docstring), adaptive per panel. Per panel [t_lo, t_hi]:
    - the outer variable is u = CDF(theta_h) on the NDF-peak panel [0, atan(alpha)] (the weight is
      g / p, D cancels), and theta_h itself beyond it (the weight is 2 pi sin(theta_h) g, because
      du = 2 pi D cos sin dtheta); a panel in region B has its outer variable smoothstep-mapped;
    - the inner variable phi runs over [0, pi] in region A and [0, acos c*] in region B, through a
      sinh map that resolves G2's pole at n.l = -horizon_scale next to the cut.
    Adaptivity (lutbake.sampling.ladder.product_ladder_for, greedy): the outer and the inner rule each have their
    own order and error estimate, so that their errors cannot cancel in the estimate (measured: a 6 x 6 rule
    erring by 5e-7, its outer rule by -3.0e-6 and its inner one by +3.5e-6). Every panel is integrated at (n_0,
    n_0), (n_1, n_0), (n_1, n_1) (outer, inner; ``levels``: the orders, their rules concatenated in ``rules``, the
    outer check rule CHECK_ORDER last); a panel keeps the last, d_o = |Q(n_1, n_0) - Q(n_0, n_0)| (at least
    |Q(n_1, n_0) - Q(CHECK_ORDER, n_0)| and the geometric tail of ladder.outer_bound) and d_i = |Q(n_1, n_1) -
    Q(n_1, n_0)|. While a channel's estimate, sum_p (d_o + d_i) / pi + TERMS_ROUNDING |I_c| (float32 terms),
    exceeds max(tol_abs, tol_rel |I_c|), its panel and variable with the largest d goes one order up. The estimate
    is the texel's ``err``.
    One level: the fixed-order rule, err = 0.
    Kernel inputs: per-texel (n.v, alpha, param); ``levels`` (offset, order) into ``rules``, GL (node, weight)
    pairs on [0, 1]; ``tol`` (tol_abs, tol_rel). ``spec``: an integrand record (g, vec, acc, distribution,
    mirror)."""
    mirror = spec.mirror
    nch = spec.vec._length_
    smooth = mirror is not None
    kink = spec.nol_kink or 0.0
    integrate = product_ladder_for(panel_rule_for(spec), MAX_PANELS, nch, check=True)
    Sums = wp.types.vector(length=nch, dtype=wp.float64)

    @unique_kernel
    def gauss_legendre_kernel(
        texel: wp.array(dtype=wp.vec3),
        rules: Rule,
        phi_a: PhiRule,
        levels: wp.array(dtype=wp.vec2i),
        tol: wp.vec2d,
        out: Rows64,
        err: Rows64,
    ):
        i = wp.tid()
        merge = wp.float64(1.0)  # the fixed orders keep every breakpoint (their pixels as before PEAK_MERGE)
        if levels.shape[0] > 1:
            merge = wp.float64(PEAK_MERGE)
        kink_nol = wp.float64(wp.static(kink))
        if wp.static(spec.kink_at_nov):  # the level line n.l = n.v (Ashikhmin-Shirley's max(n.l, n.v))
            kink_nol = wp.float64(view_dir(texel[i][0])[2])
        t, n_panels = panel_texel(
            texel[i],
            phi_a,
            merge,
            wp.static(smooth),
            kink_nol,
            wp.static(spec.grazing_peak),
            wp.static(spec.ndf_peak),
        )
        # the texel's target, in units of the panel sums (I = sum / pi): the estimate, TERMS_ROUNDING included, within
        # the tolerance
        rounding = TERMS_ROUNDING
        total, e = integrate(t, n_panels, rules, levels, Sums(tol[0] * PI64), Sums(tol[1]), rounding)
        for c in range(wp.static(nch)):
            out[i, c] = total[c] / PI64
            err[i, c] = e[c] / PI64 + rounding * wp.abs(total[c] / PI64)
        if wp.static(smooth):
            if t.a <= 0.0:  # the mirror limit (lutbake.edge)
                store_row(out, i, mirror(t.v, t.prm))

    return gauss_legendre_kernel


def make_qmc(spec, vndf: bool):
    """Quasi-Monte Carlo: ``sample(v, alpha, u1, u2) -> h`` draws from density ``pdf(v, h, alpha)`` (the
    distribution's visible-normal pair if ``vndf``, else its NDF pair); the estimate is sum_k w_k g(h_k) / p(h_k)
    with w_k = 1/N (points: scrambled Sobol' or Hammersley)."""
    integrand, vec_type, acc_type, mirror = spec.g, spec.vec, spec.acc, spec.mirror
    d = spec.distribution
    pdf, sample = (d.pdf_vndf, d.sample_vndf) if vndf else (d.pdf_ndf, d.sample_ndf)
    nch = vec_type._length_
    smooth = mirror is not None

    @unique_kernel
    def qmc_kernel(texel: wp.array(dtype=wp.vec3), pts: Points2, wts: Values64, out: Rows64):
        i = wp.tid()
        v = view_dir(texel[i][0])
        a = texel[i][1]
        prm = texel[i][2]
        acc = acc_type()
        n = pts.shape[0]
        if wp.static(smooth):
            if a <= 0.0:  # alpha -> 0: the closed-form mirror limit below (lutbake.edge), no samples
                n = 0
        for k in range(n):
            h = sample(v, a, pts[k, 0], pts[k, 1])
            p = pdf(v, h, a)
            if p > 0.0:
                g = integrand(v, h, a, prm)
                for c in range(wp.static(nch)):
                    acc[c] = acc[c] + wts[k] * wp.float64(g[c] / p)
        for c in range(wp.static(nch)):
            out[i, c] = acc[c]
        if wp.static(smooth):
            if a <= 0.0:  # the mirror limit (lutbake.edge)
                store_row(out, i, mirror(v, prm))

    return qmc_kernel


DEFAULT_SAMPLES = {"gauss_legendre": 432, "sobol_vndf": 4096, "sobol_ndf": 4096, "hammersley_ndf": 1024}


def gl_order(samples: int) -> int:
    """GL points per dimension n for a nominal budget of ``samples`` evaluations per texel: 3 regions x n x n
    (A and B's two halves; grazing texels get more panels, up to 2 log4(pi / (4 theta_a)) + 1)."""
    return max(2, int(round(np.sqrt(samples / 3.0))))


@functools.lru_cache(maxsize=None)
def gl_kernel(spec):
    return make_gauss_legendre(spec)


@functools.lru_cache(maxsize=None)
def qmc_kernel(spec, vndf: bool):
    return make_qmc(spec, vndf)


def load(kernel, device: str = "cpu") -> None:
    """Compile (or load from Warp's cache) a kernel's module before worker threads launch it."""
    load_module(kernel.module, device=device)


def _texels(inputs: dict, device: str):
    n = len(inputs["nov"])
    texel = np.stack([np.asarray(inputs[k], dtype=np.float32) for k in ("nov", "alpha", "param")], axis=1)
    return n, wp.array(np.ascontiguousarray(texel), dtype=wp.vec3, device=device)


def _launch(kernel, inputs: dict, point_arrays: list, kernel_channels: int, device: str) -> np.ndarray:
    """One launch over texels (nov[i], alpha[i], param[i]) -> float64 array (len, kernel_channels)."""
    n, texel = _texels(inputs, device)
    out = wp.zeros((n, kernel_channels), dtype=wp.float64, device=device)
    wp.launch(kernel, dim=n, inputs=[texel] + point_arrays + [out], device=device)
    return out.numpy()


# the successive product-rule orders of a panel: a ratio of ~1.5 (each level costs ~2.25x the last). Starting lower
# (4, 6, ...) let coincidental agreements of two coarse rules pass (measured: error 1.9e-6 at an estimate 8e-7 on
# the 128^2 dfg; GGX's region-A NDF-peak panel from (4, 6): albedo's inner 4- and 6-point rules erred by 2.6e-7 and
# 3.7e-7, an estimate of 1.1e-7). Gentler climbs (9 -> 11 -> 14 -> 20) replayed 4-7 % cheaper on GGX but let
# Blinn-Phong's 64^2 table pass an error of 2.7e-6 under an estimate of 2.2e-7: orders 9 and 11 agree by chance.
# The outer and the inner rule climb on their own (lutbake.sampling.ladder.product_ladder_for)
ADAPTIVE_ORDERS = (6, 9, 12, 16, 24, 32, 48, 64)
# the method text's note (lutbake.sampling.plan): what a panel's difference is in the product ladder
PRODUCT_NOTE = (
    ", per panel its outer and its inner rule's, each at the other's order (the outer one at least the difference "
    "to order 8 and its geometric tail: lutbake.sampling.ladder.product_ladder_for)"
)
CHECK_ORDER = 8  # the outer check rule of the first pair (lutbake.sampling.ladder.outer_bound: orders 6, 8, 9)
assert (ADAPTIVE_ORDERS[0], CHECK_ORDER, ADAPTIVE_ORDERS[1]) == (6, 8, 9)  # outer_bound's geometric tail assumes them


@functools.lru_cache(maxsize=None)
def gl_levels(orders: tuple[int, ...], kronrod: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The GL rules of ``orders`` on [0, 1], concatenated ((node, weight) rows), and (offset, order) per order.
    ``kronrod``: the second rule is the Kronrod extension of the first (orders[1] = 2 orders[0] + 1 nodes, the first's
    among them; lutbake.sampling.points.gauss_kronrod), so the first two levels are a Gauss-Kronrod pair."""
    rule = [np.stack(points.gauss_legendre(n), axis=1) for n in orders]
    if kronrod:
        if len(orders) < 2 or orders[1] != 2 * orders[0] + 1:
            raise ValueError(f"a Gauss-Kronrod pair is (n, 2n + 1) nodes, not {orders[:2]}")
        rule[1] = np.stack(points.gauss_kronrod(orders[0])[:2], axis=1)
    rules = np.concatenate(rule)
    offsets = np.cumsum([0] + list(orders[:-1]))
    return rules, np.stack([offsets, orders], axis=1).astype(np.int32)


def phi_rule_a(rules: np.ndarray) -> np.ndarray:
    """Region A's inner rule: phimax = pi and the sinh map's scale eps = pi (make_gauss_legendre) for every texel, so
    its nodes phi_j = pi - pi sinh(A (1 - x_j)), A = asinh(1), and weights w_j pi A cosh(A (1 - x_j)) are computed
    once, here: rows (cos phi_j, sin phi_j, weight), float64."""
    x, w = rules[:, 0], rules[:, 1]
    big_a = np.arcsinh(1.0)
    ex = np.exp(big_a * (1.0 - x))
    phi = np.pi - np.pi * 0.5 * (ex - 1.0 / ex)
    return np.stack([np.cos(phi), np.sin(phi), w * np.pi * 0.5 * (ex + 1.0 / ex) * big_a], axis=1)


@functools.lru_cache(maxsize=None)
def gl_rule_arrays(orders: tuple[int, ...], device: str) -> tuple:
    """(rules, phi_rule_a, levels) of ``orders`` as the kernel's device arrays: made once per (orders, device), not
    per tile (read-only, shared by every launch)."""
    rules, levels = gl_levels(orders)
    return (
        wp.array(rules, dtype=wp.vec2d, device=device),
        wp.array(phi_rule_a(rules), dtype=wp.vec3d, device=device),
        wp.array(levels, dtype=wp.vec2i, device=device),
    )


def gl_launch(integrand, inputs: dict, orders: tuple[int, ...], tol: tuple[float, float], device: str):
    """The gauss_legendre kernel over texels ``inputs`` at ``orders`` (one: fixed order) and tolerance
    (absolute, relative): (values, error estimates), float64 (n, kernel_channels) each."""
    n, texel = _texels(inputs, device)
    out = wp.zeros((n, integrand.kernel_channels), dtype=wp.float64, device=device)
    err = wp.zeros((n, integrand.kernel_channels), dtype=wp.float64, device=device)
    ladder = tuple(orders) + ((CHECK_ORDER,) if len(orders) > 1 else ())  # the check rule last (product_ladder_for)
    args = [texel, *gl_rule_arrays(ladder, device), wp.vec2d(*tol), out, err]
    wp.launch(gl_kernel(integrand), dim=n, inputs=args, device=device)
    return out.numpy(), err.numpy()


@dataclass(frozen=True)
class GaussLegendre:
    """The ``gauss_legendre`` estimator at a nominal budget of ``budget`` evaluations per texel (order gl_order)."""

    budget: int = DEFAULT_SAMPLES["gauss_legendre"]
    name: str = "gauss_legendre"

    @property
    def order(self) -> int:
        return gl_order(self.budget)

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["nov"]), 3 * self.order**2)

    def _kernel(self, integrand):
        """The kernel of this quadrature for ``integrand`` (a subclass may supply another panelling)."""
        return gl_kernel(integrand)

    def prepare(self, integrand, device: str) -> None:
        load(self._kernel(integrand), device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        return gl_launch(integrand, inputs, (self.order,), (0.0, 0.0), device)[0]

    def refined(self):
        n = self.order
        return replace(self, budget=3 * (n + 4) ** 2), f"order {n} - order {n + 4}"


@dataclass(frozen=True)
class AdaptiveGaussLegendre:
    """``gauss_legendre`` to a tolerance: every panel at the first two orders of ADAPTIVE_ORDERS, then the worst panel
    rule (outer or inner) one order up until the texel's estimate is within max(absolute, relative |I|)
    (make_gauss_legendre, the greedy ladder of lutbake.sampling.ladder.product_ladder_for). ``evaluate_with_error``
    also returns each texel's error estimate (the sum over panels of its outer and inner rules' estimates plus
    TERMS_ROUNDING |I|), recorded as the table's lutbake:error_estimate."""

    absolute: float
    relative: float
    orders: tuple[int, ...] = ADAPTIVE_ORDERS
    name: str = "gauss_legendre"
    estimate_note: str = PRODUCT_NOTE

    def samples(self, inputs: dict) -> np.ndarray:  # nominal: 3 panels at the middle order (the work adapts)
        return np.full(len(inputs["nov"]), 3 * self.orders[(len(self.orders) + 1) // 2] ** 2)  # 24: 1728, as before

    def prepare(self, integrand, device: str) -> None:
        load(gl_kernel(integrand), device)

    def evaluate_with_error(self, integrand, inputs: dict, device: str) -> tuple[np.ndarray, np.ndarray]:
        return gl_launch(integrand, inputs, self.orders, (self.absolute, self.relative), device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        return self.evaluate_with_error(integrand, inputs, device)[0]

    def refined(self):
        return replace(self, absolute=self.absolute / 100, relative=self.relative / 100), "tolerance / 100"


@dataclass(frozen=True)
class QuasiMonteCarlo:
    """``sobol_vndf`` / ``sobol_ndf`` (scrambled Sobol' points, n rounded up to a power of two) or
    ``hammersley_ndf``: h drawn from the visible-normal or the NDF density, weight g / p / N."""

    name: str
    budget: int
    seed: int = 0

    def _n(self) -> int:
        if self.name.startswith("sobol"):
            return 1 << int(np.ceil(np.log2(max(self.budget, 1))))
        return self.budget

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["nov"]), self._n())

    def _kernel(self, integrand):
        return qmc_kernel(integrand, self.name == "sobol_vndf")

    def prepare(self, integrand, device: str) -> None:
        load(self._kernel(integrand), device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        pts = points.sobol(self.budget, self.seed) if self.name.startswith("sobol") else points.hammersley(self.budget)
        pts = np.clip(pts, 0.0, np.nextafter(np.float32(1.0), np.float32(0.0))).astype(np.float32)
        w = np.full(len(pts), 1.0 / len(pts))
        arr = [wp.array(pts, dtype=float, device=device), wp.array(w, dtype=wp.float64, device=device)]
        return _launch(self._kernel(integrand), inputs, arr, integrand.kernel_channels, device)

    def refined(self):
        return replace(self, seed=self.seed + 1), "seed - (seed + 1) (two scramblings)"


def estimator_for(name: str, samples: int | None = None, seed: int = 0, tolerance=None):
    """The hemisphere estimator ``name`` (lutbake.records.HEMISPHERE_ESTIMATOR) at ``samples`` per texel (None:
    its default). gauss_legendre without ``samples`` but with a ``tolerance`` (lutbake.tolerance.Tolerance) adapts its
    order to it."""
    budget = samples or DEFAULT_SAMPLES[name]
    if name == "gauss_legendre" and samples is None and tolerance is not None:
        return AdaptiveGaussLegendre(tolerance.absolute, tolerance.relative)
    if name == "gauss_legendre":
        return GaussLegendre(budget)
    if name in HEMISPHERE_ESTIMATOR:
        return QuasiMonteCarlo(name, budget, seed)
    raise KeyError(name)
