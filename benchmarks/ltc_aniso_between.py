"""Anisotropic GGX LTC investigation (docs/ltc_aniso.md, "Where the error comes from"): the 8^4 table fitted between
its texels. Does choosing the texels so that the *interpolated* LTC (lutbake.ltc.aniso.lookup's quadrilinear M and
magnitude, the shader's) minimises the shaded cost at points between the texels beat lutbake's per-texel shaded fit
(lutbake.ltc.aniso_shaded, the start)?

Training set: ``--configs`` configurations uniform in the table's coordinates u in [0, 1]^4 (alpha_x, alpha_y,
theta / (0.9999 pi/2), phi / (pi/2)), ``--lights`` lights each (lutbake.ltc.lights.from_uniforms on the configuration's
own uniform numbers), their lobe integrals G_j from the anisotropic sampler's 48^2 stratified samples
(lutbake.ltc.shaded.targets) and the albedo A from the same samples; the held-out set: the same from another seed.
Cost: lutbake.ltc.shaded's soft-L1 of z_j = (magnitude I_j - G_j) / (G_j + 0.4 A) through the interpolated (M,
magnitude), plus mu |x - x0|^2 (x0 the start; ``--mu`` relative to the mean diagonal of J^T J).
Unknowns: every texel's 9 M coefficients and magnitude (8^4 x 10). Levenberg-Marquardt: dI/dM by forward differences
at the interpolated M, chained through the 16 corner weights; J^T J assembled per pair of texels (Σ_c w_k w_k' J_c^T
J_c, J_c the configuration's 10-column Jacobian) and solved by conjugate gradients preconditioned by the inverse 10 x 10
diagonal blocks. Reported (outputs/bench/ltc_aniso_between.json): the held-out cost of the start and of the fit, and
bench_ltc_aniso's polygon-light statistics of both (its configurations, lights and ground truth).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spla
from bench_ltc_aniso import OUT, PUBLISHED, configuration, shade, statistics, truth_and_albedo

from lutbake.ltc import aniso, aniso_shaded, shaded
from lutbake.ltc.aniso_lobes import BetweenLobes, damped_step, training_set
from lutbake.validate.ltc_area import LIGHTS, light_polygon

GRID = aniso.Grid4("alphax_alphay", (8, 8, 8, 8))
PARAMS = 10  # per texel: M (9, row-major, tangent frame) and magnitude
CG_ITERATIONS = 200
CG_RTOL = 1e-5


class Between(BetweenLobes):
    """The shaded cost of a table x (texels, PARAMS) through the interpolation, on one training set: one lobe,
    its normal equations assembled per pair of texels."""

    def __init__(self, ts: dict):
        super().__init__(ts, int(np.prod(GRID.n)), 1)

    def residuals(self, x: np.ndarray) -> tuple[np.ndarray, ...]:
        """(z (n, L), I (n, L), the interpolated x (n, PARAMS))."""
        xi = np.einsum("nc,nck->nk", self.ts["weight"], x[self.ts["texel"]])
        i = self.integrals(xi[:, :9].reshape(-1, 3, 3))
        return (xi[:, 9:] * i - self.ts["G"]) * self.scale, i, xi

    def normal_equations(self, x: np.ndarray) -> tuple[sps.csr_matrix, np.ndarray, np.ndarray, float]:
        """(J^T J, J^T z, its diagonal 10 x 10 blocks (texels, 10, 10), cost) of the IRLS model of the soft-L1."""
        z, i, xi = self.residuals(x)
        n, nl = z.shape
        m = xi[:, :9]
        h = shaded.FD_STEP * np.maximum(np.abs(m), 1.0)
        trials = m[None] + h.T[:, :, None] * np.eye(9)[:, None, :]  # (9, n, 9)
        di = (self.integrals(trials.reshape(-1, 3, 3)).reshape(9, n, nl) - i[None]) / h.T[:, :, None]
        so = np.sqrt(shaded.robust_weight(z))
        jac = np.concatenate([di * xi[None, :, 9:], i[None]], axis=0) * (self.scale * so)[None]  # (10, n, L)
        jtj_c = np.einsum("anl,bnl->nab", jac, jac).reshape(n, PARAMS * PARAMS)
        jtz_c = np.einsum("anl,nl->na", jac, z * so)
        texel, w = self.ts["texel"], self.ts["weight"]
        nt = len(x)
        pair = (np.repeat(texel, 16, axis=1) * nt + np.tile(texel, (1, 16))).ravel()
        keys, slot = np.unique(pair, return_inverse=True)
        ww = (w[:, :, None] * w[:, None, :]).reshape(-1)
        spread = sps.csr_matrix((ww, (slot, np.repeat(np.arange(n), 256))), shape=(len(keys), n))
        blocks = (spread @ jtj_c).reshape(-1, PARAMS, PARAMS)
        row, col = keys // nt, keys % nt
        a, b = np.meshgrid(np.arange(PARAMS), np.arange(PARAMS), indexing="ij")
        rows = (row[:, None, None] * PARAMS + a[None]).ravel()
        cols = (col[:, None, None] * PARAMS + b[None]).ravel()
        jtj = sps.csr_matrix((blocks.ravel(), (rows, cols)), shape=(PARAMS * nt, PARAMS * nt))
        jtz = np.zeros((nt, PARAMS))
        np.add.at(jtz, texel.ravel(), (w[:, :, None] * jtz_c[:, None, :]).reshape(-1, PARAMS))
        diag = np.zeros((nt, PARAMS, PARAMS))
        diag[row[row == col]] = blocks[row == col]
        return jtj, jtz.ravel(), diag, float(np.sum(shaded.robust(z)))


def block_cg(a: sps.csr_matrix, rhs: np.ndarray, blocks: np.ndarray) -> np.ndarray:
    """a^-1 rhs by conjugate gradients, preconditioned by the inverse diagonal blocks."""
    inv = np.linalg.inv(blocks)
    n = len(blocks)
    pre = spla.LinearOperator(a.shape, matvec=lambda v: np.einsum("nab,nb->na", inv, v.reshape(n, PARAMS)).ravel())
    x, _ = spla.cg(a, rhs, M=pre, maxiter=CG_ITERATIONS, rtol=CG_RTOL)
    return x


def fit(x0: np.ndarray, ts: dict, iterations: int, mu: float, log=print) -> np.ndarray:
    """Levenberg-Marquardt from x0 on the training set's cost + reg |x - x0|^2, reg = mu mean(diag J^T J) at x0."""
    model = Between(ts)
    x, lam, reg = x0.copy(), 1e-3, None
    for it in range(iterations):
        t0 = time.perf_counter()
        jtj, jtz, diag, c = model.normal_equations(x)
        reg = mu * jtj.diagonal().mean() if reg is None else reg
        jtz, c = jtz + reg * (x - x0).ravel(), c + reg * np.sum((x - x0) ** 2)
        d = jtj.diagonal() + reg
        d = np.where(d > 0.0, d, d[d > 0.0].mean())

        def step_for(lam, reg=reg, d=d, jtj=jtj, jtz=jtz, diag=diag):
            blocks = diag + (reg + lam * d.reshape(-1, PARAMS))[:, :, None] * np.eye(PARAMS)
            return block_cg((jtj + sps.diags(reg + lam * d)).tocsr(), -jtz, blocks)

        x, lam, c_new = damped_step(model, x, x0, reg, c, lam, step_for)
        log(f"iteration {it}: cost {c:.6g} -> {c_new:.6g}, damping {lam:.2e}, {time.perf_counter() - t0:.1f} s")
    return x


def bench_rows(tables: dict, configs: int, gt: int) -> list:
    """bench_ltc_aniso's rows (its configurations, lights and ground truth) of each (M table, magnitude)."""
    rng = np.random.default_rng(7)
    lights = [light_polygon(*spec[:7]) for spec in LIGHTS]
    rows = []
    for _ in range(configs):
        ax, ay, theta, phi = configuration(rng)
        truth, _ = truth_and_albedo(ax, ay, theta, phi, lights, gt)
        for name, (m_table, magnitude) in tables.items():
            m, e = aniso.lookup(m_table, GRID, ax, ay, theta, phi, magnitude[..., None])
            est = shade(m[0], e[0, 0], lights)
            rows.extend((name, ax, ay, theta, tr, es, e[0, 0]) for tr, es in zip(truth, est))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--configs", type=int, default=20000, help="training configurations")
    ap.add_argument("--lights", type=int, default=32, help="training lights per configuration")
    ap.add_argument("--held-out", type=int, default=2000)
    ap.add_argument("--iterations", type=int, default=4)
    ap.add_argument("--mu", type=float, default=1.0)
    ap.add_argument("--bench-configs", type=int, default=240)
    ap.add_argument("--gt", type=int, default=256)
    a = ap.parse_args()
    t0 = time.perf_counter()
    mag, _ = aniso.magnitude_fresnel(GRID)
    l3, _ = aniso.fit_table(GRID, mag)
    start, _ = aniso_shaded.refine_table(GRID, mag, l3, 32)
    t_start = time.perf_counter() - t0
    t0 = time.perf_counter()
    ts, held = training_set(GRID, a.configs, a.lights, 1000), training_set(GRID, a.held_out, a.lights, 2000)
    t_sets = time.perf_counter() - t0
    x0 = np.concatenate([start.reshape(-1, 9), mag.reshape(-1, 1)], axis=1)
    t0 = time.perf_counter()
    x = fit(x0, ts, a.iterations, a.mu)
    t_fit = time.perf_counter() - t0
    between = (x[:, :9].reshape(*GRID.n, 3, 3), x[:, 9].reshape(GRID.n))
    tables = {"published": (np.load(PUBLISHED).astype(np.float64), mag), "lutbake_shaded": (start, mag)}
    tables["lutbake_between"] = between
    report = {
        "training": {"configs": a.configs, "lights": a.lights, "seed": 1000, "mu": a.mu, "iterations": a.iterations},
        "held_out_cost": {"configs": a.held_out, "lutbake_shaded": Between(held).cost(x0), "lutbake_between": None},
        "seconds": {"shaded_table": t_start, "training_sets": t_sets, "between_fit": t_fit},
        "magnitude_of_between": {"min": float(between[1].min()), "max": float(between[1].max())},
    }
    report["held_out_cost"]["lutbake_between"] = Between(held).cost(x)
    report["polygon_lights"] = statistics(bench_rows(tables, a.bench_configs, a.gt))
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "ltc_aniso_between.json").write_text(json.dumps(report, indent=1))
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
