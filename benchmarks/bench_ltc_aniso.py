"""Anisotropic GGX LTC tables (lutbake.ltc.aniso) against the published 8^4 table of Kt, Heitz, Dupuy & Narayanan
2022 (AakashKT/LTC-Anisotropic LUT/alphax_alphay_theta_phi.npy, tests/data), through the same reconstruction.

1. lutbake's 8^4 table (the paper's texels, parametrisation alpha_x x alpha_y x theta x phi): magnitude and fresnel
   (lutbake.ltc.aniso.magnitude_fresnel), the L3 fit (frame "free"), timed; written to outputs/bench/ltc_aniso/ in
   the paper's .npy layout and the shader's texture layout (lutbake.ltc.aniso.texture_layout).
2. The L3 relative error of both tables at every fitted texel (lutbake's metric).
3. Polygon lights (lutbake.validate.ltc_area's light set) at random (alpha_x, alpha_y, theta, phi): the ground truth
   ∫_P f (n.l) dω by anisotropic VNDF sampling (numpy, written here from Heitz 2018: independent of the Warp terms),
   S^2 stratified samples, weight G2 / G1(v); the LTC side: lutbake.ltc.aniso.lookup (the shader's quadrilinear
   interpolation of M and of the magnitude) then the exact polygon integral of M^-1 p (two-sided). Both tables use
   lutbake's magnitude: the comparison is of the matrices. Per band of roughness max(alpha), anisotropy
   min/max(alpha) and view theta: median and p90 relative error (where the truth exceeds 1e-3 x albedo) and p90
   |error| / albedo.
4. ``--shaded``: a third table, lutbake's L3 table refined to polygon lights (lutbake.ltc.aniso_shaded, the
   ltc_aniso kind's ``fit = "shaded"``; its training lights are lutbake.ltc.shaded's, another seed than these).
5. ``--breakdown``: where each table's error comes from, on the same configurations and lights: "at nodes" (each
   configuration moved to its nearest texel, ground truth recomputed there: the texel's own M, no interpolation),
   "exact albedo" (the interpolated M, magnitude = the ground truth's albedo instead of the interpolated one),
   "ground truth, second estimate" (the ground truth on a Cranley-Patterson-shifted grid against the first: its
   noise) and "per configuration" (no table: lutbake's L3 fit then shaded refinement at the configuration itself,
   magnitude = the ground truth's albedo: the LTC's own error under lutbake's shaded objective).

The paper's fitting script (fitting/fit_alphax_alphay_theta_phi.py) needs torch with CUDA ('cuda:0' is hard-coded
in every tensor it makes); it is not run here (see the JSON's "paper_fit"; its time on the CPU: docs/ltc_aniso.md).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from lutbake.ltc import aniso, aniso_shaded, polygon
from lutbake.validate.ltc_area import GT_FLOOR, LIGHTS, hits, light_polygon

ROOT = Path(__file__).resolve().parents[1]
PUBLISHED = ROOT / "tests" / "data" / "ltc_aniso_alphax_alphay_theta_phi.npy"
OUT = ROOT / "outputs" / "bench"


def lambda_aniso(w: np.ndarray, ax: float, ay: float) -> np.ndarray:
    """Heitz 2014, Eq. 86."""
    z2 = np.maximum(w[:, 2] ** 2, 1e-30)
    return 0.5 * (np.sqrt(1.0 + (ax * ax * w[:, 0] ** 2 + ay * ay * w[:, 1] ** 2) / z2) - 1.0)


def vndf_samples(v: np.ndarray, ax: float, ay: float, s: int, shift=None) -> tuple[np.ndarray, np.ndarray]:
    """l and the weight f (n.l) / p = G2 / G1(v) for h by anisotropic VNDF sampling (Heitz 2018, Listing 1); ``shift``
    (2,): the stratified grid moved by it modulo 1 (Cranley-Patterson)."""
    u = (np.stack(np.meshgrid(np.arange(s), np.arange(s), indexing="ij"), -1).reshape(-1, 2) + 0.5) / s
    if shift is not None:
        u = np.mod(u + shift, 1.0)
    vh = np.array([ax * v[0], ay * v[1], v[2]])
    vh /= np.linalg.norm(vh)
    lensq = vh[0] ** 2 + vh[1] ** 2
    t1 = np.array([-vh[1], vh[0], 0.0]) / np.sqrt(lensq) if lensq > 0 else np.array([1.0, 0.0, 0.0])
    t2 = np.cross(vh, t1)
    r, ph = np.sqrt(u[:, 0]), 2.0 * np.pi * u[:, 1]
    p1, p2 = r * np.cos(ph), r * np.sin(ph)
    sv = 0.5 * (1.0 + vh[2])
    p2 = (1.0 - sv) * np.sqrt(np.maximum(1.0 - p1 * p1, 0.0)) + sv * p2
    nh = p1[:, None] * t1 + p2[:, None] * t2 + np.sqrt(np.maximum(1.0 - p1 * p1 - p2 * p2, 0.0))[:, None] * vh
    h = np.stack([ax * nh[:, 0], ay * nh[:, 1], np.maximum(nh[:, 2], 0.0)], axis=1)
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    l = 2.0 * (h @ v)[:, None] * h - v
    lam_v = lambda_aniso(v[None], ax, ay)[0]
    w = np.where(l[:, 2] > 0, (1.0 + lam_v) / (1.0 + lam_v + lambda_aniso(l, ax, ay)), 0.0)
    return l, w


def ltc_integral(m: np.ndarray, poly: np.ndarray) -> float:
    """The LTC's polygon integral: the form factor of M^-1 p (two-sided)."""
    return abs(polygon.form_factor(poly @ np.linalg.inv(m).T))


def truth_and_albedo(ax, ay, theta, phi, lights, s, shift=None) -> tuple[np.ndarray, float]:
    """The ground truth of every light and the albedo ∫ f (n.l) dω at one configuration (S^2 VNDF samples)."""
    v = np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    l, w = vndf_samples(v, ax, ay, s, shift)
    return np.array([np.sum(w[hits(l, p)]) for p in lights]) / s**2, float(np.sum(w)) / s**2


def nearest_texel(grid: aniso.Grid4, ax, ay, theta, phi) -> tuple[float, ...]:
    """(alpha_x, alpha_y, theta, phi) of the texel nearest to a configuration in table coordinates (phi folded by
    aniso.quadrant, the texel's phi unfolded into the configuration's quadrant)."""
    folded, _ = aniso.quadrant(np.array([phi]))
    u = np.array([ax, ay, theta / (aniso.THETA_SCALE * np.pi / 2), folded[0] / (np.pi / 2)])
    k = np.clip(np.rint(u * (np.array(grid.n) - 1)).astype(int), 0, np.array(grid.n) - 1)
    a, b, th, ph = grid.axes()
    q = min(int(np.mod(phi, 2.0 * np.pi) // (np.pi / 2)), 3)
    p = [ph[k[3]], np.pi - ph[k[3]], np.pi + ph[k[3]], 2.0 * np.pi - ph[k[3]]][q]
    return max(a[k[0]], grid.alpha_min), max(b[k[1]], grid.alpha_min), th[k[2]], p


def configuration_fit(cfg: np.ndarray, albedo: np.ndarray) -> np.ndarray:
    """Tangent-frame M (k, 3, 3) fitted at configurations cfg (k, 4) themselves: aniso.fit_tile (L3, frame "free")
    then aniso_shaded.refine_matrices, magnitude = albedo."""
    ax, ay = cfg[:, 0].astype(np.float32), cfg[:, 1].astype(np.float32)
    nov, phi = np.cos(cfg[:, 2]), cfg[:, 3]
    m_l3, _, _ = aniso.fit_tile(nov.astype(np.float32), ax, ay, phi, albedo, 32, "cpu", "free")
    return aniso.rotate_z(aniso_shaded.refine_matrices(nov, ax, ay, phi, albedo, m_l3), phi)


def band(x, edges, names):
    return names[int(np.searchsorted(edges, x, side="right"))]


BANDS = {
    "roughness max(alpha)": ([0.3, 0.6], ["<0.3", "0.3-0.6", ">0.6"], lambda r: max(r[1], r[2])),
    "anisotropy min/max": ([0.35, 0.7], ["<0.35", "0.35-0.7", ">0.7"], lambda r: min(r[1], r[2]) / max(r[1], r[2])),
    "view theta (deg)": ([40.0, 70.0], ["<40", "40-70", ">70"], lambda r: np.degrees(r[3])),
}


def configuration(rng: np.random.Generator) -> tuple[float, ...]:
    """One benchmark configuration (alpha_x, alpha_y, theta, phi): alphas uniform in [0.05, 1], cos theta uniform
    down to 85 degrees, phi uniform."""
    ax, ay = rng.uniform(0.05, 1.0, 2)
    theta = np.arccos(rng.uniform(np.cos(np.radians(85.0)), 1.0))
    return ax, ay, theta, rng.uniform(0.0, 2.0 * np.pi)


def shade(m: np.ndarray, magnitude: float, lights) -> np.ndarray:
    """magnitude x the LTC's integral over each light."""
    return magnitude * np.array([ltc_integral(m, p) for p in lights])


def stats(sel) -> dict:
    """Median and p90 relative error (where the truth exceeds GT_FLOOR x albedo), p90 |error| / albedo of rows
    (name, alpha_x, alpha_y, theta, truth, estimate, albedo)."""
    tr = np.array([r[4] for r in sel])
    es = np.array([r[5] for r in sel])
    alb = np.array([r[6] for r in sel])
    ok = tr > GT_FLOOR * alb
    rel = np.abs(es[ok] - tr[ok]) / tr[ok]
    ea = np.abs(es - tr) / alb
    return {
        "n": int(len(sel)),
        "median_rel": float(np.median(rel)),
        "p90_rel": float(np.percentile(rel, 90)),
        "p90_abs_over_albedo": float(np.percentile(ea, 90)),
    }


def statistics(rows) -> dict:
    """stats of every name's rows, all and per BANDS."""
    out = {}
    for name in dict.fromkeys(r[0] for r in rows):
        mine = [r for r in rows if r[0] == name]
        res = {"all": stats(mine)}
        for key, (edges, names, f) in BANDS.items():
            for nm in names:
                sel = [r for r in mine if band(f(r), edges, names) == nm]
                if sel:
                    res[f"{key} {nm}"] = stats(sel)
        out[name] = res
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--configs", type=int, default=240)
    ap.add_argument("--gt", type=int, default=256, help="S: S^2 VNDF samples per configuration")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--frame", default="free", choices=sorted(aniso.FRAMES))
    ap.add_argument("--shaded", action="store_true", help="also the shaded refinement (lutbake.ltc.aniso_shaded)")
    ap.add_argument("--shaded-iterations", type=int, default=aniso_shaded.ITERATIONS)
    ap.add_argument("--breakdown", action="store_true", help="where the error comes from (module docstring, 5.)")
    a = ap.parse_args()
    grid = aniso.Grid4("alphax_alphay", (8, 8, 8, 8))
    t0 = time.perf_counter()
    mag, fres = aniso.magnitude_fresnel(grid)
    t_mag = time.perf_counter() - t0
    t0 = time.perf_counter()
    table, err = aniso.fit_table(grid, mag, workers=a.workers, frame=a.frame)
    t_fit = time.perf_counter() - t0
    tables = {"published": None, "lutbake": table}
    if a.shaded:
        t0 = time.perf_counter()
        tables["lutbake_shaded"], err_shaded = aniso_shaded.refine_table(
            grid, mag, table, 32, workers=a.workers, iterations=a.shaded_iterations
        )
        t_shaded = time.perf_counter() - t0
    out = OUT / "ltc_aniso"
    out.mkdir(parents=True, exist_ok=True)
    np.save(out / "alphax_alphay_theta_phi.npy", table.astype(np.float32))
    np.save(out / "ltc_aniso_textures.npy", aniso.texture_layout(table, mag, fres, err))
    published = tables["published"] = np.load(PUBLISHED).astype(np.float64)
    fitted = aniso.fitted_texels(grid)
    e_pub = aniso.relative_error_of(grid, mag, published.reshape(-1, 3, 3)[fitted], fitted)
    e_ours = err.reshape(-1)[fitted]
    e_sh = err_shaded.reshape(-1)[fitted] if a.shaded else None

    rng = np.random.default_rng(7)
    lights = [light_polygon(*spec[:7]) for spec in LIGHTS]
    extra = np.stack([mag], axis=-1)
    rows = []
    configs, truths = [], []
    shifts = np.random.default_rng(8)  # the second ground truth's grid shifts (the configurations' rng untouched)

    def add(name, ax, ay, theta, truth, est, albedo):
        rows.extend((name, ax, ay, theta, tr, es, albedo) for tr, es in zip(truth, est))

    for _ in range(a.configs):
        ax, ay, theta, phi = configuration(rng)
        truth, albedo = truth_and_albedo(ax, ay, theta, phi, lights, a.gt)
        for name, tab in tables.items():
            m, e = aniso.lookup(tab, grid, ax, ay, theta, phi, extra)
            add(name, ax, ay, theta, truth, shade(m[0], e[0, 0], lights), e[0, 0])
            if a.breakdown:
                add(f"{name} exact albedo", ax, ay, theta, truth, shade(m[0], albedo, lights), albedo)
        if a.breakdown:
            configs.append((ax, ay, theta, phi))
            truths.append((truth, albedo))
            second, _ = truth_and_albedo(ax, ay, theta, phi, lights, a.gt, shifts.random(2))
            add("ground truth, second estimate", ax, ay, theta, truth, second, albedo)
            node = nearest_texel(grid, ax, ay, theta, phi)
            node_truth, _ = truth_and_albedo(*node, lights, a.gt)
            for name, tab in tables.items():
                m, e = aniso.lookup(tab, grid, *node, extra)
                add(f"{name} at nodes", *node[:3], node_truth, shade(m[0], e[0, 0], lights), e[0, 0])
    if a.breakdown:
        t0 = time.perf_counter()
        per_configuration = configuration_fit(np.array(configs), np.array([t[1] for t in truths]))
        t_configuration = time.perf_counter() - t0
        for c, (truth, albedo), m in zip(configs, truths, per_configuration):
            add("per configuration", *c[:3], truth, shade(m, albedo, lights), albedo)
    table_rows = statistics(rows)
    report = {
        "table": "8x8x8x8 alpha_x x alpha_y x theta x phi (the paper's texels)",
        "frame": a.frame,
        "fit_seconds": t_fit,
        "magnitude_seconds": t_mag,
        "workers": a.workers,
        "texels_fitted": int(len(fitted)),
        "l3_relative_error": {
            "published": {"median": float(np.median(e_pub)), "p90": float(np.percentile(e_pub, 90))},
            "lutbake": {"median": float(np.median(e_ours)), "p90": float(np.percentile(e_ours, 90))},
            **(
                {"lutbake_shaded": {"median": float(np.median(e_sh)), "p90": float(np.percentile(e_sh, 90))}}
                if a.shaded
                else {}
            ),
        },
        **({"shaded_seconds": t_shaded, "shaded_iterations": a.shaded_iterations} if a.shaded else {}),
        **({"configuration_fit_seconds": t_configuration} if a.breakdown else {}),
        "polygon_lights": table_rows,
        "configs": a.configs,
        "ground_truth_samples": a.gt**2,
        "files": {
            "alphax_alphay_theta_phi.npy": "the paper's layout (8, 8, 8, 8, 3, 3), M with |M e_z| = 1",
            "ltc_aniso_textures.npy": "(3, 64, 8, 8, 4): three RGBA 3D textures 8 (phi) x 8 (theta) x 64 (alpha_y + 8 "
            "alpha_x), docs/shaders/ltc_aniso.glsl",
        },
        "paper_fit": "fitting/fit_alphax_alphay_theta_phi.py: torch + CUDA ('cuda:0' hard-coded), tqdm; 10000 SGD "
        "epochs over the 8^4 texels by default; not run by this benchmark (on one CPU core with its device strings "
        "changed: ~110 s per epoch, docs/ltc_aniso.md)",
    }
    (OUT / "ltc_aniso.json").write_text(json.dumps(report, indent=1))
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
