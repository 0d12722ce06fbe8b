"""Anisotropic GGX LTC investigation (docs/ltc_aniso.md, "More than one lobe"; the fit: lutbake.ltc.aniso_lobes, as the
kind's ``lobes = 2``): bench_ltc_aniso --breakdown finds the error of the 8^4 tables to be one LTC's own (an LTC
fitted at each configuration is no better than the table). Does a sum of K LTCs, value(P) = Σ_k w_k I_P(M_k) (Heitz
et al. 2016, Eq. 11 per lobe; w_k free, M_k general; the shader's cost K polygon integrals), reach the goal (at most
half the published table's median relative error and a third of its p90 |error| / albedo), and does it survive the
table's interpolation?

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
3. The same table fitted between its texels (lutbake.ltc.aniso_lobes.between_table, the kind's ``lobes = 2``: each
   texel's lobes put narrowest first, then fit_between): all 8^4 x 2 x (9 + 1) unknowns so that the
   interpolated sum minimises the shaded cost at ``--configs`` configurations uniform in table coordinates
   (lutbake.ltc.aniso_lobes.training_set, 32 lights + HEMISPHERE each), plus mu |x - x0|^2 towards the per-texel table
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
from bench_ltc_aniso import OUT, configuration, configuration_fit, nearest_texel, shade, statistics, truth_and_albedo
from ltc_aniso_between import GRID

from lutbake.ltc import aniso, aniso_shaded
from lutbake.ltc.aniso_grid import BETWEEN_CONFIGS
from lutbake.ltc.aniso_lobes import (
    BETWEEN_LIGHTS,
    BETWEEN_SEED,
    HEMISPHERE,
    TARGET_SAMPLES,
    BetweenLobes,
    between_fit,
    between_start,
    fit_lobes,
    packed,
    per_texel_table,
    split_narrow,
    training_set,
)
from lutbake.validate.ltc_area import LIGHTS, light_polygon


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
    ap.add_argument("--configs", type=int, default=BETWEEN_CONFIGS, help="training configurations of fit_between")
    ap.add_argument("--between-iterations", type=int, default=20)
    ap.add_argument("--mu", type=float, default=0.001)
    a = ap.parse_args()
    seconds = {}
    t0 = time.perf_counter()
    mag, _ = aniso.magnitude_fresnel(GRID)
    l3, _ = aniso.fit_table(GRID, mag, workers=2)
    one, _ = aniso_shaded.refine_table(GRID, mag, l3, 32, workers=2)
    seconds["one_lobe_table"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    per_texel = per_texel_table(GRID, mag, one, 2, workers=2, iterations=a.iterations)
    seconds["two_lobe_table"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    # the kind's between_table (lobes = 2, then 3), its two-lobe table kept: one training set, two fits
    ts = training_set(GRID, a.configs, BETWEEN_LIGHTS, BETWEEN_SEED, HEMISPHERE)
    between = between_fit(ts, *between_start(mag, per_texel), a.between_iterations, a.mu)
    seconds["between_fit"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    three = between_fit(ts, *split_narrow(*between), a.between_iterations, a.mu)  # lobes = 3
    seconds["between_fit_three_lobes"] = time.perf_counter() - t0
    held_set = training_set(GRID, 2000, 32, 2000, HEMISPHERE)
    held_cost = {
        name: BetweenLobes(held_set, int(np.prod(GRID.n)), table[1].shape[1]).cost(packed(*table))
        for name, table in (
            ("two_per_texel", between_start(mag, per_texel)),
            ("two_between", between),
            ("three_between", three),
        )
    }

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
            ("table, three lobes between texels", shade_lobes(*three, cfg, lights)),
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
