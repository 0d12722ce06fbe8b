"""Fitting Linearly Transformed Cosines (Heitz, Dupuy, Hill & Neubelt 2016, "Real-Time Polygonal-Light
Shading with Linearly Transformed Cosines", SIGGRAPH) to a lobe f(v, l)(n.l), one texel at a time.

The LTC distribution of a 3x3 matrix M is the clamped cosine D_o(w_o) = max(0, z_o)/pi pushed through
w = M w_o / |M w_o|:
    D(w) = D_o(w_o) |det M^-1| / |M^-1 w|^3,   w_o = M^-1 w / |M^-1 w|          (Heitz et al. 2016, Eq. 3)
and the fitted lobe is magnitude x D, magnitude = ∫ f (n.l) dω (the directional albedo with F = 1).

Parametrisation (ltc_code fit/LTC.h, fitLTC.cpp): M = [X Y Z] * [[m11, 0, m13], [0, m22, 0], [0, 0, 1]],
the frame Z = the lobe's average direction (y cleared: the lobe is symmetric about the xz-plane), X = (Z.z, 0,
-Z.x), Y = (0, 1, 0); at normal incidence (n.v = 1) the lobe is isotropic: m22 = m11, m13 = 0.
The optimiser sees q = (log m11, log m22, m13 / m11): scale-free, so one simplex size fits every roughness.

Error metric (ltc_code computeError, unchanged): the L3 distance between the lobe and the LTC,
    E = ∫ |f(v, l)(n.l) - magnitude D(l)|^3 dω_l,
estimated with multiple importance sampling by both distributions on the same N x N stratified grid
u = ((i + 0.5)/N, (j + 0.5)/N): E ≈ 1/N^2 Σ_both |f - D|^3 / (p_ltc + p_brdf), p_ltc = D / magnitude.
Kept as Heitz's so that the published table and lutbake's fits are compared on one metric. The table
records the scale-free relative form e = (E / ∫ f^3 dω)^(1/3) (same ordering per texel; ∫ f^3 by the
lobe's sampler on the same grid).

Search: Nelder-Mead (ltc_code nelder_mead.h: reflection 1, expansion 2, contraction 1/2, shrink 1/2,
Numerical Recipes' stopping test 2|f_lo - f_hi| <= tol (|f_lo| + |f_hi|)) vectorised with numpy over every
texel at once, the objective a Warp kernel over (texel, candidate) pairs. Every texel is independent: the
start is the best of (an analytic guess; the fits of a coarse pass at the surrounding coarse-grid texels),
the coarse pass itself starting from analytic guesses only. No texel depends on its neighbours' order, and
a texel's result is a function of its own inputs and the coarse pass alone, so the table is bit-identical
for any tiling or worker count (ltc_code instead chains each texel off the previously fitted neighbour).
"""

from __future__ import annotations

import numpy as np
import warp as wp

from ..limits import LTC_FIT_GRID
from ..runtime.memo import RowMemo
from ..runtime.warp_runtime import MODULE_OPTIONS, kernel_factory, load_module
from .lobes import lobe

wp.set_module_options(MODULE_OPTIONS)

NELDER_MEAD_TOL = 1.0e-5  # ltc_code fit(): NelderMead(..., epsilon, 1e-5, 100, ...)
NELDER_MEAD_ITERS = 100
# successive restarts' simplex sizes in q = (log m11, log m22, m13/m11): the coarse pass starts far from the
# optimum and restarts twice; a texel starts from the coarse fits and runs once (a second restart at 0.02 cost
# 80 % more evaluations and changed the median error by 1e-9 relative on GGX 64^2)
COARSE_STEPS = (0.5, 0.1, 0.02)
FINE_STEPS = (0.1,)
# absolute stop: simplex values within (1e-6)^3 ∫ f^3 (relative L3 errors within 1e-6): reached only by lobes an
# LTC fits exactly (Lambert), whose E ~ 1e-22 would otherwise run every iteration on rounding noise
ATOL_RELATIVE = 1.0e-6
COARSE_NODES = 8  # coarse-pass texels per axis (including both ends)
M_MIN = 1.0e-7  # ltc_code FitLTC::update: m11, m22 >= 1e-7
ALBEDO_ORDER = 48  # lobe_albedo's Gauss-Legendre order in theta (half in phi): Zeltner's sheen albedo within 2e-7 of
# order 64 and 6e-6 of a 256^2 graded midpoint rule, at 1/60 of that rule's evaluations


@wp.struct
class Texels:
    """What the lobe is at every texel: view v, alpha, and a tabulated lobe's table (lutbake.ltc.tabulated; a
    1-element placeholder for analytic lobes)."""

    v: wp.array(dtype=wp.vec3)
    alpha: wp.array(dtype=float)
    tab: wp.array3d(dtype=float)


@wp.struct
class LobeSamples:
    """The lobe's importance samples per (texel, grid point): direction, f (n.l) and its density."""

    dirs: wp.array2d(dtype=wp.vec3d)
    f: wp.array2d(dtype=wp.float64)
    p: wp.array2d(dtype=wp.float64)


@wp.func
def ltc_eval(m_inv: wp.mat33d, det_inv: wp.float64, l: wp.vec3d):
    """D(l) = max(0, z_o)/pi |det M^-1| / |M^-1 l|^3, z_o = (M^-1 l).z / |M^-1 l| (Heitz et al. 2016, Eq. 3)."""
    lo = m_inv * l
    n = wp.length(lo)
    z = lo[2] / n
    if z <= wp.float64(0.0):
        return wp.float64(0.0)
    return z * wp.float64(0.3183098861837907) * det_inv / (n * n * n)


@kernel_factory
def kernels(lb):
    """(lobe_samples, heitz_error, lobe_values) Warp kernels for a Lobe, compiled once per Warp cache."""
    sample = lb.sample
    if lb.tabulate is not None:  # f takes the texel's table and index (lutbake.ltc.tabulated)
        f_cos, pdf, f_pdf = lb.f_cos, lb.pdf, lb.f_pdf
    else:
        f_cos0, pdf0, f_pdf0 = lb.f_cos, lb.pdf, lb.f_pdf

        @wp.func
        def f_cos(v: wp.vec3, l: wp.vec3, a: float, tab: wp.array3d(dtype=float), t: int):
            return f_cos0(v, l, a)

        @wp.func
        def pdf(v: wp.vec3, l: wp.vec3, a: float, tab: wp.array3d(dtype=float), t: int):
            return pdf0(v, l, a)

        @wp.func
        def f_pdf(v: wp.vec3, l: wp.vec3, a: float, tab: wp.array3d(dtype=float), t: int):
            return f_pdf0(v, l, a)

    @wp.kernel(enable_backward=False)
    def lobe_samples(x: Texels, grid: wp.array(dtype=wp.vec2), out: LobeSamples):
        """The lobe-sampled half of the metric does not depend on M: its directions, f (n.l) and density, once."""
        i, s = wp.tid()
        vi = x.v[i]
        a = x.alpha[i]
        u = grid[s]
        l = sample(vi, a, u[0], u[1])
        out.dirs[i, s] = wp.vec3d(wp.float64(l[0]), wp.float64(l[1]), wp.float64(l[2]))
        out.f[i, s] = wp.float64(f_cos(vi, l, a, x.tab, i))
        out.p[i, s] = wp.float64(pdf(vi, l, a, x.tab, i))

    @wp.kernel(enable_backward=False)
    def heitz_error(
        texel: wp.array(dtype=int),
        m: wp.array(dtype=wp.mat33d),
        x: Texels,
        magnitude: wp.array(dtype=wp.float64),
        cos_dirs: wp.array(dtype=wp.vec3d),
        lobe: LobeSamples,
        err: wp.array(dtype=wp.float64),
    ):
        """ltc_code computeError: 1/N^2 Σ over LTC samples and lobe samples of |f - mag D|^3 / (p_ltc + p_brdf)."""
        i = wp.tid()
        t = texel[i]
        mi = m[i]
        m_inv = wp.inverse(mi)
        det_inv = wp.abs(wp.determinant(m_inv))
        vi = x.v[t]
        a = x.alpha[t]
        mag = magnitude[t]
        acc = wp.float64(0.0)
        for s in range(cos_dirs.shape[0]):
            # LTC sample: l = M w_o / |M w_o|, w_o cosine-distributed (p_ltc = D, the normalised LTC). There
            # M^-1 l = w_o / |M w_o|, so Eq. 3 is D(l) = (w_o.z / pi) |det M^-1| |M w_o|^3: no second matrix product
            wo = cos_dirs[s]
            mw = mi * wo
            r = wp.length(mw)
            ld = mw / r
            l = wp.vec3(float(ld[0]), float(ld[1]), float(ld[2]))
            d = wo[2] * wp.float64(0.3183098861837907) * det_inv * r * r * r
            fp = f_pdf(vi, l, a, x.tab, t)
            e = wp.abs(wp.float64(fp[0]) - mag * d)
            q = d + wp.float64(fp[1])
            if q > wp.float64(0.0):
                acc += e * e * e / q
            # lobe sample (precomputed by lobe_samples)
            d2 = ltc_eval(m_inv, det_inv, lobe.dirs[t, s])
            e2 = wp.abs(lobe.f[t, s] - mag * d2)
            q2 = d2 + lobe.p[t, s]
            if q2 > wp.float64(0.0):
                acc += e2 * e2 * e2 / q2
        err[i] = acc / wp.float64(cos_dirs.shape[0])

    @wp.kernel(enable_backward=False)
    def lobe_values(texel: wp.array(dtype=int), l: wp.array(dtype=wp.vec3), x: Texels, out: wp.array(dtype=wp.float64)):
        """f (n.l) of texel[i] at direction l[i], as the fit sees it (a tabulated lobe: interpolated)."""
        i = wp.tid()
        t = texel[i]
        out[i] = wp.float64(f_cos(x.v[t], l[i], x.alpha[t], x.tab, t))

    return lobe_samples, heitz_error, lobe_values


def stratified_grid(n: int) -> np.ndarray:
    """ltc_code's N x N grid (U1 = (i + 0.5)/N fastest, U2 = (j + 0.5)/N), float32 (N^2, 2)."""
    u = (np.arange(n) + 0.5) / n
    u1, u2 = np.meshgrid(u, u)
    return np.stack([u1.ravel(), u2.ravel()], axis=1).astype(np.float32)


def cosine_dirs(grid: np.ndarray) -> np.ndarray:
    """ltc_code LTC::sample's cosine-distributed directions: theta = acos(sqrt(U1)), phi = 2 pi U2 (float64)."""
    u1, u2 = grid[:, 0].astype(np.float64), grid[:, 1].astype(np.float64)
    s = np.sqrt(1.0 - u1)
    return np.stack([s * np.cos(2 * np.pi * u2), s * np.sin(2 * np.pi * u2), np.sqrt(u1)], axis=1)


class Problem:
    """The per-texel data of a fit (views, alphas, magnitudes, frames) and its objective on Warp's CPU device."""

    def __init__(
        self,
        lobe_of,
        nov: np.ndarray,
        alpha: np.ndarray,
        magnitude: np.ndarray,
        n_grid: int = LTC_FIT_GRID,
        device: str = "cpu",
        workers: int = 1,
        tab: np.ndarray | None = None,
        symmetric: np.ndarray | None = None,
    ):
        """``tab``: a tabulated lobe's per-texel table given by the caller (lutbake.ltc.aniso: each texel's
        (alpha_y, cos phi, sin phi)) instead of Lobe.tabulate's; ``symmetric``: with a general_frame lobe, the texels
        whose lobe is symmetric about the plane of incidence (fitted in ltc_code's 3 parameters)."""
        self.lobe = lobe(lobe_of)  # a Lobe, or the name of one of lutbake's
        self.device = device
        self.nov = np.asarray(nov, np.float32)
        self.alpha = np.asarray(alpha, np.float32)
        self.magnitude = np.asarray(magnitude, np.float64)
        self.n = len(self.nov)
        nv = self.nov.astype(np.float64)
        self.v = np.stack([np.sqrt(np.maximum(1.0 - nv * nv, 0.0)), np.zeros_like(nv), nv], axis=1).astype(np.float32)
        self.isotropic = self.nov >= np.float32(1.0)
        self.grid_n = n_grid
        grid = stratified_grid(n_grid)
        lobe_samples, self._heitz, self._values = kernels(self.lobe)
        d = device
        load_module(lobe_samples.module, d)  # the three kernels' module, compiled once when tables prepare in parallel
        lb = self.lobe
        # a tabulated lobe's per-texel table (lutbake.ltc.tabulated, ``workers`` threads), else a 1-element placeholder
        if tab is None:
            tab = lb.tabulate(self.v, self.alpha, d, workers) if lb.tabulate else np.zeros((1, 1, 1), np.float32)
        self._texels = Texels()
        self._texels.v = wp.array(self.v, dtype=wp.vec3, device=d)
        self._texels.alpha = wp.array(self.alpha, dtype=float, device=d)
        self._texels.tab = wp.array(tab, dtype=float, device=d)
        self._cos = wp.array(cosine_dirs(grid), dtype=wp.vec3d, device=d)
        self._mag = wp.array(self.magnitude, dtype=wp.float64, device=d)
        s = len(grid)
        self._lobe = LobeSamples()
        self._lobe.dirs = wp.zeros((self.n, s), dtype=wp.vec3d, device=d)
        self._lobe.f = wp.zeros((self.n, s), dtype=wp.float64, device=d)
        self._lobe.p = wp.zeros((self.n, s), dtype=wp.float64, device=d)
        grid_d = wp.array(grid, dtype=wp.vec2, device=d)
        wp.launch(lobe_samples, dim=(self.n, s), inputs=[self._texels, grid_d, self._lobe], device=d)
        # from the lobe's samples: its average direction Σ (f / p) l (ltc_code computeAvgTerms) and ∫ f^3 ≈ Σ f^3 / p
        dirs, f, p = self.lobe_sample_arrays(slice(None))
        w = np.where(p > 0.0, f / np.where(p > 0.0, p, 1.0), 0.0)
        self.f3 = np.sum(f * f * w, axis=1) / s
        self.frame_z = self._frames(np.einsum("ts,tsk->tk", w, dirs))
        self.evaluations = 0
        self.normal_frame = lb.normal_frame
        self.general = lb.general_frame
        self.symmetric = np.zeros(self.n, bool) if symmetric is None else np.asarray(symmetric, bool)
        general = (7 if lb.free_frame else 5) if lb.general_frame else None
        self.dof = 2 if lb.normal_frame else general or (4 if lb.free_frame else 3)  # q's length (matrices)

    def _frames(self, avg: np.ndarray) -> np.ndarray:
        """Z = normalize(average direction with y cleared); (0, 0, 1) at normal incidence (ltc_code fitTab)."""
        z = avg.copy()
        if not self.lobe.general_frame:
            z[:, 1] = 0.0
        nrm = np.linalg.norm(z, axis=1)
        ok = nrm > 0.0
        z[ok] /= nrm[ok, None]
        z[~ok] = (0.0, 0.0, 1.0)
        z[self.isotropic] = (0.0, 0.0, 1.0)
        return z

    def matrices(self, texel: np.ndarray, q: np.ndarray) -> np.ndarray:
        """M = [X Y Z] * [[m11, 0, m13], [0, m22, 0], [0, 0, 1]] for q = (log m11, log m22, m13 / m11) (``dof`` 3,
        ltc_code's); with ``dof`` 4, q[:, 3] = d, the frame Z turned by d radians about y from the lobe's average
        direction (every M of a lobe symmetric about the xz-plane, up to scale, is of this form); with
        ``normal_frame`` (``dof`` 2) normal_frame_matrices."""
        if self.normal_frame:
            return normal_frame_matrices(q, self.isotropic[texel])
        if self.general:
            return general_matrices(self.frame_z[texel], q, self.symmetric[texel], self.isotropic[texel])
        m11 = np.maximum(np.exp(q[:, 0]), M_MIN)
        m22 = np.maximum(np.exp(q[:, 1]), M_MIN)
        m13 = q[:, 2] * m11
        iso = self.isotropic[texel]
        m22 = np.where(iso, m11, m22)
        m13 = np.where(iso, 0.0, m13)
        z = self.frame_z[texel]
        if q.shape[1] > 3:
            d = np.where(iso, 0.0, q[:, 3])
            c, s = np.cos(d), np.sin(d)
            z = np.stack([c * z[:, 0] + s * z[:, 2], z[:, 1], c * z[:, 2] - s * z[:, 0]], axis=1)
        k = len(texel)
        R = np.zeros((k, 3, 3))
        R[:, :, 2] = z
        R[:, 0, 0], R[:, 2, 0] = z[:, 2], -z[:, 0]  # X = (Z.z, 0, -Z.x)
        R[:, 1, 1] = 1.0
        A = np.zeros((k, 3, 3))
        A[:, 0, 0], A[:, 1, 1], A[:, 0, 2], A[:, 2, 2] = m11, m22, m13, 1.0
        return R @ A

    def error(self, texel: np.ndarray, m: np.ndarray) -> np.ndarray:
        """Heitz's metric E for the matrices ``m`` (k, 3, 3) at texels ``texel`` (k,) (any scale of M)."""
        k = len(texel)
        if k == 0:
            return np.zeros(0)
        d = self.device
        out = wp.zeros(k, dtype=wp.float64, device=d)
        wp.launch(
            self._heitz,
            dim=k,
            inputs=[
                wp.array(np.asarray(texel, np.int32), dtype=int, device=d),
                wp.array(np.ascontiguousarray(m, np.float64), dtype=wp.mat33d, device=d),
                self._texels,
                self._mag,
                self._cos,
                self._lobe,
                out,
            ],
            device=d,
        )
        self.evaluations += k
        return out.numpy()

    def f_cos(self, texel: np.ndarray, l: np.ndarray) -> np.ndarray:
        """The lobe f (n.l) the fit uses at texels ``texel`` (k,) and unit directions ``l`` (k, 3), float64."""
        d = self.device
        out = wp.zeros(len(texel), dtype=wp.float64, device=d)
        inputs = [wp.array(np.asarray(texel, np.int32), dtype=int, device=d)]
        inputs += [wp.array(np.asarray(l, np.float32), dtype=wp.vec3, device=d), self._texels, out]
        wp.launch(self._values, dim=len(texel), inputs=inputs, device=d)
        return out.numpy()

    def lobe_sample_arrays(self, texel: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The lobe's importance samples of ``texel`` (k,): directions (k, N^2, 3), f (n.l) and density (k, N^2)."""
        return self._lobe.dirs.numpy()[texel], self._lobe.f.numpy()[texel], self._lobe.p.numpy()[texel]

    def objective(self, texel: np.ndarray, q: np.ndarray) -> np.ndarray:
        return self.error(texel, self.matrices(texel, q))

    def relative(self, texel: np.ndarray, err: np.ndarray) -> np.ndarray:
        """The scale-free fit error e = (E / ∫ f^3)^(1/3) recorded per texel. ∫ f^3 is the lobe sampler's estimate,
        floored at Hölder's bound ∫ f^3 >= (∫ f)^3 / (2 pi)^2 = magnitude^3 / (4 pi^2): where a sampler misses a
        lobe (charlie at alpha -> 0 and grazing view puts it all within 1e-2 rad of the horizon) the estimate
        falls below that provable bound and the floor keeps e finite and meaningful (0 for a zero lobe)."""
        f3 = np.maximum(self.f3[texel], self.magnitude[texel] ** 3 / (4.0 * np.pi**2))
        return np.cbrt(np.where(f3 > 0.0, err / np.where(f3 > 0.0, f3, 1.0), 0.0))


def lobe_albedo(problem: Problem, order: int = ALBEDO_ORDER) -> np.ndarray:
    """∫ f (n.l) dω_l per texel of ``problem`` (the magnitude of a lobe no other integrator has: Lobe.magnitude
    "lobe") by the product Gauss-Legendre rule, ``order`` nodes in t and order / 2 in phi over [0, pi] doubled (the
    lobes are symmetric about the xz-plane), theta = pi/2 (1 - (1 - t)^2): nodes graded towards the horizon, where
    sheen lobes peak. float64 sums of the lobe's float32 values."""
    x, w = np.polynomial.legendre.leggauss(order)
    t, wt = (x + 1.0) / 2.0, w / 2.0
    theta = 0.5 * np.pi * (1.0 - (1.0 - t) ** 2)
    w_theta = wt * np.pi * (1.0 - t) * np.sin(theta)  # d theta / dt x the solid angle's sin theta
    x, w = np.polynomial.legendre.leggauss(order // 2)
    phi, w_phi = (x + 1.0) * np.pi / 2.0, w * np.pi  # the half circle's weights doubled
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    dirs = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1).reshape(-1, 3)
    weights = np.outer(w_theta, w_phi).ravel()
    texel = np.repeat(np.arange(problem.n), len(dirs))
    return (problem.f_cos(texel, np.tile(dirs, (problem.n, 1))).reshape(problem.n, -1) @ weights).astype(np.float64)


def normal_frame_matrices(q: np.ndarray, isotropic: np.ndarray) -> np.ndarray:
    """Zeltner, Burley & Chiang 2022's LTC (tizian/ltc-sheen fit_ltc_sheen_*.py; pbrt-v3 sheenltc.cpp evalLTC): in
    the normal's frame, M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]]; q = (log(1 / a), b) (the first as ltc_code's
    log m11: M scales x and y by 1 / a), b = 0 at normal incidence. Returns M (k, 3, 3)."""
    a = 1.0 / np.maximum(np.exp(q[:, 0]), M_MIN)
    b = np.where(isotropic, 0.0, q[:, 1])
    m = np.zeros((len(q), 3, 3))
    m[:, 0, 0] = m[:, 1, 1] = 1.0 / a
    m[:, 0, 2] = -b / a
    m[:, 2, 2] = 1.0
    return m


def frame_of(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(X0, Y0) of the frame Z (k, 3): X0 = normalize(y x Z) (ltc_code's X = (Z.z, 0, -Z.x) where Z.y = 0),
    Y0 = Z x X0."""
    x0 = np.stack([z[:, 2], np.zeros(len(z)), -z[:, 0]], axis=1)
    x0 /= np.linalg.norm(x0, axis=1, keepdims=True)
    return x0, np.cross(z, x0)


def general_matrices(z: np.ndarray, q: np.ndarray, symmetric: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """M of a lobe without a plane of symmetry (lutbake.ltc.aniso), up to scale and the clamped cosine's invariance
    under rotations about z (M ~ M R_z: Kt et al. 2022, Sec. 4): M = [X Y Z] [[m11, 0, m13], [0, m22, m23], [0, 0,
    1]], X = cos psi X0 + sin psi Y0, Y = Z x X (frame_of(Z)); q = (log m11, log m22, m13 / m11, m23 / m22, psi) with
    Z = the lobe's average direction ``z``, or (dof 7) q[:, 5:7] = (d1, d2) tilting it: Z = normalize(cos d1 cos d2 z
    + sin d1 X0 + sin d2 Y0) (d2 = 0: fit.Problem's free_frame rotation by d1). Every M R_z is of the 7-parameter
    form (a 2x2 block's SVD absorbs R_z). ``symmetric`` texels (a lobe symmetric about the xz-plane) take psi = m23 =
    d2 = 0: ltc_code's M (with d1: the free frame); ``normal`` ones (n.v = 1) also m13 = d1 = 0. Returns M (k, 3, 3)."""
    m11 = np.maximum(np.exp(q[:, 0]), M_MIN)
    m22 = np.maximum(np.exp(q[:, 1]), M_MIN)
    m13 = np.where(normal, 0.0, q[:, 2] * m11)
    m23 = np.where(symmetric | normal, 0.0, q[:, 3] * m22)
    psi = np.where(symmetric, 0.0, q[:, 4])
    if q.shape[1] > 5:
        d1 = np.where(normal, 0.0, q[:, 5])[:, None]
        d2 = np.where(symmetric | normal, 0.0, q[:, 6])[:, None]
        x0, y0 = frame_of(z)
        z = np.cos(d1) * np.cos(d2) * z + np.sin(d1) * x0 + np.sin(d2) * y0
        z /= np.linalg.norm(z, axis=1, keepdims=True)
    x0, y0 = frame_of(z)
    c, s = np.cos(psi)[:, None], np.sin(psi)[:, None]
    x, y = c * x0 + s * y0, c * y0 - s * x0
    a = np.zeros((len(q), 3, 3))
    a[:, 0, 0], a[:, 1, 1], a[:, 0, 2], a[:, 1, 2], a[:, 2, 2] = m11, m22, m13, m23, 1.0
    return np.stack([x, y, z], axis=2) @ a


def nelder_mead(
    fun,
    texel: np.ndarray,
    start: np.ndarray,
    step: float,
    tol: float = NELDER_MEAD_TOL,
    iters: int = NELDER_MEAD_ITERS,
    atol: np.ndarray | float = 0.0,
    f_start: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """ltc_code's downhill simplex (nelder_mead.h) run on every texel at once: ``fun(texel_subset, q)`` -> values.
    Each texel follows exactly the scalar algorithm (its own simplex, its own stopping test
    2 |f_lo - f_hi| < tol (|f_lo| + |f_hi|) + atol); the vector form only batches the objective calls.
    ``f_start``: fun at ``start`` where the caller has it (not evaluated again). Returns (best q (n, 3), best
    value (n,))."""
    n, dim = start.shape
    s = np.repeat(start[:, None, :], dim + 1, axis=1)
    for i in range(dim):
        s[:, i + 1, i] += step
    if f_start is None:
        f = fun(np.repeat(texel, dim + 1), s.reshape(-1, dim)).reshape(n, dim + 1)
    else:
        f = np.empty((n, dim + 1))
        f[:, 0] = f_start
        f[:, 1:] = fun(np.repeat(texel, dim), s[:, 1:].reshape(-1, dim)).reshape(n, dim)
    active = np.ones(n, bool)
    rows = np.arange(n)
    for _ in range(iters):
        order = np.argsort(f, axis=1, kind="stable")
        lo, nh, hi = order[:, 0], order[:, -2], order[:, -1]
        flo, fhi, fnh = f[rows, lo], f[rows, hi], f[rows, nh]
        a, b = np.abs(flo), np.abs(fhi)
        active &= ~(2.0 * np.abs(a - b) < (a + b) * tol + atol)
        idx = np.flatnonzero(active)
        if len(idx) == 0:
            break
        sh = s[idx, hi[idx]]
        o = (s[idx].sum(axis=1) - sh) / dim
        r = o + (o - sh)
        fr = fun(texel[idx], r)
        better_nh = fr < fnh[idx]
        expand = better_nh & (fr < flo[idx])
        contract = ~better_nh
        # expansion and contraction points are evaluated together (a texel needs one or the other)
        trial = np.where(expand[:, None], o + 2.0 * (o - sh), o - 0.5 * (o - sh))
        need = expand | contract
        ft = np.full(len(idx), np.inf)
        ft[need] = fun(texel[idx[need]], trial[need])
        new = sh.copy()
        fnew = fhi[idx].copy()
        take_e = expand & (ft < fr)
        take_r = better_nh & ~take_e
        take_c = contract & (ft < fhi[idx])
        new[take_e], fnew[take_e] = trial[take_e], ft[take_e]
        new[take_r], fnew[take_r] = r[take_r], fr[take_r]
        new[take_c], fnew[take_c] = trial[take_c], ft[take_c]
        s[idx, hi[idx]] = new
        f[idx, hi[idx]] = fnew
        shrink = idx[contract & ~take_c]
        if len(shrink):
            slo = s[shrink, lo[shrink]][:, None, :]
            s[shrink] = slo + 0.5 * (s[shrink] - slo)
            # the best vertex stays (slo + 0.5 * 0) and keeps its value: only the other dim vertices are evaluated
            moved = np.ones((len(shrink), dim + 1), bool)
            moved[np.arange(len(shrink)), lo[shrink]] = False
            fs = f[shrink]
            fs[moved] = fun(np.repeat(texel[shrink], dim), s[shrink][moved])
            f[shrink] = fs
    best = np.argmin(f, axis=1)
    return s[rows, best], f[rows, best]


def analytic_guesses(problem: Problem, texel: np.ndarray) -> np.ndarray:
    """Starting points without any other texel: isotropic lobes of scale 2 alpha (a mirror lobe is twice as
    wide as its NDF), alpha and 1, no skew, the frame at the average direction; (k, 3, dof) candidates q."""
    a = np.maximum(problem.alpha[texel].astype(np.float64), 1e-4)
    cands = [np.log(2.0 * a), np.log(a), np.zeros_like(a)]
    z = np.zeros_like(a)
    scales = 1 if problem.normal_frame else 2  # (log m11, b) or (log m11, log m22, ...)
    return np.stack([np.stack([c] * scales + [z] * (problem.dof - scales), axis=1) for c in cands], axis=1)


def best_of(problem: Problem, texel: np.ndarray, cands: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The candidate (k, c, dof) of least error per texel (first on ties) and that error."""
    k, c, dof = cands.shape
    f = problem.objective(np.repeat(texel, c), cands.reshape(-1, dof)).reshape(k, c)
    best = np.argmin(f, axis=1)
    return cands[np.arange(k), best], f[np.arange(k), best]


def refine(
    problem: Problem, texel: np.ndarray, start: np.ndarray, steps, f_start: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Nelder-Mead from ``start`` (of error ``f_start`` if known), restarted from its result at each simplex size of
    ``steps`` (each restart's first vertex keeps the value the previous run found)."""
    q, f = start, f_start
    atol = ATOL_RELATIVE**3 * problem.f3[texel]
    for step in steps:
        q, f = nelder_mead(problem.objective, texel, q, step, atol=atol, f_start=f)
    return q, f


# the ltc kind's per-texel fits (lutbake.ltc.table.LtcBake), shared by every table a process bakes: a texel's fit is a
# pure function of its own inputs (lobe, metric grid, device, n.v, alpha, magnitude) and its candidate starts
# (texel_keys), so two tables that fit a texel with equal inputs and candidates get the same bits; the memo fits it
# once (the ltc-hdrp preset, alpha_min 1e-3, differs from ltc-ggx only in the columns whose clamped alpha or coarse
# seeds differ). Rows (q, f) per texel.
MEMO = RowMemo()


def texel_keys(problem: Problem, texel: np.ndarray, points: np.ndarray, what: str) -> list[bytes]:
    """The memo keys of ``texel``: everything its fit from ``points`` (k, c, dof) reads (``what``: the fit options,
    the texel's inputs)."""
    head = repr((what, problem.lobe.name, problem.lobe.origin, problem.device, problem.grid_n, problem.dof))
    head = (head + repr((NELDER_MEAD_TOL, NELDER_MEAD_ITERS, ATOL_RELATIVE, M_MIN))).encode()
    points = np.ascontiguousarray(points, np.float64)
    rows = zip(problem.nov[texel], problem.alpha[texel], problem.magnitude[texel], points)
    return [head + n.tobytes() + a.tobytes() + m.tobytes() + c.tobytes() for n, a, m, c in rows]


def fit_from(
    problem: Problem, texel: np.ndarray, cands: np.ndarray, steps, memo: RowMemo | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Nelder-Mead (``refine`` at ``steps``) from the best of the candidates (k, c, dof) per texel; (q, f).
    With ``memo``, a texel fitted before with equal inputs and candidates is taken from it, and one whose best
    candidate equals the start of an earlier fit takes that fit's result (refine reads nothing else): same bits."""
    if memo is None or len(texel) == 0:
        start, f_start = best_of(problem, texel, cands)
        return refine(problem, texel, start, steps, f_start)

    def from_cands(i):
        start, f_start = best_of(problem, texel[i], cands[i])
        keys = texel_keys(problem, texel[i], start[:, None, :], f"start {steps}")
        return memo.run(keys, lambda j: refine(problem, texel[i][j], start[j], steps, f_start[j]))

    return memo.run(texel_keys(problem, texel, cands, f"candidates {steps}"), from_cands)


def coarse_nodes(n: int) -> np.ndarray:
    return np.unique(np.round(np.linspace(0, n - 1, min(COARSE_NODES, n))).astype(int))


def coarse_texels(ny: int, nx: int) -> np.ndarray:
    """The coarse-grid texels (rows coarse_nodes(ny), columns coarse_nodes(nx)), row-major in the ny x nx grid."""
    return (coarse_nodes(ny)[:, None] * nx + coarse_nodes(nx)[None, :]).ravel()


def coarse_pass(
    problem: Problem, ny: int, nx: int, memo: RowMemo | None = None, nodes: Problem | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fit the coarse-grid texels (rows ``iy``, columns ``ix``) from analytic guesses alone: texels of ``problem``,
    or the texels 0, 1, ... of ``nodes``, a problem holding just the coarse texels (coarse_texels' order), e.g. at
    other inputs than the table's (lutbake.kinds.ltc: the lobe's own alpha where a table clamps it).
    Returns (iy nodes, ix nodes, q of shape (len(iy), len(ix), dof))."""
    iy, ix = coarse_nodes(ny), coarse_nodes(nx)
    p, texel = (problem, coarse_texels(ny, nx)) if nodes is None else (nodes, np.arange(len(iy) * len(ix)))
    q, _ = fit_from(p, texel, analytic_guesses(p, texel), COARSE_STEPS, memo)
    return iy, ix, q.reshape(len(iy), len(ix), p.dof)


def seed_candidates(problem: Problem, texel: np.ndarray, nx: int, coarse) -> np.ndarray:
    """Per texel (k, 8, dof): the analytic guesses, the coarse fits of the (up to 4) surrounding coarse texels and
    their bilinear blend in q."""
    iy, ix, qc = coarse
    y, x = texel // nx, texel % nx
    j = np.clip(np.searchsorted(iy, y, side="right") - 1, 0, len(iy) - 2) if len(iy) > 1 else np.zeros_like(y)
    i = np.clip(np.searchsorted(ix, x, side="right") - 1, 0, len(ix) - 2) if len(ix) > 1 else np.zeros_like(x)
    j1, i1 = np.minimum(j + 1, len(iy) - 1), np.minimum(i + 1, len(ix) - 1)
    ty = np.where(iy[j1] > iy[j], (y - iy[j]) / np.maximum(iy[j1] - iy[j], 1), 0.0)[:, None]
    tx = np.where(ix[i1] > ix[i], (x - ix[i]) / np.maximum(ix[i1] - ix[i], 1), 0.0)[:, None]
    c00, c01, c10, c11 = qc[j, i], qc[j, i1], qc[j1, i], qc[j1, i1]
    blend = (1 - ty) * ((1 - tx) * c00 + tx * c01) + ty * ((1 - tx) * c10 + tx * c11)
    return np.concatenate([analytic_guesses(problem, texel), np.stack([c00, c01, c10, c11, blend], axis=1)], axis=1)


def fit_texels(
    problem: Problem, texel: np.ndarray, nx: int, coarse, memo: RowMemo | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Fitted M (k, 3, 3) and Heitz's error E (k,) at ``texel``, started from the best of its seed candidates."""
    q, f = fit_from(problem, texel, seed_candidates(problem, texel, nx, coarse), FINE_STEPS, memo)
    return problem.matrices(texel, q), f


def pack_inverse(m: np.ndarray) -> np.ndarray:
    """ltc_code packTab: M^-1 / (M^-1)_11, stored (M^-1_00, M^-1_20, M^-1_02, M^-1_22) in the row-major maths
    indexing used here (glm's invM[0][0], invM[0][2], invM[2][0], invM[2][2], glm being column-major); the
    shader rebuilds mat3(vec3(t.x, 0, t.y), vec3(0, 1, 0), vec3(t.z, 0, t.w)) (columns)."""
    inv = np.linalg.inv(m)
    inv = inv / inv[:, 1, 1][:, None, None]
    return np.stack([inv[:, 0, 0], inv[:, 2, 0], inv[:, 0, 2], inv[:, 2, 2]], axis=1)


def unpack_inverse(t: np.ndarray) -> np.ndarray:
    """(k, 4) packed coefficients -> M^-1 (k, 3, 3) (row-major maths indexing; the inverse of pack_inverse)."""
    k = len(t)
    inv = np.zeros((k, 3, 3))
    inv[:, 0, 0], inv[:, 2, 0], inv[:, 0, 2], inv[:, 2, 2] = t[:, 0], t[:, 1], t[:, 2], t[:, 3]
    inv[:, 1, 1] = 1.0
    return inv


def heitz_error_of_packed(problem: Problem, texel: np.ndarray, packed: np.ndarray) -> np.ndarray:
    """Heitz's metric of a stored table (its packed inverse matrices), e.g. the published ltc_code table."""
    return problem.error(texel, np.linalg.inv(unpack_inverse(packed)))
