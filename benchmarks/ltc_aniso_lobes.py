"""Anisotropic GGX LTC investigation (docs/ltc_aniso.md, "More than one lobe"): bench_ltc_aniso --breakdown finds the
error of the 8^4 tables to be one LTC's own (an LTC fitted at each configuration is no better than the table). Does a
sum of K LTCs, value(P) = Σ_k w_k I_P(M_k) (Heitz et al. 2016, Eq. 11 per lobe; w_k free, M_k general; the shader's
cost K polygon integrals), reach the goal (at most half the published table's median relative error and a third of
its p90 |error| / albedo), and does it survive the table's interpolation?

Fit (``fit_lobes``): lutbake.ltc.aniso_shaded.levenberg_marquardt on lutbake.ltc.shaded's cost (soft-L1 of
(value_j - G_j) / (G_j + 0.4 A)) over lutbake.ltc.shaded.texel_lights' 128 training lights plus HEMISPHERE's 9 (the
whole hemisphere, its halves and quadrants: they hold the lobes' total and its split, which small lights leave free),
G_j from the anisotropic sampler's TARGET_SAMPLES^2 stratified samples; unknowns each lobe's M^-1 (9, unit norm) and
log(w_k / A); start: lobe 1 the one-lobe shaded fit, lobe k > 1 its M broadened 2^(k-1) times in x and y, weights
0.8 A and 0.2 A / (K - 1).
1. Per configuration (bench_ltc_aniso's configurations, lights and ground truth; no table): K = 1, 2, 3.
2. The 8^4 table (alpha_x x alpha_y x theta x phi) with K = 2 fitted at each texel (the fitted texels, the others by
   the symmetries, each lobe on its own: lutbake.ltc.aniso.completed), at its nodes (each configuration moved to its
   nearest texel, the ground truth recomputed there) and interpolated (each lobe's M and w quadrilinear,
   lutbake.ltc.aniso.lookup: the shader's).
3. The same table fitted between its texels (``fit_between``): all 8^4 x 2 x (9 + 1) unknowns so that the
   interpolated sum minimises the shaded cost at ``--configs`` configurations uniform in table coordinates
   (ltc_aniso_between.training_set, 32 lights + HEMISPHERE each), plus mu |x - x0|^2 towards the per-texel table
   (x0's weights limited to the texel's magnitude: a larger one belongs to a lobe with almost no mass above the
   horizon). Levenberg-Marquardt, matrix-free: J^T J v by the configurations' dense 16-corner Jacobians and a sparse
   (texel x configuration) weight matrix, conjugate gradients with the Jacobi preconditioner.
Written: outputs/bench/ltc_aniso_lobes.json.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spla
from bench_ltc_aniso import OUT, configuration, configuration_fit, nearest_texel, shade, statistics, truth_and_albedo
from ltc_aniso_between import GRID, Between, damped_step, training_set

from lutbake.ltc import aniso, aniso_shaded, shaded
from lutbake.ltc.aniso import AnisoProblem
from lutbake.validate.ltc_area import LIGHTS, light_polygon

TARGET_SAMPLES = 128
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


def fit_lobes(nov, ax, ay, phi, albedo, m_view, lobes: int, iterations: int) -> tuple[np.ndarray, np.ndarray]:
    """View-frame M (k, K, 3, 3) and weights w (k, K) of K lobes at k texels or configurations (module docstring),
    from the one-lobe fit ``m_view`` (k, 3, 3)."""
    k = len(nov)
    ax, ay = np.asarray(ax, np.float32), np.asarray(ay, np.float32)
    polys = shaded.texel_lights(nov, np.sqrt(ax.astype(np.float64) * ay))
    polys = np.concatenate([polys, np.broadcast_to(HEMISPHERE, (k, *HEMISPHERE.shape))], axis=1)
    g, _ = shaded.targets(AnisoProblem(nov, ax, ay, phi, albedo, TARGET_SAMPLES), np.arange(k), polys)
    sw = 1.0 / np.maximum(g + shaded.ABS_WEIGHT * albedo[:, None], shaded.TINY)

    def residuals(x: np.ndarray) -> np.ndarray:
        t = np.tile(np.arange(k), len(x) // k)
        return (albedo[t, None] * integral_sum(x, lobes, t, polys) - g[t]) * sw[t]

    minv = np.linalg.inv(m_view)
    start = [(np.diag([2.0**-j, 2.0**-j, 1.0]) @ minv).reshape(k, 9) for j in range(lobes)]
    weights = [0.8] + [0.2 / (lobes - 1)] * (lobes - 1) if lobes > 1 else [1.0]
    x0 = np.concatenate(start + [np.full((k, 1), np.log(w)) for w in weights], axis=1)
    x = aniso_shaded.levenberg_marquardt(x0, residuals, aniso_shaded.unit_blocks(lobes), iterations)
    return np.linalg.inv(x[:, : 9 * lobes].reshape(k, lobes, 3, 3)), albedo[:, None] * np.exp(x[:, 9 * lobes :])


class BetweenLobes(Between):
    """The shaded cost of a K-lobe table x (texels, 10 K) = (M_1..M_K tangent frame row-major, w_1..w_K) through the
    interpolation, on one training set (ltc_aniso_between.Between's)."""

    def __init__(self, ts: dict, texels: int, lobes: int):
        super().__init__(ts)
        self.lobes = lobes
        cols = np.repeat(np.arange(self.n), 16)
        self.spread = sps.csr_matrix((ts["weight"].ravel(), (ts["texel"].ravel(), cols)), shape=(texels, self.n))
        self.gather = self.spread.T.tocsr()
        self.spread2 = self.spread.multiply(self.spread).tocsr()

    def residuals(self, x: np.ndarray) -> tuple[np.ndarray, ...]:
        """(z (n, L), each lobe's I (K, n, L), the interpolated x (n, 10 K))."""
        xi = self.gather @ x
        lobe = [self.integrals(xi[:, 9 * k : 9 * k + 9].reshape(-1, 3, 3)) for k in range(self.lobes)]
        value = sum(xi[:, 9 * self.lobes + k, None] * i for k, i in enumerate(lobe))
        return (value - self.ts["G"]) * self.scale, np.array(lobe), xi

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


def fit_between(x0: np.ndarray, model: BetweenLobes, iterations: int, mu: float, log=print) -> np.ndarray:
    """Levenberg-Marquardt from x0 on the model's cost + reg |x - x0|^2, reg = mu mean(diag J^T J) at x0."""
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
            return spla.cg(a, -grad.ravel(), M=pre, maxiter=150, rtol=1e-5)[0]

        x, lam, c_new = damped_step(model, x, x0, reg, c, lam, step_for)
        log(f"iteration {it}: cost {c:.6g} -> {c_new:.6g}, damping {lam:.2e}, {time.perf_counter() - t0:.1f} s")
    return x


def shade_lobes(table: np.ndarray, weights: np.ndarray, cfg, lights) -> np.ndarray:
    """Σ_k w_k I(M_k) through the interpolation: table (8^4, K, 3, 3) tangent frame, weights (8^4, K)."""
    est = 0.0
    for k in range(table.shape[1]):
        m, w = aniso.lookup(table[:, k].reshape(*GRID.n, 3, 3), GRID, *cfg, weights[:, k].reshape(*GRID.n, 1))
        est = est + shade(m[0], w[0, 0], lights)
    return est


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench-configs", type=int, default=240)
    ap.add_argument("--gt", type=int, default=256)
    ap.add_argument("--iterations", type=int, default=40, help="Levenberg-Marquardt steps of fit_lobes")
    ap.add_argument("--configs", type=int, default=20000, help="training configurations of fit_between")
    ap.add_argument("--between-iterations", type=int, default=20)
    ap.add_argument("--mu", type=float, default=0.001)
    a = ap.parse_args()
    seconds = {}
    t0 = time.perf_counter()
    mag, _ = aniso.magnitude_fresnel(GRID)
    l3, _ = aniso.fit_table(GRID, mag, workers=2)
    one, _ = aniso_shaded.refine_table(GRID, mag, l3, 32, workers=2)
    seconds["one_lobe_table"] = time.perf_counter() - t0

    nov, ax, ay, phi, mag_f = aniso.fitted_inputs(GRID, mag)
    fitted = aniso.fitted_texels(GRID)
    t0 = time.perf_counter()
    m_view = aniso.rotate_z(one.reshape(-1, 3, 3)[fitted], -phi)
    parts = [
        fit_lobes(nov[s], ax[s], ay[s], phi[s], mag_f[s], m_view[s], 2, a.iterations)
        for s in np.array_split(np.arange(len(nov)), 8)
    ]
    lobes = [
        aniso.completed(GRID, np.concatenate([p[0][:, k] for p in parts]), np.concatenate([p[1][:, k] for p in parts]))
        for k in range(2)
    ]
    per_texel = (np.stack([l[0].reshape(-1, 3, 3) for l in lobes], 1), np.stack([l[1].ravel() for l in lobes], 1))
    seconds["two_lobe_table"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    ts = training_set(a.configs, 32, 1000, HEMISPHERE)
    held = training_set(2000, 32, 2000, HEMISPHERE)
    x0 = np.concatenate([per_texel[0].reshape(-1, 18), np.minimum(per_texel[1], mag.reshape(-1, 1))], axis=1)
    model = BetweenLobes(ts, len(x0), 2)
    x = fit_between(x0, model, a.between_iterations, a.mu)
    between = (x[:, :18].reshape(-1, 2, 3, 3), x[:, 18:])
    held_model = BetweenLobes(held, len(x0), 2)
    held_cost = {"two_per_texel": held_model.cost(x0), "two_between": held_model.cost(x)}
    seconds["between_fit"] = time.perf_counter() - t0

    rng = np.random.default_rng(7)
    lights = [light_polygon(*spec[:7]) for spec in LIGHTS]
    rows, configs, truths = [], [], []
    for _ in range(a.bench_configs):
        cfg = configuration(rng)
        truth, albedo = truth_and_albedo(*cfg, lights, a.gt)
        configs.append(cfg)
        truths.append((truth, albedo))
        m, e = aniso.lookup(one, GRID, *cfg, mag[..., None])
        for name, est in (
            ("table, one lobe (the shaded fit)", shade(m[0], e[0, 0], lights)),
            ("table, two lobes per texel", shade_lobes(*per_texel, cfg, lights)),
            ("table, two lobes between texels", shade_lobes(*between, cfg, lights)),
        ):
            rows.extend((name, *cfg[:3], tr, es, e[0, 0]) for tr, es in zip(truth, est))
        node = nearest_texel(GRID, *cfg)
        node_truth, node_albedo = truth_and_albedo(*node, lights, a.gt)
        est = shade_lobes(*per_texel, node, lights)
        rows.extend(
            ("table, two lobes per texel, at nodes", *node[:3], tr, es, node_albedo) for tr, es in zip(node_truth, est)
        )
    cfg = np.array(configs)
    albedo = np.array([t[1] for t in truths])
    one_cfg = aniso.rotate_z(configuration_fit(cfg, albedo), -cfg[:, 3])  # view frame
    for count in (1, 2, 3):
        t0 = time.perf_counter()
        m, w = fit_lobes(np.cos(cfg[:, 2]), cfg[:, 0], cfg[:, 1], cfg[:, 3], albedo, one_cfg, count, a.iterations)
        seconds[f"per_configuration_{count}"] = time.perf_counter() - t0
        for c, (truth, alb), mk, wk in zip(configs, truths, m, w):
            est = sum(shade(aniso.rotate_z(mk[j][None], np.array([c[3]]))[0], wk[j], lights) for j in range(count))
            rows.extend((f"per configuration, {count} lobe(s)", *c[:3], tr, es, alb) for tr, es in zip(truth, est))
    report = {
        "goal": "at most half the published table's median relative error and a third of its p90 |error| / albedo",
        "held_out_cost": held_cost,
        "seconds": seconds,
        "settings": vars(a) | {"target_samples": TARGET_SAMPLES, "hemisphere_lights": len(HEMISPHERE)},
        "polygon_lights": statistics(rows),
    }
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "ltc_aniso_lobes.json").write_text(json.dumps(report, indent=1))
    for name, res in report["polygon_lights"].items():
        s = res["all"]
        print(f"{name:45s} {s['median_rel']:.4f} {s['p90_rel']:.3f} {s['p90_abs_over_albedo']:.4f}")


if __name__ == "__main__":
    main()
