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
    The integrand is then analytic in both variables and GL converges exponentially.
``sobol_ndf`` / ``hammersley_ndf``  h from the NDF's inverse CDF (Distribution.sample_ndf) at scrambled Sobol'
    (or Hammersley) points, weight g / p / N with p = D(h)(n.h) (Distribution.pdf_ndf).
``sobol_vndf`` (GGX) h from the visible-normal distribution (Distribution.sample_vndf),
    p_v(h) = G1(v) max(0, v.h) D(h) / (n.v) (Distribution.pdf_vndf).

All accumulate in float64; per-sample terms run in float32; the domain maps run in float64 because
1 - u underflows float32 for small alpha.
Edge: a texel with alpha = 0 (the integrand has a ``mirror`` and alpha < ALPHA_MIN: lutbake.edge) takes the
closed-form mirror limit ``mirror(v, param)`` instead of a quadrature.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import numpy as np
import warp as wp

from ..terms.frame import view_dir
from . import points
from .arrays import Points2, Rows64, Rule, Values64

PI64 = wp.constant(wp.float64(math.pi))


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
def facet_weight_for(integrand, pdf):
    """``facet_weight(v, h, alpha, param, in_u)``: g(h) / p(h) where the outer variable is the NDF's CDF u (D cancels;
    0 where p = 0), g(h) where it is theta_h itself."""

    @wp.func
    def facet_weight(v: wp.vec3, h: wp.vec3, a: float, prm: float, in_u: bool):
        g = integrand(v, h, a, prm)
        if in_u:
            p = pdf(v, h, a)
            if p > 0.0:
                return g / p
            return g * 0.0
        return g

    return facet_weight


def make_gauss_legendre(spec):
    """Product Gauss-Legendre over panels in theta_h (module docstring). Per panel [t_lo, t_hi]:
    - the outer variable is u = CDF(theta_h) on the NDF-peak panel [0, atan(alpha)] (the weight is
      g / p, D cancels), and theta_h itself beyond it (the weight is 2 pi sin(theta_h) g, because
      du = 2 pi D cos sin dtheta); a panel in region B has its outer variable smoothstep-mapped;
    - the inner variable phi runs over [0, pi] in region A and [0, acos c*] in region B, through a
      sinh map that resolves G2's pole at n.l = -horizon_scale next to the cut.
    Kernel inputs: per-texel (n.v, alpha, param); GL (node, weight) pairs on [0, 1] for the outer (rule_u) and
    inner (rule_p) variables. ``spec``: an integrand record (g, vec, acc, distribution, mirror)."""
    vec_type, acc_type, mirror = spec.vec, spec.acc, spec.mirror
    outer_range, outer_node = outer_variable_for(spec.distribution.tan2_from_u, spec.distribution.u_from_tan2)
    facet_weight = facet_weight_for(spec.g, spec.distribution.pdf_ndf)
    nch = vec_type._length_
    smooth = mirror is not None

    @wp.kernel(enable_backward=False, module="unique")
    def gauss_legendre_kernel(texel: wp.array(dtype=wp.vec3), rule_u: Rule, rule_p: Rule, out: Rows64):
        i = wp.tid()
        # theta_b: c* = +1, nothing beyond reflects above the horizon
        v, a, prm, a64, cos_v, sin_v, eps_l, theta_a, theta_b, theta_peak = texel_view(texel[i])
        zero = wp.float64(0.0)
        one = wp.float64(1.0)
        two = wp.float64(2.0)
        acc = acc_type()
        t_lo = zero
        if wp.static(smooth):
            if a <= 0.0:  # alpha -> 0: the closed-form mirror limit below (lutbake.edge), no quadrature
                t_lo = theta_b
        while t_lo < theta_b:
            t_hi = next_theta(t_lo, theta_a, theta_peak)
            in_b = t_lo >= theta_a
            in_u = t_hi <= theta_peak
            x_lo, dx = outer_range(t_lo, t_hi, in_u, a64)
            for k in range(rule_u.shape[0]):
                s = rule_u[k][0]
                x = x_lo + dx * s
                wk = rule_u[k][1] * dx
                if in_b:  # smoothstep: removes the sqrt-like ends of acos(c*) at c* = +-1
                    x = x_lo + dx * s * s * (wp.float64(3.0) - two * s)
                    wk = rule_u[k][1] * dx * wp.float64(6.0) * s * (one - s)
                cos_h, sin_h, wk = outer_node(x, wk, in_u, a64)
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
                for j in range(rule_p.shape[0]):
                    # sinh map (Johnston & Elliott 2005): phi = phimax - eps sinh(big_a (1 - x))
                    arg = big_a * (one - rule_p[j][0])
                    phi = phimax - eps * wp.sinh(arg)
                    w = wk * rule_p[j][1] * eps * wp.cosh(arg) * big_a
                    h = wp.vec3(float(sin_h * wp.cos(phi)), float(sin_h * wp.sin(phi)), float(cos_h))
                    gw = facet_weight(v, h, a, prm, in_u)
                    for c in range(wp.static(nch)):
                        acc[c] = acc[c] + w * wp.float64(gw[c])
            t_lo = t_hi
        for c in range(wp.static(nch)):
            out[i, c] = acc[c] / PI64
        if wp.static(smooth):
            if a <= 0.0:  # the mirror limit (lutbake.edge)
                store_row(out, i, mirror(v, prm))

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

    @wp.kernel(enable_backward=False, module="unique")
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


ESTIMATORS = {
    "gauss_legendre": "deterministic product Gauss-Legendre over panels in theta_h (or CDF(theta_h)) and phi, "
    "split exactly at the horizon (default; converges exponentially)",
    "sobol_vndf": "scrambled Sobol' points, GGX visible-normal sampling (Dupuy & Benyoub 2023)",
    "sobol_ndf": "scrambled Sobol' points, NDF importance sampling of D(h)(n.h)",
    "hammersley_ndf": "Hammersley points, NDF importance sampling (Filament cmgen's estimator)",
}
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
    wp.load_module(kernel.module, device=device)


def _launch(kernel, inputs: dict, point_arrays: list, kernel_channels: int, device: str) -> np.ndarray:
    """One launch over texels (nov[i], alpha[i], param[i]) -> float64 array (len, kernel_channels)."""
    n = len(inputs["nov"])
    out = wp.zeros((n, kernel_channels), dtype=wp.float64, device=device)
    texel = np.stack([np.asarray(inputs[k], dtype=np.float32) for k in ("nov", "alpha", "param")], axis=1)
    arrays = [wp.array(np.ascontiguousarray(texel), dtype=wp.vec3, device=device)]
    wp.launch(kernel, dim=n, inputs=arrays + point_arrays + [out], device=device)
    return out.numpy()


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
        rule = wp.array(np.stack(points.gauss_legendre(self.order), axis=1), dtype=wp.vec2d, device=device)
        return _launch(self._kernel(integrand), inputs, [rule, rule], integrand.kernel_channels, device)

    def refined(self):
        n = self.order
        return replace(self, budget=3 * (n + 4) ** 2), f"order {n} - order {n + 4}"


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


def estimator_for(name: str, samples: int | None = None, seed: int = 0):
    """The hemisphere estimator ``name`` (ESTIMATORS) at ``samples`` per texel (None: its default)."""
    budget = samples or DEFAULT_SAMPLES[name]
    if name == "gauss_legendre":
        return GaussLegendre(budget)
    if name in ESTIMATORS:
        return QuasiMonteCarlo(name, budget, seed)
    raise KeyError(name)
