"""Anisotropic GGX LTC tables of two or three lobes (kind ltc_aniso, ``lobes = 2`` / ``3``): a sum of K LTCs per texel,
value(P) = Σ_k w_k I_P(M_k) (Heitz et al. 2016, Eq. 11 per lobe; w_k free, M_k general; the shader's cost K polygon
integrals), fitted per texel and then between the texels, as benchmarks/ltc_aniso_lobes.py measures (docs/ltc_aniso.md,
"More than one lobe").

1. Per texel (``fit_lobes``): lutbake.ltc.aniso_shaded.levenberg_marquardt on lutbake.ltc.shaded's cost (soft-L1 of
   (value_j - G_j) / (G_j + 0.4 A)) over lutbake.ltc.shaded.texel_lights' 128 training lights plus ``HEMISPHERE``'s
   9 (the whole hemisphere, its halves and quadrants: they hold the lobes' total and its split, which small lights
   leave free), G_j from the anisotropic sampler's TARGET_SAMPLES^2 stratified samples; unknowns each lobe's M^-1 (9,
   unit norm) and log(w_k / A); start: lobe 1 the one-lobe shaded fit, lobe k > 1 its M broadened 2^(k-1) times in x
   and y, weights 0.8 A and 0.2 A / (K - 1). The fitted texels only; the others by the symmetries, each lobe on its
   own (lutbake.ltc.aniso.completed).
2. Between the texels (``fit_between``): every texel's K x (9 + 1) unknowns (tangent-frame M_k row-major, w_k) so
   that the interpolated sum (lutbake.ltc.aniso.lookup's quadrilinear M_k and w_k, the shader's) minimises the shaded
   cost at ``training_set``'s configurations uniform in table coordinates (32 lights + HEMISPHERE each), plus
   mu |x - x0|^2 towards the per-texel table (x0's weights limited to the texel's magnitude: a larger one belongs to
   a lobe with almost no mass above the horizon). Levenberg-Marquardt, matrix-free: J^T J v by the configurations'
   dense 16-corner Jacobians and a sparse (texel x configuration) weight matrix, conjugate gradients with the Jacobi
   preconditioner. M_k are left as the fit leaves them (not scaled to |M e_z| = 1 per texel: that would change the
   interpolated M the fit chose; the polygon integral does not see a matrix's scale).
3. Three lobes (``split_narrow``): the two-lobe between table's narrow lobe split in two, then the between fit again
   with three lobes. Three lobes fitted per texel (1.) are no start: their lobes trade roles from texel to texel, and
   the between fit from them ended worse than two lobes (on benchmarks/ltc_aniso_lobes.py's configurations: 0.041 /
   0.0124 against 0.029 / 0.0069, median relative / p90 |error| / albedo, at 20000 configurations); split from two
   lobes every lobe varies across the texels as the two-lobe table's do.
``sum_error``: the per-texel relative RMS of the sum's shaded residual at the texel itself. Cost at the paper's 8^4:
outputs/bench/ltc_aniso_lobes.json's seconds.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spla

from . import aniso, aniso_shaded, shaded
from . import lights as ltc_lights
from .aniso import AnisoProblem
from .aniso_grid import BETWEEN_CONFIGS, BETWEEN_ITERATIONS, SPLIT

TARGET_SAMPLES = 128  # fit_lobes' lobe samples per texel: TARGET_SAMPLES^2 stratified
LOBE_ITERATIONS = 40  # fit_lobes' Levenberg-Marquardt steps
BETWEEN_LIGHTS = 32  # training lights per configuration (+ HEMISPHERE)
BETWEEN_SEED = 1000  # the training set's random numbers
BETWEEN_SAMPLES = 48  # the training set's lobe samples per configuration: 48^2 stratified
MU = 0.001  # the between fit's pull towards the per-texel table, relative to mean(diag J^T J) at the start
CHUNK = 1024  # configurations per AnisoProblem (its lobe samples: CHUNK x 48^2 directions)
CG_ITERATIONS = 150
CG_RTOL = 1e-5
FAR = 1e3  # the hemisphere lights: quads on the plane z = 1 reaching FAR (to within 0.06 degrees of the horizon)
HEMISPHERE = np.array(
    [
        [(x, y, 1.0) for x, y in quad]
        for quad in (
            [(-1, -1), (1, -1), (1, 1), (-1, 1)],
            [(0, 0), (1, 0), (1, 1), (0, 1)],
            [(0, 0), (0, 1), (-1, 1), (-1, 0)],
            [(0, 0), (-1, 0), (-1, -1), (0, -1)],
            [(0, 0), (0, -1), (1, -1), (1, 0)],
            [(0, -1), (1, -1), (1, 1), (0, 1)],
            [(-1, -1), (0, -1), (0, 1), (-1, 1)],
            [(-1, 0), (1, 0), (1, 1), (-1, 1)],
            [(-1, -1), (1, -1), (1, 0), (-1, 0)],
        )
    ],
    np.float64,
) * np.array([FAR, FAR, 1.0])


def integral_sum(x: np.ndarray, lobes: int, texel: np.ndarray, polys: np.ndarray) -> np.ndarray:
    """Σ_k exp(x_w,k) I(M_k^-1) (n, L): x (n, 10 K) = (M_1^-1, ..., M_K^-1 row-major, log-weights)."""
    total = 0.0
    for k in range(lobes):
        minv = x[:, 9 * k : 9 * k + 9].reshape(-1, 3, 3)
        total = total + np.exp(x[:, 9 * lobes + k, None]) * shaded.integrals(minv, texel, polys)
    return total


def texel_targets(nov, ax, ay, phi, albedo, samples: int = TARGET_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """(the texels' lights (k, 128 + 9, 4, 3): lutbake.ltc.shaded.texel_lights and HEMISPHERE, view frame; their lobe
    integrals G (k, 137) from ``samples``^2 stratified samples)."""
    k = len(nov)
    ax, ay = np.asarray(ax, np.float32), np.asarray(ay, np.float32)
    polys = shaded.texel_lights(nov, np.sqrt(ax.astype(np.float64) * ay))
    polys = np.concatenate([polys, np.broadcast_to(HEMISPHERE, (k, *HEMISPHERE.shape))], axis=1)
    g, _ = shaded.targets(AnisoProblem(nov, ax, ay, phi, albedo, samples), np.arange(k), polys)
    return polys, g


def fit_lobes(nov, ax, ay, phi, albedo, m_view, lobes: int, iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """View-frame M (k, K, 3, 3) and weights w (k, K) of K lobes at k texels or configurations (module docstring),
    from the one-lobe fit ``m_view`` (k, 3, 3). Each texel reads its own inputs only."""
    k = len(nov)
    polys, g = texel_targets(nov, ax, ay, phi, albedo)
    sw = 1.0 / np.maximum(g + shaded.ABS_WEIGHT * albedo[:, None], shaded.TINY)

    def residuals(x: np.ndarray) -> np.ndarray:
        t = np.tile(np.arange(k), len(x) // k)
        return (albedo[t, None] * integral_sum(x, lobes, t, polys) - g[t]) * sw[t]

    minv = np.linalg.inv(m_view)
    start = [(np.diag([2.0**-j, 2.0**-j, 1.0]) @ minv).reshape(k, 9) for j in range(lobes)]
    weights = [0.8] + [0.2 / (lobes - 1)] * (lobes - 1) if lobes > 1 else [1.0]
    x0 = np.concatenate(start + [np.full((k, 1), np.log(w)) for w in weights], axis=1)
    # a trial's log-weight may overflow: its cost is then not finite and levenberg_marquardt refuses the step
    with np.errstate(over="ignore", invalid="ignore"):
        x = aniso_shaded.levenberg_marquardt(x0, residuals, aniso_shaded.unit_blocks(lobes), iterations)
    return np.linalg.inv(x[:, : 9 * lobes].reshape(k, lobes, 3, 3)), albedo[:, None] * np.exp(x[:, 9 * lobes :])


def rotation_z(phi: np.ndarray) -> np.ndarray:
    """R_z(phi) (k, 3, 3)."""
    return aniso.rotate_z(np.broadcast_to(np.eye(3), (len(phi), 3, 3)).copy(), phi)


def table_alphas(grid: aniso.Grid4, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(alpha_x, alpha_y) at table coordinates (a, b) in [0, 1] of ``grid``'s parametrisation (aniso_grid.Grid4)."""
    if grid.parametrisation == "alpha_lambda":
        b = a * b
    return np.maximum(a, grid.alpha_min), np.maximum(b, grid.alpha_min)


def training_set(grid: aniso.Grid4, n: int, count: int, seed: int, extra: np.ndarray | None = None) -> dict:
    """n configurations uniform in ``grid``'s table coordinates (phi in [0, pi/2]: the other quadrants are its
    reflections), ``count`` lights each (tangent frame; ``extra`` (e, 4, 3) view-frame lights added to every
    configuration's), their lobe integrals G (n, count + e), albedo A (n,), and the texels' flat indices (n, 16) and
    weights (n, 16) of the interpolation."""
    rng = np.random.default_rng(seed)
    u = rng.random((n, 4))
    ax, ay = table_alphas(grid, u[:, 0], u[:, 1])
    theta, phi = u[:, 2] * aniso.THETA_SCALE * np.pi / 2, u[:, 3] * np.pi / 2
    nov = np.cos(theta)
    v = np.stack([np.sin(theta), np.zeros(n), nov], axis=1)
    uniforms = rng.random((n, 2 * count + 16, ltc_lights.UNIFORMS))
    lit = ltc_lights.from_uniforms(uniforms, v[:, None, :], np.sqrt(ax * ay)[:, None])
    polys = ltc_lights.first_lit(lit, count)  # view frame
    if extra is not None:
        polys = np.concatenate([polys, np.broadcast_to(extra, (n, *extra.shape))], axis=1)
    g, albedo = np.zeros(polys.shape[:2]), np.zeros(n)
    for s in range(0, n, CHUNK):
        t = slice(s, s + CHUNK)
        p = AnisoProblem(
            nov[t], ax[t].astype(np.float32), ay[t].astype(np.float32), phi[t], np.ones(len(nov[t])), BETWEEN_SAMPLES
        )
        g[t], _ = shaded.targets(p, np.arange(p.n), polys[t])
        _, f, pdf = p.lobe_sample_arrays(slice(None))
        albedo[t] = np.mean(np.where(pdf > 0.0, f / np.where(pdf > 0.0, pdf, 1.0), 0.0), axis=1)
    index, weight = aniso.corner_weights(u, grid.n)
    flat = np.ravel_multi_index(tuple(index.transpose(2, 0, 1)), grid.n)
    polys_t = np.einsum("nij,nlvj->nlvi", rotation_z(phi), polys)
    return {"polys": polys_t, "G": g, "A": albedo, "texel": flat, "weight": weight}


class BetweenLobes:
    """The shaded cost of a K-lobe table x (texels, 10 K) = (M_1..M_K tangent frame row-major, w_1..w_K) through the
    interpolation, on one training set (``training_set``)."""

    def __init__(self, ts: dict, texels: int, lobes: int):
        self.ts = ts
        self.n = len(ts["A"])
        self.scale = 1.0 / np.maximum(ts["G"] + shaded.ABS_WEIGHT * ts["A"][:, None], shaded.TINY)
        self.lobes = lobes
        cols = np.repeat(np.arange(self.n), 16)
        self.spread = sps.csr_matrix((ts["weight"].ravel(), (ts["texel"].ravel(), cols)), shape=(texels, self.n))
        self.gather = self.spread.T.tocsr()
        self.spread2 = self.spread.multiply(self.spread).tocsr()

    def integrals(self, m: np.ndarray) -> np.ndarray:
        """I of every configuration's lights through M (r n, 3, 3): r blocks of the n configurations, in order."""
        t = np.tile(np.arange(self.n), len(m) // self.n)
        return shaded.integrals(np.linalg.inv(m), t, self.ts["polys"])

    def residuals(self, x: np.ndarray) -> tuple[np.ndarray, ...]:
        """(z (n, L), each lobe's I (K, n, L), the interpolated x (n, 10 K))."""
        xi = self.gather @ x
        lobe = [self.integrals(xi[:, 9 * k : 9 * k + 9].reshape(-1, 3, 3)) for k in range(self.lobes)]
        value = sum(xi[:, 9 * self.lobes + k, None] * i for k, i in enumerate(lobe))
        return (value - self.ts["G"]) * self.scale, np.array(lobe), xi

    def cost(self, x: np.ndarray) -> float:
        return float(np.sum(shaded.robust(self.residuals(x)[0])))

    def nonnegative_weights(self, x: np.ndarray) -> np.ndarray:
        """x with every w_k >= 0: a negative lobe would shade a light that holds only it below zero (the interpolated
        w_k of non-negative texels stay non-negative)."""
        out = x.copy()
        out[:, 9 * self.lobes :] = np.maximum(out[:, 9 * self.lobes :], 0.0)
        return out

    def jacobian(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """(J (n, L, 10 K) of the IRLS model per configuration w.r.t. its interpolated x, the weighted z, cost)."""
        z, lobe, xi = self.residuals(x)
        n, nl = z.shape
        cols = []
        for k in range(self.lobes):
            m = xi[:, 9 * k : 9 * k + 9]
            h = shaded.FD_STEP * np.maximum(np.abs(m), 1.0)
            trials = m[None] + h.T[:, :, None] * np.eye(9)[:, None, :]
            di = (self.integrals(trials.reshape(-1, 3, 3)).reshape(9, n, nl) - lobe[k][None]) / h.T[:, :, None]
            cols.append(di * xi[None, :, 9 * self.lobes + k, None])
        so = np.sqrt(shaded.robust_weight(z))
        jac = np.concatenate([*cols, lobe], axis=0) * (self.scale * so)[None]
        return np.ascontiguousarray(jac.transpose(1, 2, 0)), z * so, float(np.sum(shaded.robust(z)))


def damped_step(model, x: np.ndarray, x0: np.ndarray, reg: float, cost: float, lam: float, step_for, project=None):
    """Levenberg-Marquardt's inner loop: x + step_for(lam) (mapped by ``project`` onto the feasible set, if given: a
    projected Levenberg-Marquardt step) tried at up to 6 dampings (lam x 4 each) until the model's cost +
    reg |x - x0|^2 falls below ``cost``; (x, lam, the last cost tried)."""
    c_new = np.inf
    for _ in range(6):
        cand = x + step_for(lam).reshape(x.shape)
        cand = cand if project is None else project(cand)
        c_new = model.cost(cand) + reg * np.sum((cand - x0) ** 2)
        if np.isfinite(c_new) and c_new < cost:
            return cand, lam / 3.0, c_new
        lam *= 4.0
    return x, lam, c_new


def fit_between(x0: np.ndarray, model: BetweenLobes, iterations: int, mu: float = MU, log=None) -> np.ndarray:
    """Levenberg-Marquardt from x0 on the model's cost + reg |x - x0|^2, reg = mu mean(diag J^T J) at x0; ``log``
    (str -> None) is told each step's cost."""
    x, lam, reg = x0.copy(), 1e-3, None
    for it in range(iterations):
        t0 = time.perf_counter()
        jac, r, c = model.jacobian(x)
        d = model.spread2 @ np.einsum("nla,nla->na", jac, jac)
        reg = mu * d.mean() if reg is None else reg
        grad = model.spread @ np.einsum("nla,nl->na", jac, r) + reg * (x - x0)
        c += reg * np.sum((x - x0) ** 2)
        d = np.where(d > 0.0, d, d[d > 0.0].mean())

        def step_for(lam, reg=reg, d=d, jac=jac, grad=grad):
            damp = reg + lam * d

            def normal(v):
                v = v.reshape(x.shape)
                jv = np.einsum("nla,na->nl", jac, model.gather @ v)
                return (model.spread @ np.einsum("nla,nl->na", jac, jv) + damp * v).ravel()

            a = spla.LinearOperator((x.size, x.size), matvec=normal)
            pre = spla.LinearOperator((x.size, x.size), matvec=lambda v, p=(d + damp).ravel(): v / p)
            return spla.cg(a, -grad.ravel(), M=pre, maxiter=CG_ITERATIONS, rtol=CG_RTOL)[0]

        x, lam, c_new = damped_step(model, x, x0, reg, c, lam, step_for, model.nonnegative_weights)
        if log is not None:
            log(f"iteration {it}: cost {c:.6g} -> {c_new:.6g}, damping {lam:.2e}, {time.perf_counter() - t0:.1f} s")
    return x


def per_texel_table(
    grid: aniso.Grid4, magnitude: np.ndarray, one: np.ndarray, lobes: int, workers=1, iterations=LOBE_ITERATIONS
):
    """(M (texels, K, 3, 3) tangent frame, w (texels, K)) of fit_lobes at every fitted texel from the one-lobe shaded
    table ``one`` (n_a, n_b, n_theta, n_phi, 3, 3), in aniso's fixed tiles (the same bits for any worker count), the
    other texels by the symmetries, each lobe on its own."""
    nov, ax, ay, phi, mag = aniso.fitted_inputs(grid, magnitude)
    m_view = aniso.rotate_z(one.reshape(-1, 3, 3)[aniso.fitted_texels(grid)], -phi)
    out = aniso.in_tiles(
        lambda t: fit_lobes(nov[t], ax[t], ay[t], phi[t], mag[t], m_view[t], lobes, iterations),
        len(nov),
        workers,
    )
    done = [
        aniso.completed(grid, np.concatenate([o[0][:, k] for o in out]), np.concatenate([o[1][:, k] for o in out]))
        for k in range(lobes)
    ]
    return np.stack([d[0].reshape(-1, 3, 3) for d in done], 1), np.stack([d[1].ravel() for d in done], 1)


def spread(m: np.ndarray) -> np.ndarray:
    """|det M| / |M e_z|^3 of M (..., 3, 3): the solid angle a lobe spreads over (diag(a, a, 1): a^2), whatever M's
    scale."""
    return np.abs(np.linalg.det(m)) / np.linalg.norm(m[..., :, 2], axis=-1) ** 3


def narrow_first(m: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every texel's lobes (M (texels, K, 3, 3), w (texels, K)) sorted by ``spread``, narrowest first: the per-texel
    fit leaves the broader lobe first at some texels and second at others, and the quadrilinear mix of two texels
    whose lobes swapped roles is no fit (on the 8^4 benchmark, before the between fit, one lobe in three was out of
    this order)."""
    order = np.argsort(spread(m), axis=1, kind="stable")
    return np.take_along_axis(m, order[:, :, None, None], axis=1), np.take_along_axis(w, order, axis=1)


def between_start(magnitude: np.ndarray, per_texel: tuple) -> tuple[np.ndarray, np.ndarray]:
    """The between fit's start: per_texel_table's (M, w), the weights limited to the texel's magnitude (a larger one
    belongs to a lobe with almost no mass above the horizon), the lobes in ``narrow_first`` order."""
    return narrow_first(per_texel[0], np.minimum(per_texel[1], magnitude.reshape(-1, 1)))


def packed(m: np.ndarray, w: np.ndarray) -> np.ndarray:
    """x (texels, 10 K) = (M_1..M_K row-major, w_1..w_K): BetweenLobes' unknowns."""
    return np.concatenate([m.reshape(len(m), -1), w], axis=1)


def split_narrow(m: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Three lobes from two (M (texels, 2, 3, 3) narrowest first, w (texels, 2)): lobe 1 split into M_1 diag(s, s, 1)
    for s in SPLIT (first and last), half its weight each, lobe 2 between them: the sum nearly unchanged, and each lobe
    as smooth across the texels as the two-lobe table's."""
    narrow, broad = (np.diag([s, s, 1.0]) for s in SPLIT)
    half = 0.5 * w[:, 0]
    return np.stack([m[:, 0] @ narrow, m[:, 1], m[:, 0] @ broad], 1), np.stack([half, w[:, 1], half], 1)


def between_fit(ts: dict, m: np.ndarray, w: np.ndarray, iterations: int, mu: float = MU) -> tuple[np.ndarray, ...]:
    """(M (texels, K, 3, 3), w (texels, K)) of fit_between from (m, w) on the training set ``ts``, ``iterations``
    steps."""
    count = m.shape[1]
    x = fit_between(packed(m, w), BetweenLobes(ts, len(m), count), iterations, mu)
    return x[:, : 9 * count].reshape(-1, count, 3, 3), x[:, 9 * count :]


def between_table(
    grid: aniso.Grid4,
    magnitude: np.ndarray,
    per_texel: tuple,
    configs: int = BETWEEN_CONFIGS,
    iterations: int = BETWEEN_ITERATIONS,
    mu: float = MU,
    lobes: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(M (texels, K, 3, 3), w (texels, K)): between_fit from ``between_start`` (of per_texel_table's table) on
    ``configs`` training configurations (BETWEEN_LIGHTS lights + HEMISPHERE each, seed BETWEEN_SEED), ``iterations``
    steps (0: the start itself); ``lobes`` 3 from a two-lobe per-texel table: then split_narrow and between_fit again,
    ``iterations`` steps with three lobes on the same configurations (module docstring, 3.)."""
    m, w = between_start(magnitude, per_texel)
    if iterations:
        ts = training_set(grid, configs, BETWEEN_LIGHTS, BETWEEN_SEED, HEMISPHERE)
        m, w = between_fit(ts, m, w, iterations, mu)
    if lobes == 3:
        m, w = split_narrow(m, w)
        if iterations:
            m, w = between_fit(ts, m, w, iterations, mu)
    return m, w


def sum_error(grid: aniso.Grid4, magnitude: np.ndarray, m: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The relative RMS of the sum's shaded residual at every texel (n_a, n_b, n_theta, n_phi): sqrt(mean_j z_j^2),
    z_j = (Σ_k w_k I_j(M_k) - G_j) / (G_j + 0.4 A) over the texel's own lights (texel_targets: 128 training lights +
    HEMISPHERE, view frame, G_j from shaded.SAMPLES^2 lobe samples), A the texel's magnitude; M (texels, K, 3, 3)
    tangent frame, w (texels, K). The residual of the texel itself: between the texels the table is the
    interpolation, which the between fit weighs and this does not."""
    ax2, ay2 = grid.alphas()
    _, _, theta, phi = grid.axes()
    i, j, k, l = np.indices(grid.n).reshape(4, -1)
    a = magnitude.reshape(-1)
    nov = np.cos(theta[k]).astype(np.float32)
    polys, g = texel_targets(nov, ax2[i, j], ay2[i, j], phi[l], a, shaded.SAMPLES)
    t = np.arange(len(a))
    value = sum(
        w[:, q, None] * shaded.integrals(np.linalg.inv(aniso.rotate_z(m[:, q], -phi[l])), t, polys)
        for q in range(m.shape[1])
    )
    z = (value - g) / np.maximum(g + shaded.ABS_WEIGHT * a[:, None], shaded.TINY)
    return np.sqrt(np.mean(z * z, axis=1)).reshape(grid.n)


def lobe_textures(grid: aniso.Grid4, magnitude, fresnel, m: np.ndarray, w: np.ndarray) -> np.ndarray:
    """3 K RGBA 3D textures (3 K, n_a n_b, n_theta, n_phi, 4): lobe k's lutbake.ltc.aniso.texture_layout with
    (M_k, w_k, w_k fresnel / magnitude, sum_error) in place of (M, magnitude, fresnel, fit_error), so that
    f0 t2.y + (1 - f0) t2.z of each set is lobe k's share of the one-lobe shader's Schlick term."""
    err = sum_error(grid, magnitude, m, w)
    ratio = fresnel / magnitude
    sets = []
    for q in range(m.shape[1]):
        wq = w[:, q].reshape(grid.n)
        sets.append(aniso.texture_layout(m[:, q].reshape(*grid.n, 3, 3), wq, wq * ratio, err))
    return np.concatenate(sets, axis=0)
