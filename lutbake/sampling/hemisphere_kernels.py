"""Kernel factories of the hemisphere estimators (lutbake.sampling.hemisphere): the product Gauss-Legendre over the
horizon-split panels (make_gauss_legendre) and the quasi-Monte Carlo kernel (make_qmc), each closing over an integrand
record of lutbake.integrands.specular and cached by it, and their launches.

All accumulate in float64; per-sample terms run in float32. Per gauss_legendre node the costly part was the float64
exp, cos and sin of the inner map (two thirds of the time, measured on the 128^2 dfg): region A's inner rule is the
same for every texel (phimax = eps = pi) and is tabulated once on the host (lutbake.sampling.rules.phi_rule_a);
region B's cos(phi), sin(phi) come from cos(phimax) = c*, sin(phimax) in float64 and sin, cos of (phimax - phi) / 2 in
float32 (lutbake.sampling.horizon.phi_b), which keeps cos(phi) - c* (the distance to the horizon cut) accurate
relatively (order 32: <= 1.2e-8 from the float64 trig on the 128^2 dfg).
Edge: a texel with alpha = 0 (the integrand has a ``mirror`` and alpha < ALPHA_MIN: lutbake.edge) takes the
closed-form mirror limit ``mirror(v, param)`` instead of a quadrature.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from .. import tolerance
from ..runtime.warp_runtime import kernel_factory, load_module, unique_kernel
from ..terms.frame import view_dir
from .arrays import PhiRule, Points2, Rows64, Rule, Values64, store_row
from .facet_rules import panel_rule_for
from .horizon import MAX_PANELS, PEAK_MERGE, PI64, panel_texel
from .ladder import product_ladder_for
from .rules import CHECK_ORDER, gl_rule_arrays

# the BRDF terms run in float32: a texel value carries their rounding, ~1e-7 relative (measured: orders 48 and 64
# differ by 3e-8 on the 128^2 dfg), which no difference of two orders sees; the error estimate adds it
TERMS_ROUNDING = wp.constant(wp.float64(tolerance.TERMS_ROUNDING))


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


@kernel_factory
def gl_kernel(spec):
    return make_gauss_legendre(spec)


@kernel_factory
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
