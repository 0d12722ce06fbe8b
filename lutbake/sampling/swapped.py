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
  (lutbake.sampling.panels; lutbake.sampling.facets uses the same panels for the BRDF itself);
- H: μ = n.l on four panels cut at sin θ_m (beyond it m.l > 0 for every φ_l), 2α and 16α (the shoulder of
  G2 ~ 2μ/α at grazing light and its slow approach to 1); in φ only the visible arc |φ| <= acos(-cot θ_m cot θ_l) (its
  ends are zeros of (m.x)+ T(m.x), no kink inside); the arc is symmetric, so 2 ∫_0^w.
Cost per texel: P n_u (4 n_μ n_φ + n_φ) evaluations (P u panels), against 48 n^4 for the
direct nested rule (n = 8: 196 608). Orders per texel are chosen by ``orders_for`` (1.5 x at grazing
view), and the error estimate re-integrates probe texels with every order + 8.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import warp as wp

from ..runtime.warp_runtime import kernel_factory, load_module, unique_kernel
from ..terms.masking import Lambda_ggx64
from . import points
from .groups import group_rows, key_of
from .panels import (
    MAX_TAIL_CUTS,
    PI64,
    TAIL_RATIO,
    TAIL_RATIO64,
    arc_half_width,
    facet_cos_sin,
    interval,
    n_tail_cuts,
    n_tail_cuts_np,
    sort4,
)


@kernel_factory
def swapped_kernel(T, members: int = 1):
    """Kernel: E(nov[g]) / c(f0) for alpha[g] and ``members`` values f0[g, k] (a group of texels that share (n.v,
    alpha) and orders, lutbake.sampling.groups: every node, its cosines and the f0-free factors once; the facet
    transmission ``T(c, f0)`` (float64; lutbake.terms.diffuse.T_*) per member, each member's sums taking the same float
    operations in the same order as alone). rule[g] = (n_u, n_μ, n_φ), the group's GL orders for u, μ = n.l and the
    arcs: row n of xs, ws (``rules``) is the n-point rule on [0, 1], ns[n] = n. out[g, k]: member k."""
    Members = wp.types.vector(length=members, dtype=wp.float64)

    @wp.func
    def arc_integral(
        cm: wp.float64,
        sm: wp.float64,
        cx: wp.float64,
        sx: wp.float64,
        f0: Members,
        xp: wp.array2d(dtype=wp.float64),
        wpp: wp.array2d(dtype=wp.float64),
        rp: int,
        n: int,
    ):
        """∫ (m.x)+ T(m.x) dφ over the arc where m.x > 0 (2 ∫_0^w, the arc being symmetric), per member."""
        w = arc_half_width(cm, sm, cx, sx)
        acc = Members()
        if w > wp.float64(0.0):
            for j in range(n):
                c = cm * cx + sm * sx * wp.cos(w * xp[rp, j])
                if c > wp.float64(0.0):
                    for k in range(wp.static(members)):  # unrolled: T of every member vectorised (a loop: 1.4x)
                        acc[k] = acc[k] + wpp[rp, j] * c * T(c, f0[k])
        return wp.float64(2.0) * w * acc

    @wp.func
    def smooth(lo: wp.float64, hi: wp.float64, s: wp.float64):
        return lo + (hi - lo) * s * s * (wp.float64(3.0) - wp.float64(2.0) * s)

    @wp.func
    def smooth_w(lo: wp.float64, hi: wp.float64, s: wp.float64):
        return (hi - lo) * wp.float64(6.0) * s * (wp.float64(1.0) - s)

    @unique_kernel
    def albedo_kernel(
        nov: wp.array(dtype=wp.float64),
        alpha: wp.array(dtype=wp.float64),
        f0: wp.array2d(dtype=wp.float64),
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
        ff = Members()
        for k in range(wp.static(members)):
            ff[k] = f0[i, k]
        ru = rule[i, 0]
        rm = rule[i, 1]
        rp = rule[i, 2]
        nu = ns[ru]
        nm = ns[rm]
        npp = ns[rp]
        sv = wp.sqrt(wp.max(one - cv * cv, zero))
        lam_v = Lambda_ggx64(cv, a)
        den_v = a * a * (one - cv * cv) + cv * cv
        u_v = cv * cv / den_v
        om_v = a * a * (one - cv * cv) / den_v  # 1 - u_v without cancellation
        n_geo = n_tail_cuts(a)
        acc = Members()
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
                om_hi = om_cut
                if split and h == 0:
                    om_hi = om_v
                if split and h == 1:
                    lo = u_v
                    om_lo = om_v
                du = om_lo - om_hi
                if (h == 0 or split) and du > zero:
                    for q in range(nu):
                        s = xs[ru, q]
                        wu = ws[ru, q] * du * wp.float64(6.0) * s * (one - s)
                        csm = facet_cos_sin(lo, du, om_hi, s, a)
                        cm = csm[0]
                        sm = csm[1]
                        V = arc_integral(cm, sm, cv, sv, ff, xs, ws, rp, npp)
                        if wp.max(V) > zero:
                            # H(theta_m): mu = n.l on four panels cut at sin(theta_m), 2 alpha and 16 alpha (sorted)
                            cuts = sort4(
                                zero,
                                wp.min(sm, one),
                                wp.min(wp.float64(2.0) * a, one),
                                wp.min(wp.float64(16.0) * a, one),
                            )
                            H = Members()
                            for pm in range(4):
                                ends = interval(pm, cuts, one)
                                mlo = ends[0]
                                mhi = ends[1]
                                if mhi > mlo:
                                    for q in range(nm):
                                        t = xs[rm, q]
                                        mu = smooth(mlo, mhi, t)
                                        wmu = ws[rm, q] * smooth_w(mlo, mhi, t)
                                        sl = wp.sqrt(wp.max(one - mu * mu, zero))
                                        g2 = one / (one + lam_v + Lambda_ggx64(mu, a))
                                        H = H + wmu * g2 * arc_integral(cm, sm, mu, sl, ff, xs, ws, rp, npp)
                            for m in range(wp.static(members)):  # a member whose V is 0 takes nothing (as alone)
                                if V[m] > zero:
                                    acc[m] = acc[m] + wu * V[m] * H[m] / cm
            prev = cut
            om_prev = om_cut
        for m in range(wp.static(members)):
            out[i, m] = acc[m] / (wp.float64(2.0) * PI64 * PI64 * cv)

    return albedo_kernel


MAX_ORDER = 96
MEMBERS = 16  # texels per group (diffuse_3d: the 16 f0 slices of a (n.v, sigma) texel)
GRAZING_NOV = 0.1


@kernel_factory
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


def integrate_swapped(
    integrand,
    nov,
    alpha,
    f0=0.0,
    order: int = 12,
    orders: np.ndarray | None = None,
    device: str = "cpu",
    members: int = 1,
) -> np.ndarray:
    """E(nov_i) for GGX alpha_i and f0 (rho = 1) of the microfacet diffuse ``integrand`` (its ``transmission``
    T and factor c(f0): lutbake.integrands.diffuse), float64 (N,). ``orders``: (N, 3) per texel (u, μ, φ);
    omitted: ``orders_for(nov, alpha, order)``. ``members`` (1 or MEMBERS): texels of one (n.v, alpha, orders) in
    groups of that many (the same bits)."""
    nov = np.ascontiguousarray(nov, dtype=np.float64).reshape(-1)
    n = len(nov)
    alpha = np.ascontiguousarray(np.broadcast_to(np.asarray(alpha, np.float64), (n,)))
    f0a = np.ascontiguousarray(np.broadcast_to(np.asarray(f0, np.float64), (n,)))
    if orders is None:
        orders = orders_for(nov, alpha, order)
    orders = np.ascontiguousarray(np.minimum(orders, MAX_ORDER), dtype=np.int32)
    # texels of one (n.v, alpha, orders) share every node (diffuse_3d's f0 slices): in groups of MEMBERS, the others
    # one by one; the same bits either way
    groups, singles = group_rows(key_of(nov, alpha, *orders.T), np.full(n, members > 1), max(members, 1))
    e = np.zeros(n)
    for rows, size in ((groups, members), (singles[:, None], 1)):
        if len(rows) == 0:
            continue
        lead = rows[:, 0]
        f0_rows = np.where(rows >= 0, f0a[rows], f0a[lead][:, None])  # an unused row: the first member's f0
        out = wp.zeros((len(rows), size), dtype=wp.float64, device=device)
        args = [wp.array(np.ascontiguousarray(x), dtype=wp.float64, device=device) for x in (nov[lead], alpha[lead])]
        args += [wp.array(f0_rows, dtype=wp.float64, device=device), wp.array(orders[lead], dtype=int, device=device)]
        kernel = swapped_kernel(integrand.transmission, size)
        wp.launch(kernel, dim=len(rows), inputs=[*args, *rules(device), out], device=device)
        used = rows >= 0
        e[rows[used]] = out.numpy()[used]
    c = integrand.f0_scale
    return e * np.array([c(x) for x in f0a]) if n else np.zeros(0)


def u_panels(nov: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """u panels per texel: K + 1 geometric ones (n_tail_cuts), one more where u_v falls inside one."""
    alpha = np.asarray(alpha, np.float64)
    k = n_tail_cuts_np(alpha)
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


@dataclass(frozen=True)
class SwappedGaussLegendre:
    """The microfacet diffuse albedo by the swapped integral (module docstring) at base order ``order`` (per-texel
    orders: ``orders_for``; ``extra`` is added to every order). Inputs: nov, alpha, f0."""

    order: int = 12
    extra: int = 0
    name: str = "gauss_legendre_swapped"
    members: int = 1  # MEMBERS: texels that differ only in f0 in groups (diffuse_3d; integrate_swapped)

    def _orders(self, inputs: dict) -> np.ndarray:
        return orders_for(inputs["nov"], inputs["alpha"], self.order) + self.extra

    def samples(self, inputs: dict) -> np.ndarray:
        nov, alpha = (np.asarray(inputs[k], np.float64) for k in ("nov", "alpha"))
        return evaluations(self._orders(inputs), nov, alpha)

    def prepare(self, integrand, device: str) -> None:
        for size in sorted({1, self.members}):
            load_module(swapped_kernel(integrand.transmission, size).module, device=device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        nov, alpha, f0 = (np.asarray(inputs[k], np.float64) for k in ("nov", "alpha", "f0"))
        orders = self._orders(inputs)
        return integrate_swapped(integrand, nov, alpha, f0, orders=orders, device=device, members=self.members)[:, None]

    def refined(self):
        e = self.extra + ESTIMATE_EXTRA_ORDER
        return replace(self, extra=e), f"orders (n_u, n_mu, n_phi) - orders + {e}"
