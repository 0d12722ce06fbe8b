"""The horizon-split domain of the hemisphere integrals (lutbake.sampling.hemisphere): a texel's panels in theta_h
and the float64 helpers of their maps, as ``@wp.func``s.

For a view at theta_v the reflected direction l = reflect(v, h) is above the horizon exactly when
cos(phi) > c*(theta_h) = -cos(theta_v) cos(2 theta_h) / (sin(theta_v) sin(2 theta_h)), so the visible domain splits at
closed-form breakpoints:
    A: theta_h < (pi/2 - theta_v)/2   every phi in [0, pi] is visible (c* <= -1)
    B: theta_h < (pi/2 + theta_v)/2   phi in [0, acos c*]           (-1 < c* < 1)
    beyond: nothing reflects above the horizon.
c* grows monotonically in theta_h; near grazing view c* ~ -cot(theta_v) / (2 theta_h) varies on every scale from
theta_a to pi/4, so B is cut into panels growing geometrically (factor PANEL_RATIO) from both of its ends towards
pi/4 (next_theta). An integrand only C1 along n.l = kink gets the same treatment for that level line (kink_band,
kink_cos_phi); a Charlie lobe's panels also grade towards theta_b (next_toward). The domain maps run in float64
because 1 - u underflows float32 for small alpha.
"""

from __future__ import annotations

import math

import warp as wp

from ..terms.frame import view_dir
from .arrays import PhiRule

PI64 = wp.constant(wp.float64(math.pi))
MAX_PANELS = 32  # a texel's panels: <= 22 for n.v >= NOV_MIN, alpha >= ALPHA_MIN (lutbake.edge), 23 with a Charlie lobe
# an NDF-peak breakpoint within this factor of a horizon breakpoint (or of the panel's start) is dropped: a sliver
# panel costs a whole product rule at two orders (measured, 256^2 glTF grid: 5.9 -> 4.9 panels per texel; every
# estimate still bounds its error against order 64 there and on the 128^2 dfg, worst error / estimate unchanged;
# 2.0 raised it to 0.98, 2.5 past 1). To a tolerance only: at a fixed order fewer panels are fewer nodes (the
# kink-limited Cook-Torrance tables lost accuracy: 3.4e-5 -> 4.1e-5)
PEAK_MERGE = 1.6
PANEL_RATIO = 4.0  # panels grow geometrically in theta_h (and in pi/2 - theta_h) by this factor


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
