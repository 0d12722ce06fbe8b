"""The microfacet diffuse AmbientBRDF E(v) with the order of integration swapped (m outside, l inside).

E(v) = ∫ f(l, v) (n.l) dω_l with Eq. 4, f = G2 / (pi (n.l)(n.v)) ∫ (m.l)+ (m.v)+ F_facet D(m) dω_m. Every
per-facet Fresnel form of lutbake is a product F_facet = c(f0) T(m.l) T(m.v) (a transmission in, a
transmission out: Eq. 6 on each facet, (1 - F(m.l))(1 - F(m.v)) for Schlick or the exact dielectric F), and
height-correlated Smith G2 = 1 / (1 + Λ(n.v) + Λ(n.l)) depends on l only through n.l. Swapping the integrals:

    E(v) = c / (pi (n.v)) ∫ D(m) (m.v)+ T(m.v) H(θ_m) dω_m,
    H(θ_m) = ∫_{n.l > 0} (m.l)+ T(m.l) / (1 + Λ_v + Λ(n.l)) dω_l,

and H depends on m only through θ_m (the l-integrand is symmetric about n): a 2D integral per θ_m node
instead of one per (l, m) pair. With u = CDF of D(m)(n.m) (D dω_m = du dφ_m / (2 pi (n.m)); for GGX
tan^2 θ_m = α^2 u / (1 - u), the σ-scaled variable: as σ -> 0 every node crowds to m = n and the rule
stays exact) and V(θ_m) = ∫ (m.v)+ T(m.v) dφ_m:

    E(v) = c / (2 pi^2 (n.v)) ∫_0^1 V(u) H(u) / (n.m) du.

Quadrature (every rule Gauss-Legendre, every panel smoothstep-mapped, float64 throughout):
- u: panels geometric in θ_m, ending where tan θ_m = α 4^k (k = 1 .. K, until tan θ_m >= 4; the last runs to
  90 degrees), so that the wide-angle tail (tiny D mass, but V and H vary there on their own, α-free, scale)
  gets as many nodes as the peak; the panel holding u_v is cut there (beyond it the facet no longer sees v
  for every φ_m). The cut points u_k = r / (1 + r), r = 16^k, do not depend on α, only their number K does
  (lutbake.tables.diffuse.fd_microfacet_for uses the same panels for the BRDF itself);
- H: μ = n.l on four panels cut at sin θ_m (beyond it m.l > 0 for every φ_l), 2α and 16α (the shoulder of
  G2 ~ 2μ/α at grazing light and its slow approach to 1); in φ only the visible arc |φ| <= acos(-cot θ_m cot θ_l) (its
  ends are zeros of (m.x)+ T(m.x), no kink inside); the arc is symmetric, so 2 ∫_0^w.
Cost per texel: P n_u (4 n_μ n_φ + n_φ) evaluations (P u panels), against 48 n^4 for the
direct nested rule (n = 8: 196 608). Orders per texel are chosen by ``orders_for`` (1.5 x at grazing
view), and the error estimate re-integrates probe texels with every order + 8.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import warp as wp

from ..sampling import points
from ..terms import fresnel

PI64 = wp.constant(wp.float64(math.pi))
TAIL_RATIO = 4.0  # u panels end where tan(theta_m) = alpha * 4^k, k = 1 .. K (geometric in theta_m)
TAIL_RATIO64 = wp.constant(wp.float64(TAIL_RATIO))
TAIL_TAN = 4.0  # ... until tan(theta_m) >= 4 (76 degrees); the last panel runs to theta_m = 90 degrees
MAX_TAIL_CUTS = 16
TAIL_TAN64 = wp.constant(wp.float64(TAIL_TAN))


@wp.func
def n_tail_cuts(alpha: wp.float64):
    k = int(wp.ceil(wp.log(TAIL_TAN64 / alpha) / wp.log(TAIL_RATIO64)))
    return wp.clamp(k, 1, MAX_TAIL_CUTS)


@wp.func
def T_pow5(c: wp.float64, f0: wp.float64):
    """1 - (1 - c)^5: the transmission shape of Eq. 6 and of 1 - F_Schlick (its f0 factor is in c(f0))."""
    m = wp.float64(1.0) - c
    m2 = m * m
    return wp.float64(1.0) - m2 * m2 * m


@wp.func
def T_dielectric_f0(c: wp.float64, f0: wp.float64):
    """1 - F(f0, c) with F the exact dielectric Fresnel of Eq. 2 (evaluated in float32, as the terms)."""
    return wp.float64(1.0) - wp.float64(fresnel.F_dielectric_f0(float(f0), float(c)))


# facet form -> (transmission T(c, f0), the f0 factor c(f0) as a Python function)
FACET_SPLIT = {
    "eq6": (T_pow5, lambda f0: 1.05 * (1.0 - f0)),
    "schlick": (T_pow5, lambda f0: (1.0 - f0) ** 2),
    "dielectric_f0": (T_dielectric_f0, lambda f0: 1.0),
}


@wp.func
def lambda_ggx64(c: wp.float64, alpha: wp.float64):
    c2 = c * c
    return wp.float64(0.5) * (wp.sqrt(c2 + alpha * alpha * (wp.float64(1.0) - c2)) / c - wp.float64(1.0))


@wp.func
def half_arc(cos_m: wp.float64, sin_m: wp.float64, cos_x: wp.float64, sin_x: wp.float64):
    den = sin_m * sin_x
    num = -cos_m * cos_x
    if den <= wp.abs(num):
        if num <= wp.float64(0.0):
            return PI64
        return wp.float64(0.0)
    return wp.acos(wp.clamp(num / den, wp.float64(-1.0), wp.float64(1.0)))


@functools.lru_cache(maxsize=None)
def albedo_kernel_for(facet_fresnel: str):
    """Kernel: E(nov[i]) / c(f0) for alpha[i], f0[i]. rule[i] = (n_u, n_μ, n_φ), the texel's GL orders for u,
    μ = n.l and the arcs: row n of xs, ws (``rules``) is the n-point rule on [0, 1], ns[n] = n."""
    T = FACET_SPLIT[facet_fresnel][0]

    @wp.func
    def arc_integral(
        cm: wp.float64,
        sm: wp.float64,
        cx: wp.float64,
        sx: wp.float64,
        f0: wp.float64,
        xp: wp.array2d(dtype=wp.float64),
        wpp: wp.array2d(dtype=wp.float64),
        rp: int,
        n: int,
    ):
        """∫ (m.x)+ T(m.x) dφ over the arc where m.x > 0 (2 ∫_0^w, the arc being symmetric)."""
        w = half_arc(cm, sm, cx, sx)
        acc = wp.float64(0.0)
        if w > wp.float64(0.0):
            for j in range(n):
                c = cm * cx + sm * sx * wp.cos(w * xp[rp, j])
                if c > wp.float64(0.0):
                    acc = acc + wpp[rp, j] * c * T(c, f0)
        return wp.float64(2.0) * w * acc

    @wp.func
    def smooth(lo: wp.float64, hi: wp.float64, s: wp.float64):
        return lo + (hi - lo) * s * s * (wp.float64(3.0) - wp.float64(2.0) * s)

    @wp.func
    def smooth_w(lo: wp.float64, hi: wp.float64, s: wp.float64):
        return (hi - lo) * wp.float64(6.0) * s * (wp.float64(1.0) - s)

    @wp.kernel(enable_backward=False, module="unique")
    def albedo_kernel(
        nov: wp.array(dtype=wp.float64),
        alpha: wp.array(dtype=wp.float64),
        f0: wp.array(dtype=wp.float64),
        rule: wp.array2d(dtype=int),
        xs: wp.array2d(dtype=wp.float64),
        ws: wp.array2d(dtype=wp.float64),
        ns: wp.array(dtype=int),
        out: wp.array2d(dtype=wp.float64),
    ):
        i = wp.tid()
        one = wp.float64(1.0)
        zero = wp.float64(0.0)
        cv = nov[i]
        a = alpha[i]
        ff = f0[i]
        ru = rule[i, 0]
        rm = rule[i, 1]
        rp = rule[i, 2]
        nu = ns[ru]
        nm = ns[rm]
        npp = ns[rp]
        sv = wp.sqrt(wp.max(one - cv * cv, zero))
        lam_v = lambda_ggx64(cv, a)
        den_v = a * a * (one - cv * cv) + cv * cv
        u_v = cv * cv / den_v
        om_v = a * a * (one - cv * cv) / den_v  # 1 - u_v without cancellation
        n_geo = n_tail_cuts(a)
        acc = zero
        prev = zero
        om_prev = one
        for k in range(n_geo + 1):
            cut = one
            om_cut = zero
            if k < n_geo:
                r2 = wp.pow(TAIL_RATIO64, wp.float64(2 * (k + 1)))
                om_cut = one / (one + r2)
                cut = r2 / (one + r2)
            split = u_v > prev and u_v < cut
            for h in range(2):
                lo = prev
                om_lo = om_prev
                hi = cut
                om_hi = om_cut
                if split and h == 0:
                    hi = u_v
                    om_hi = om_v
                if split and h == 1:
                    lo = u_v
                    om_lo = om_v
                du = om_lo - om_hi
                if (h == 0 or split) and du > zero:
                    for q in range(nu):
                        s = xs[ru, q]
                        u = lo + du * s * s * (wp.float64(3.0) - wp.float64(2.0) * s)
                        wu = ws[ru, q] * du * wp.float64(6.0) * s * (one - s)
                        omu = om_hi + du * (one - s) * (one - s) * (one + wp.float64(2.0) * s)  # 1 - u
                        tan2 = a * a * u / omu
                        cm = one / wp.sqrt(one + tan2)
                        sm = wp.sqrt(tan2) * cm
                        V = arc_integral(cm, sm, cv, sv, ff, xs, ws, rp, npp)
                        if V > zero:
                            # H(theta_m): mu = n.l on four panels cut at sin(theta_m), 2 alpha and 16 alpha (sorted)
                            c1 = wp.min(sm, one)
                            c2 = wp.min(wp.float64(2.0) * a, one)
                            c3 = wp.min(wp.float64(16.0) * a, one)
                            if c1 > c2:
                                t0 = c1
                                c1 = c2
                                c2 = t0
                            if c2 > c3:
                                t0 = c2
                                c2 = c3
                                c3 = t0
                            if c1 > c2:
                                t0 = c1
                                c1 = c2
                                c2 = t0
                            H = zero
                            for pm in range(4):
                                mlo = zero
                                mhi = c1
                                if pm == 1:
                                    mlo = c1
                                    mhi = c2
                                if pm == 2:
                                    mlo = c2
                                    mhi = c3
                                if pm == 3:
                                    mlo = c3
                                    mhi = one
                                if mhi > mlo:
                                    for q in range(nm):
                                        t = xs[rm, q]
                                        mu = smooth(mlo, mhi, t)
                                        wmu = ws[rm, q] * smooth_w(mlo, mhi, t)
                                        sl = wp.sqrt(wp.max(one - mu * mu, zero))
                                        g2 = one / (one + lam_v + lambda_ggx64(mu, a))
                                        H = H + wmu * g2 * arc_integral(cm, sm, mu, sl, ff, xs, ws, rp, npp)
                            acc = acc + wu * V * H / cm
            prev = cut
            om_prev = om_cut
        out[i, 0] = acc / (wp.float64(2.0) * PI64 * PI64 * cv)

    return albedo_kernel


MAX_ORDER = 96
GRAZING_NOV = 0.1


@functools.lru_cache(maxsize=None)
def rules(device: str):
    """GL rules of orders 0..MAX_ORDER as rows of (MAX_ORDER + 1, MAX_ORDER) arrays (row n = order n)."""
    xs = np.zeros((MAX_ORDER + 1, MAX_ORDER))
    ws = np.zeros_like(xs)
    for n in range(1, MAX_ORDER + 1):
        x, w = points.gauss_legendre(n)
        xs[n, :n], ws[n, :n] = x, w
    ns = np.arange(MAX_ORDER + 1, dtype=np.int32)
    return (
        wp.array(xs, dtype=wp.float64, device=device),
        wp.array(ws, dtype=wp.float64, device=device),
        wp.array(ns, dtype=int, device=device),
    )


def orders_for(nov: np.ndarray, alpha: np.ndarray, base: int) -> np.ndarray:
    """(N, 3) orders (u, μ, φ) per texel: ``base`` everywhere, 1.5 x base in u and μ at grazing view (n.v < 0.1),
    where the factor 1 / (n.v) and the steep Λ(n.v) amplify the quadrature error (measured: docs/diffuse.md)."""
    nov = np.asarray(nov, np.float64)
    o = np.full((len(nov), 3), base, dtype=np.int32)
    o[nov < GRAZING_NOV, :2] += base // 2
    return np.minimum(o, MAX_ORDER)


def albedo(
    nov,
    alpha,
    f0=0.0,
    facet_fresnel: str = "eq6",
    order: int = 12,
    orders: np.ndarray | None = None,
    device: str = "cpu",
) -> np.ndarray:
    """E(nov_i) for GGX alpha_i and f0 (rho = 1), float64 (N,). ``orders``: (N, 3) per texel (u, μ, φ);
    omitted: ``orders_for(nov, alpha, order)``."""
    nov = np.ascontiguousarray(nov, dtype=np.float64).reshape(-1)
    n = len(nov)
    alpha = np.ascontiguousarray(np.broadcast_to(np.asarray(alpha, np.float64), (n,)))
    f0a = np.ascontiguousarray(np.broadcast_to(np.asarray(f0, np.float64), (n,)))
    if orders is None:
        orders = orders_for(nov, alpha, order)
    orders = np.ascontiguousarray(np.minimum(orders, MAX_ORDER), dtype=np.int32)
    out = wp.zeros((n, 1), dtype=wp.float64, device=device)
    wp.launch(
        albedo_kernel_for(facet_fresnel),
        dim=n,
        inputs=[
            wp.array(nov, dtype=wp.float64, device=device),
            wp.array(alpha, dtype=wp.float64, device=device),
            wp.array(f0a, dtype=wp.float64, device=device),
            wp.array(orders, dtype=int, device=device),
            *rules(device),
            out,
        ],
        device=device,
    )
    c = FACET_SPLIT[facet_fresnel][1]
    return out.numpy()[:, 0] * np.array([c(x) for x in f0a]) if n else np.zeros(0)


def u_panels(nov: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """u panels per texel: K + 1 geometric ones (n_tail_cuts), one more where u_v falls inside one."""
    alpha = np.asarray(alpha, np.float64)
    k = np.clip(np.ceil(np.log(TAIL_TAN / alpha) / np.log(TAIL_RATIO)), 1, MAX_TAIL_CUTS).astype(int)
    c = np.asarray(nov, np.float64)
    u_v = c * c / (alpha * alpha * (1 - c * c) + c * c)
    r2 = TAIL_RATIO ** (2.0 * np.arange(1, MAX_TAIL_CUTS + 1))
    cuts = r2 / (1 + r2)
    on_cut = (
        np.zeros(len(c), bool)
        if len(c) == 0
        else np.any(np.isclose(u_v[:, None], cuts[None, :], rtol=0, atol=0) | (u_v[:, None] >= 1.0), axis=1)
    )
    return k + 1 + (~on_cut)


def evaluations(orders: np.ndarray, nov: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """Nominal integrand evaluations per texel for (N, 3) orders: P n_u (4 n_μ n_φ + n_φ), P = u_panels."""
    o = np.asarray(orders)
    return u_panels(nov, alpha) * o[:, 0] * (4 * o[:, 1] * o[:, 2] + o[:, 2])


ESTIMATE_EXTRA_ORDER = 8  # the error estimate re-integrates probe texels with every order + 8


def probe_indices(nov: np.ndarray, alpha: np.ndarray, budget: int = 256) -> np.ndarray:
    """Strided texels plus the hardest ones (smallest alpha at the most grazing views)."""
    n = len(nov)
    strided = np.arange(0, n, max(1, n // budget))
    hard = np.lexsort((alpha, nov))[: min(n, 64)]  # most grazing first, then smallest alpha
    small = np.lexsort((nov, alpha))[: min(n, 64)]
    return np.unique(np.concatenate([strided, hard, small]))


def microfacet_albedo_plan(
    *, nov: np.ndarray, alpha: np.ndarray, f0: np.ndarray, facet_fresnel: str, order: int, **plan_fields
):
    """Plan of a table whose texel i is E(nov[i], alpha[i], f0[i]) of the microfacet model (one channel),
    with per-texel orders (orders_for) and an error estimate from re-integrating probe texels at orders + 8."""
    from .base import Plan

    orders = orders_for(nov, alpha, order)
    nov = nov.astype(np.float64)
    alpha = alpha.astype(np.float64)
    f0 = f0.astype(np.float64)
    evals = evaluations(orders, nov, alpha)

    def run_tile(start: int, stop: int, device: str) -> np.ndarray:
        return albedo(
            nov[start:stop], alpha[start:stop], f0[start:stop], facet_fresnel, orders=orders[start:stop], device=device
        )[:, None]

    def error_estimate(data: np.ndarray, device: str) -> tuple[float, str]:
        idx = probe_indices(nov, alpha)
        other = albedo(
            nov[idx], alpha[idx], f0[idx], facet_fresnel, orders=orders[idx] + ESTIMATE_EXTRA_ORDER, device=device
        )
        err = float(np.max(np.abs(data.reshape(len(nov), -1)[idx, 0] - other)))
        return err, (
            f"max |orders (n_u, n_mu, n_phi) - orders + {ESTIMATE_EXTRA_ORDER}| over {len(idx)} probe texels "
            "(strided + most grazing NoV + smallest alpha)"
        )

    return Plan(
        n_texels=len(nov),
        n_channels=1,
        run_tile=run_tile,
        prepare=lambda d: wp.load_module(albedo_kernel_for(facet_fresnel).module, device=d),
        samples=int(round(evals.mean())),
        estimator="gauss_legendre_swapped",
        cost=float(evals.sum()),
        error_estimate=error_estimate,
        **plan_fields,
    )
