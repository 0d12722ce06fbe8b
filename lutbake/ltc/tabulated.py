"""Gotanda's microfacet diffuse (Gotanda 2014, "Designing Reflectance Models for New Consoles", course notes,
Eq. 4) as an LTC lobe: tabulated per texel over the light direction, interpolated in the fit.

Eq. 4 has no closed form: f(l, v) is itself an integral over facet normals (lutbake.sampling.facets, 12 n^2
evaluations per (l, v)), and the fit evaluates f at every LTC sample of every candidate matrix (~10^9 times for
64^2). So per texel (n.v, alpha) the factor

    J(l) = f(l, v) (n.l) / G2(l, v) = 1 / (pi n.v) ∫ (m.l)+ (m.v)+ F_facet D(m) dω_m         (rho = 1, f0 = 0)

is computed once by lutbake's own quadrature (``fd_microfacet_for``, GL order ``TAB_ORDER``) on a grid of light
directions, and the fit's f (n.l) is G2(l, v) J(l): height-correlated Smith G2 = 1 / (1 + Λ(n.v) + Λ(n.l))
(Heitz 2014, Eq. 99) is evaluated exactly, only the smooth J is interpolated (G2 carries the steep onset
G2 ~ 2 n.l / alpha at the horizon, which no coarse grid resolves).

Grid: theta_l at TAB_THETA cell centres (i + 0.5)/TAB_THETA pi/2, phi_l (azimuth from v's plane; f is even in it)
at TAB_PHI endpoints j/(TAB_PHI - 1) pi. Interpolation: Catmull-Rom in both directions (16 taps); ghost nodes
by the lobe's symmetries (phi -> -phi and 2 pi - phi; theta -> -theta is the node at phi + pi) and, past the
horizon row, linear extrapolation. Accuracy (tests/test_ltc_diffuse.py, docs/ltc.md): the interpolated lobe
against the direct quadrature at GL order 12 on cosine-distributed directions.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import warp as wp

from ..edge import COS_EPS
from ..runtime.warp_runtime import MODULE_OPTIONS, kernel_factory, load_module
from ..sampling.diffuse import gl_rule
from ..sampling.facets import fd_microfacet_for
from ..terms import masking
from ..terms.diffuse import F_facet_eq6

wp.set_module_options(MODULE_OPTIONS)

TAB_THETA = 32  # theta_l cell centres on [0, pi/2]
TAB_PHI = 17  # phi_l endpoints on [0, pi]
TAB_ORDER = 8  # GL order of Eq. 4's m-integral at the grid nodes (lutbake.sampling.facets)
TAB_CHUNK = 256  # texels per tabulation launch (launches spread over threads; values independent of the split)


def grid_directions() -> np.ndarray:
    """The tabulated light directions (TAB_THETA, TAB_PHI, 3), float32, in the frame n = +z, v in the xz-plane."""
    th = (np.arange(TAB_THETA) + 0.5) / TAB_THETA * (np.pi / 2)
    ph = np.linspace(0.0, np.pi, TAB_PHI)
    T, P = np.meshgrid(th, ph, indexing="ij")
    return np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1).astype(np.float32)


@wp.func
def G2_ggx(NoL: float, NoV: float, alpha: float):
    """Height-correlated Smith G2 = 1 / (1 + Λ(n.v) + Λ(n.l)) of GGX (Heitz 2014, Eq. 99)."""
    return masking.G2_smith_height_correlated(masking.Lambda_ggx(NoV, alpha), masking.Lambda_ggx(NoL, alpha))


@kernel_factory
def tabulate_kernel():
    fd = fd_microfacet_for(F_facet_eq6)

    @wp.kernel(enable_backward=False)
    def tabulate_gotanda(
        v: wp.array(dtype=wp.vec3),
        alpha: wp.array(dtype=float),
        dirs: wp.array2d(dtype=wp.vec3),
        rule: wp.array(dtype=wp.vec2d),
        out: wp.array3d(dtype=float),
    ):
        """out[t, i, j] = J = f (n.l) / G2 at the grid direction (i, j) of texel t (module docstring)."""
        t, i, j = wp.tid()
        l = dirs[i, j]
        vt = v[t]
        a = alpha[t]
        f = fd(l, vt, a, 0.0, rule)
        g = G2_ggx(l[2], vt[2], a)
        J = wp.float64(0.0)
        if g > 0.0:
            J = f * wp.float64(l[2]) / wp.float64(g)
        out[t, i, j] = float(J)

    return tabulate_gotanda


def tabulate_gotanda(v: np.ndarray, alpha: np.ndarray, device: str = "cpu", workers: int = 1) -> np.ndarray:
    """J per texel on the grid: (n, TAB_THETA, TAB_PHI) float32 for views ``v`` (n, 3) and GGX alphas ``alpha``."""
    n = len(v)
    dirs = wp.array(grid_directions(), dtype=wp.vec3, device=device)
    rule = gl_rule(TAB_ORDER, device)
    kernel = tabulate_kernel()
    load_module(kernel.module, device)  # compiled once, before the chunks' threads launch it
    out = np.zeros((n, TAB_THETA, TAB_PHI), np.float32)

    def run(start: int) -> None:
        stop = min(start + TAB_CHUNK, n)
        res = wp.zeros((stop - start, TAB_THETA, TAB_PHI), dtype=float, device=device)
        wp.launch(
            kernel,
            dim=(stop - start, TAB_THETA, TAB_PHI),
            inputs=[
                wp.array(np.ascontiguousarray(v[start:stop], np.float32), dtype=wp.vec3, device=device),
                wp.array(np.ascontiguousarray(alpha[start:stop], np.float32), dtype=float, device=device),
                dirs,
                rule,
                res,
            ],
            device=device,
        )
        out[start:stop] = res.numpy()

    starts = range(0, n, TAB_CHUNK)
    if workers > 1 and n > TAB_CHUNK:
        with ThreadPoolExecutor(workers) as pool:
            list(pool.map(run, starts))
    else:
        for s in starts:
            run(s)
    return out


@wp.func
def catmull_rom(p0: float, p1: float, p2: float, p3: float, x: float):
    """Catmull-Rom spline through p1 (x = 0) and p2 (x = 1)."""
    return p1 + 0.5 * x * (p2 - p0 + x * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + x * (3.0 * (p1 - p2) + p3 - p0)))


@wp.func
def tab_node(tab: wp.array3d(dtype=float), t: int, i: int, j: int):
    """Node (i, j) of texel t, ghosts included: phi reflected at 0 and pi, theta < 0 through the pole (phi + pi),
    theta past the last row linearly extrapolated."""
    nt = tab.shape[1]
    last = tab.shape[2] - 1
    jj = j
    if jj < 0:
        jj = -jj
    if jj > last:
        jj = 2 * last - jj
    ii = i
    if ii < 0:
        ii = -1 - ii
        jj = last - jj
    if ii > nt - 1:
        a = tab[t, nt - 1, jj]
        return a + float(ii - nt + 1) * (a - tab[t, nt - 2, jj])
    return tab[t, ii, jj]


@wp.func
def tab_lookup(tab: wp.array3d(dtype=float), t: int, l: wp.vec3):
    """J of texel t at the light direction l (Catmull-Rom in theta_l and phi_l; clamped at 0)."""
    nt = tab.shape[1]
    last = tab.shape[2] - 1
    theta = wp.acos(wp.clamp(l[2], -1.0, 1.0))
    phi = wp.atan2(wp.abs(l[1]), l[0])
    x = wp.min(theta / (0.5 * wp.pi) * float(nt) - 0.5, float(nt) - 0.5)
    y = phi / wp.pi * float(last)
    i0 = int(wp.floor(x))
    j0 = wp.min(int(wp.floor(y)), last - 1)
    fx = x - float(i0)
    fy = y - float(j0)
    rows = wp.vec4(0.0)
    for k in range(4):
        i = i0 - 1 + k
        rows[k] = catmull_rom(
            tab_node(tab, t, i, j0 - 1),
            tab_node(tab, t, i, j0),
            tab_node(tab, t, i, j0 + 1),
            tab_node(tab, t, i, j0 + 2),
            fy,
        )
    return wp.max(catmull_rom(rows[0], rows[1], rows[2], rows[3], fx), 0.0)


@wp.func
def gotanda_f_cos(v: wp.vec3, l: wp.vec3, alpha: float, tab: wp.array3d(dtype=float), t: int):
    """Eq. 4's f (n.l) for rho = 1, f0 = 0 (Eq. 6 facet transmission): G2(l, v) J(l), J interpolated from texel t's
    table (module docstring); 0 for a back-facing l or v."""
    if l[2] <= COS_EPS or v[2] <= COS_EPS:
        return 0.0
    return G2_ggx(l[2], v[2], alpha) * tab_lookup(tab, t, l)
