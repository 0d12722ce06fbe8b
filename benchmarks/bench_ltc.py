"""``make bench`` (LTC part): fit time and quality of the ``ltc`` kind on this machine -> outputs/bench/ltc.json.

1. GGX 64^2 bake (both cores), then one bake per other lobe (64^2): wall time, fit-error statistics.
2. Baseline: a single-threaded straight numpy port of ltc_code's fitTab loop (tests/ltc_port.py: scalar
   Nelder-Mead, each texel chained off the previous one, the metric vectorised over its 32^2 samples) on a
   subset of texels, extrapolated to 64^2 (time per texel x 4096); the ratio to lutbake's wall time.
3. Objective backends: Heitz's metric per (texel, candidate) in the Warp kernel vs the numpy port, in us/eval.
4. GGX against the published ltc_code table on Heitz's metric (per texel): fraction no worse, medians.
5. Area lights (lutbake.validate.ltc_area): relative error of magnitude x polygon integral against the brute
   force, per lobe and roughness, for lutbake's tables and the published GGX table.
6. Tabulated lobes (gotanda): the interpolated lobe the fit sees against Eq. 4 by direct quadrature (GL order 12),
   relative L3 per texel, next to the fit error of the same texels.
8. The area-light benchmark through the shader's bilinear lookup (lutbake.validate.ltc_bench): published vs
   lutbake's L3 fit (the default) vs lutbake's shaded fit (fit = "shaded"), relative error and |error| / albedo
   (median, p90, max), overall, per roughness band, per view band and per (roughness, view) band, for F = 1 and
   f0 = 0.04; the ground truth's own error (visible-normal sampling at S^2 against NDF sampling at (2S)^2, views
   below 80 degrees); and the GGX 64^2 fit time of both fits, beside ltc_code's C++ fitLTC (benchmarks/fitltc.py).
7. Sharing: the ltc-hdrp preset (alpha_min 1e-3) baked after GGX in the same process (lutbake.ltc.fit.MEMO: texels
   with equal inputs and seeds take GGX's fits), CPU seconds and the ratio to GGX's; and baked alone (memo
   cleared), to check the bits are the same.
Sections 2-4 and 7 need ``ggx`` among ``--lobes``.
"""

from __future__ import annotations

import argparse
import gzip
import json
import os
import re
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import fitltc  # noqa: E402
import ltc_port  # noqa: E402
import warp as wp  # noqa: E402

from lutbake.api import bake_table  # noqa: E402
from lutbake.config import load_configs  # noqa: E402
from lutbake.integrands.diffuse import eval_brdf  # noqa: E402
from lutbake.kinds.ltc import axes_for  # noqa: E402
from lutbake.ltc import fit  # noqa: E402
from lutbake.ltc.magnitude import lobe_parameter, magnitude_alpha, magnitude_fresnel, texel_params  # noqa: E402
from lutbake.runtime.executor import default_workers  # noqa: E402
from lutbake.validate import ltc_area  # noqa: E402

OUT = ROOT / "outputs" / "bench"
N = 64
AREA_TEXELS = [(t, a) for t in (0, 16, 32, 48, 60) for a in (6, 16, 32, 48, 63)]


def published():
    text = gzip.decompress((ROOT / "tests" / "data" / "ltc_code_ltc.js.gz").read_bytes()).decode()
    a, b = text.split("var g_ltc_2")
    num = re.compile(r"-?[0-9.]+(?:e[-+]?[0-9]+)?")
    return (
        np.array([float(x) for x in num.findall(a.split("[", 1)[1])]).reshape(N, N, 4),
        np.array([float(x) for x in num.findall(b.split("[", 1)[1])]).reshape(N, N, 4),
    )


def bake(lobe: str, workers: int, preset: str = "ltc-ggx", fit_kind: str = "l3"):
    spec = load_configs(
        [ROOT / "lutbake" / "presets" / f"{preset}.toml"],
        [f'lobe="{lobe}"', f'name="ltc_{lobe}"', 'format="exr"', 'dtype="float32"', f'fit="{fit_kind}"'],
    )[0]
    cpu0 = time.process_time()
    table, seconds, _ = bake_table(spec, workers=workers)
    return table, seconds, time.process_time() - cpu0


AREA_SAMPLES = {"gotanda": 256}  # brute-force grid S (S x S); Eq. 4 per sample is costly; default 512


def area(lobe: str, t1, t2, axes) -> dict:
    s = AREA_SAMPLES.get(lobe, 512)
    rows = ltc_area.compare(lobe, t1, t2, axes[1].values(), lobe_parameter(axes[2]), AREA_TEXELS, s=s)
    by_rough = ltc_area.summarise(rows, "a")
    overall = ltc_area.summarise([{**r, "all": "all"} for r in rows], "all")
    return {f"r={a / (N - 1):.3f}": v for a, v in by_rough.items()} | overall


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--lobes", default="ggx,beckmann,charlie,lambert")
    ap.add_argument("--port-texels", type=int, default=12, help="texels of the straight-port baseline")
    ap.add_argument("--bench-cases", type=int, default=8, help="area-light benchmark: shading points per band")
    ap.add_argument("--bench-lights", type=int, default=16, help="area-light benchmark: lights per shading point")
    ap.add_argument("--bench-samples", type=int, default=512, help="area-light benchmark: truth's S (S x S samples)")
    ap.add_argument(
        "--shaded",
        default=None,
        help="lobes also fitted with fit = shaded and compared at the area-light texels (default: those of --lobes but "
        "ggx, benchmarked through the shader in section 8, and lambert, an exact LTC)",
    )
    args = ap.parse_args(argv)
    wp.config.quiet = True
    OUT.mkdir(parents=True, exist_ok=True)
    workers = default_workers()
    report = {"machine": {"workers": workers, "load_average_at_start": list(os.getloadavg())}, "lobes": {}}
    tables = {}
    for lobe in args.lobes.split(","):
        table, seconds, cpu = bake(lobe, workers)
        tables[lobe] = table
        report["lobes"][lobe] = {
            "seconds": round(seconds, 2),
            "cpu_seconds": round(cpu, 2),
            "size": "64x64",
            **{k: float(v) for k, v in table.attributes.items() if k.startswith("fit_error_")},
        }
        print(
            f"{lobe}: {seconds:.1f} s wall, {cpu:.1f} s CPU, fit error median {table.attributes['fit_error_median']}, "
            f"max {table.attributes['fit_error_max']}",
            flush=True,
        )

    if "ggx" in tables:
        report["hdrp_after_ggx"] = sharing_section(report["lobes"]["ggx"]["cpu_seconds"], workers)
        print("ltc-hdrp after ggx:", report["hdrp_after_ggx"], flush=True)
    for lobe, table in tables.items():
        if fit.lobe(lobe).tabulate is not None:
            report.setdefault("interpolation", {})[lobe] = interpolation_error(lobe, table)
            print(f"interpolation {lobe}:", json.dumps(report["interpolation"][lobe]), flush=True)
    axes = axes_for({"lobe": "ggx", "size": [N, N]})
    if "ggx" not in tables:
        area_section(report, tables, axes, None, None, with_published=False, shaded=shaded_lobes(args, tables))
        return finish(report)
    nov, alpha = texel_params(axes)
    ggx = tables["ggx"]
    mag = ggx.data[1, ..., 0].reshape(-1).astype(np.float64)
    prob = fit.Problem("ggx", nov, alpha, mag)
    texels = np.arange(N * N)
    t1p, t2p = published()
    e_ours = fit.heitz_error_of_packed(prob, texels, ggx.data[0].reshape(-1, 4).astype(np.float64))
    e_pub = fit.heitz_error_of_packed(prob, texels, t1p.reshape(-1, 4))
    r_ours, r_pub = prob.relative(texels, e_ours), prob.relative(texels, e_pub)
    report["ggx_vs_published"] = {
        "metric": "Heitz L3 (ltc_code computeError, 32^2 per technique), magnitudes = lutbake's for both",
        "fraction_no_worse": float(np.mean(e_ours <= e_pub)),
        "relative_error_median": {"lutbake": float(np.median(r_ours)), "ltc_code": float(np.median(r_pub))},
        "relative_error_max": {"lutbake": float(r_ours.max()), "ltc_code": float(r_pub.max())},
        "note": "lutbake's table is stored as float32; the fit itself is float64",
    }
    print("GGX vs published:", json.dumps(report["ggx_vs_published"]), flush=True)

    # objective backends: Warp kernel vs numpy port, per (texel, candidate) evaluation
    q = np.zeros((N * N, 3))
    q[:, :2] = np.log(2.0 * alpha[:, None].astype(np.float64) + 1e-3)
    m = prob.matrices(texels, q)
    t0 = time.perf_counter()
    prob.error(texels, m)
    warp_us = (time.perf_counter() - t0) / (N * N) * 1e6
    sub = texels[::97]
    t0 = time.perf_counter()
    for k in sub:
        ltc_port.compute_error(m[k], mag[k], prob.v[k].astype(np.float64), float(alpha[k]))
    numpy_us = (time.perf_counter() - t0) / len(sub) * 1e6
    report["objective_us_per_eval"] = {
        "warp_kernel_1_thread": round(warp_us, 1),
        "numpy_port": round(numpy_us, 1),
        "ratio": round(numpy_us / warp_us, 1),
    }
    print("objective us/eval:", report["objective_us_per_eval"], flush=True)

    # the straight port of fitTab on a subset, extrapolated
    rng = np.random.default_rng(0)
    pick = [
        (int(t), int(a)) for t, a in zip(rng.integers(1, N, args.port_texels), rng.integers(0, N, args.port_texels))
    ]
    t0 = time.perf_counter()
    ltc_port.fit_tab(N, pick)
    per_texel = (time.perf_counter() - t0) / len(pick)
    est = per_texel * N * N
    report["baseline_straight_port"] = {
        "texels_run": len(pick),
        "seconds_per_texel": round(per_texel, 3),
        "extrapolated_64x64_s": round(est, 1),
        "ratio_to_lutbake_ggx": round(est / report["lobes"]["ggx"]["seconds"], 1),
        "note": "single thread; run on a random subset of texels (chained within the subset) and extrapolated",
    }
    print("straight port:", report["baseline_straight_port"], flush=True)

    area_section(report, tables, axes, t1p, t2p, with_published=True, shaded=shaded_lobes(args, tables))
    report["area_benchmark"] = benchmark_section(ggx, report["lobes"]["ggx"], workers, t1p, t2p, args)
    finish(report)


def benchmark_section(ggx, ggx_row: dict, workers: int, t1p, t2p, args) -> dict:
    """Section 8: the area-light benchmark (published, L3, shaded) and the two fits' times."""
    from lutbake.validate import ltc_bench

    fit.MEMO.clear()  # the shaded fit starts from the L3 fit: timed in full, not from the memo
    new, seconds, cpu = bake("ggx", workers, fit_kind="shaded")
    times = {
        "l3_fit_64x64": {"seconds": ggx_row["seconds"], "cpu_seconds": ggx_row["cpu_seconds"]},
        "shaded_fit_64x64": {"seconds": round(seconds, 2), "cpu_seconds": round(cpu, 2)},
        "ltc_code_fitLTC": fitltc.time_fitltc(),
    }
    c = times["ltc_code_fitLTC"]
    c_seconds = c.get("seconds", c.get("last_measured", {}).get("seconds"))
    if c_seconds:  # fitLTC runs one thread; lutbake's l3 fit runs `workers`
        times["fitLTC_seconds_over_lutbake_l3"] = round(c_seconds / ggx_row["seconds"], 1)
        times["fitLTC_seconds_over_lutbake_l3_cpu"] = round(c_seconds / ggx_row["cpu_seconds"], 1)
    print("fit times:", json.dumps(times), flush=True)
    t0 = time.perf_counter()
    cases = ltc_bench.cases(args.bench_cases, args.bench_lights)
    truths = [ltc_bench.ground_truth(c, args.bench_samples) for c in cases]
    truth_seconds = time.perf_counter() - t0
    # the truth's own error: an independent estimator at another count, on views below 80 degrees (NDF sampling
    # degrades at grazing views) and lights above the relative floor
    check = [i for i, c in enumerate(cases) if c["theta"] < 80.0][:: max(1, len(cases) // 24)]
    dev = []
    for i in check:
        other = ltc_bench.ground_truth(cases[i], 2 * args.bench_samples, "ndf")
        g = truths[i]["lobe"]
        ok = g > ltc_bench.REL_FLOOR * truths[i]["albedo"]
        dev.append(np.abs(g - other["lobe"])[ok] / g[ok])
    dev = np.concatenate(dev)
    tables = {
        "published": (t1p, t2p),
        "l3": (ggx.data[0].astype(np.float64), ggx.data[1].astype(np.float64)),
        "shaded": (new.data[0].astype(np.float64), new.data[1].astype(np.float64)),
        # the smallest shader change: a second LTC for the Schlick part (only the texels the lookups read are fitted)
        "two_lobe": ltc_bench.fitted_texels(ltc_bench.lookup_texels(cases, N), "two_lobe", N),
    }
    out = {
        "cases": len(cases),
        "lights": sum(len(c["lights"]) for c in cases),
        "truth": {
            "estimator": f"GGX visible-normal sampling, {args.bench_samples}^2 stratified per shading point",
            "seconds": round(truth_seconds, 1),
            "vs_ndf_sampling_at_2S": {
                "lights": int(len(dev)),
                "relative_difference_median": float(np.median(dev)),
                "relative_difference_p90": float(np.quantile(dev, 0.9)),
                "relative_difference_max": float(dev.max()),
            },
        },
        "fit_times": times,
    }
    for f0 in (1.0, 0.04):
        res = {n: ltc_bench.report(ltc_bench.errors(t[0], t[1], cases, truths, f0, *t[2:])) for n, t in tables.items()}
        pub = res["published"]
        out[f"f0={f0:g}"] = {"tables": res} | {
            f"{name}_over_published": over_published(res[name], pub) for name in ("shaded", "two_lobe")
        }
        for name in ("shaded", "two_lobe"):
            ratios = out[f"f0={f0:g}"][f"{name}_over_published"]
            print(f"area benchmark f0={f0:g} {name}:", json.dumps(ratios), flush=True)
        for k in ("all", *[k for k in pub if " / " not in k and k != "all"]):
            row = " | ".join(
                f"{n} {res[n][k]['rel_median']:.4f} {res[n][k]['rel_p90']:.3f} {res[n][k]['abs_p90']:.4f}" for n in res
            )
            print(f"  {k:14s} {row}", flush=True)
    return out


def over_published(new: dict, pub: dict) -> dict:
    """The goals' ratios (median relative error, |error| / albedo p90) and the bands worse than the published table."""
    worse = [
        k
        for k in pub
        if " / " in k and (new[k]["rel_median"] > pub[k]["rel_median"] or new[k]["abs_p90"] > pub[k]["abs_p90"])
    ]
    return {
        "rel_median": new["all"]["rel_median"] / pub["all"]["rel_median"],
        "abs_p90": new["all"]["abs_p90"] / pub["all"]["abs_p90"],
        "bands_worse_in_rel_median_or_abs_p90": worse,
    }


def sharing_section(ggx_cpu: float, workers: int) -> dict:
    hits, misses = fit.MEMO.hits, fit.MEMO.misses
    shared, seconds, cpu = bake("ggx", workers, "ltc-hdrp")
    row = {
        "seconds": round(seconds, 2),
        "cpu_seconds": round(cpu, 2),
        "cpu_ratio_to_ggx": round(cpu / ggx_cpu, 3),
        "memo_hits": fit.MEMO.hits - hits,
        "memo_misses": fit.MEMO.misses - misses,
    }
    fit.MEMO.clear()
    alone, seconds, cpu = bake("ggx", workers, "ltc-hdrp")
    row |= {"alone_seconds": round(seconds, 2), "alone_cpu_seconds": round(cpu, 2)}
    row["identical_to_alone"] = bool(np.array_equal(shared.data, alone.data))
    return row


def shaded_lobes(args, tables: dict) -> list[str]:
    return args.shaded.split(",") if args.shaded else [lb for lb in tables if lb not in ("ggx", "lambert")]


def area_section(report, tables, axes, t1p, t2p, with_published: bool, shaded: list[str]) -> None:
    report["area_lights"] = {"lights": [name for name, _ in ltc_area.light_set()], "texels": AREA_TEXELS}
    if with_published:
        report["area_lights"]["published_ggx"] = area("ggx", t1p, t2p, axes)
        print("area lights published ggx:", json.dumps(report["area_lights"]["published_ggx"]), flush=True)
    for lobe, table in tables.items():
        ax = axes_for({"lobe": lobe, "size": [N, N]})
        report["area_lights"][lobe] = area(lobe, table.data[0].astype(np.float64), table.data[1].astype(np.float64), ax)
        print(f"area lights {lobe}:", json.dumps(report["area_lights"][lobe]), flush=True)
    for lobe in shaded:  # the shaded fit of the other lobes, at the same texels (texel centres, no bilinear lookup)
        table, seconds, cpu = bake(lobe, default_workers(), fit_kind="shaded")
        ax = axes_for({"lobe": lobe, "size": [N, N]})
        row = area(lobe, table.data[0].astype(np.float64), table.data[1].astype(np.float64), ax)
        report.setdefault("area_lights_shaded", {})[lobe] = row | {"seconds": seconds, "cpu_seconds": cpu}
        print(f"area lights {lobe} (fit = shaded):", json.dumps(row["all"]), "L3:", report["area_lights"][lobe]["all"])


def finish(report) -> None:
    report["machine"]["load_average_at_end"] = list(os.getloadavg())
    name = "ltc.json" if "ggx" in report["lobes"] else "ltc_" + "_".join(report["lobes"]) + ".json"
    (OUT / name).write_text(json.dumps(report, indent=1))
    print(f"wrote {OUT / name}")


INTERP_DIRS = 4096  # cosine-distributed light directions per texel (stratified 64 x 64)


def interpolation_error(lobe: str, table) -> dict:
    """Relative L3 distance (∫ |f_interp - f|^3 / ∫ f^3)^(1/3) between the tabulated lobe the fit sees and Eq. 4 by
    direct GL quadrature at order 12 (cosine-sampled estimate), at AREA_TEXELS, beside those texels' fit error."""
    axes = axes_for({"lobe": lobe, "size": [N, N]})
    nov_all, alpha_all = texel_params(axes)
    idx = np.array([t * N + a for t, a in AREA_TEXELS])
    mag, _ = magnitude_fresnel(lobe, nov_all[idx], magnitude_alpha(axes)[idx], None)
    prob = fit.Problem(lobe, nov_all[idx], alpha_all[idx], mag)
    k = int(np.sqrt(INTERP_DIRS))
    u1, u2 = (x.ravel() for x in np.meshgrid((np.arange(k) + 0.5) / k, (np.arange(k) + 0.5) / k))
    l = np.stack([np.sqrt(1 - u1) * np.cos(2 * np.pi * u2), np.sqrt(1 - u1) * np.sin(2 * np.pi * u2), np.sqrt(u1)], 1)
    rel = []
    for j in range(len(idx)):
        got = prob.f_cos(np.full(len(l), j), l)
        v = np.broadcast_to(prob.v[j], l.shape)
        ref = eval_brdf(ltc_area.DIFFUSE_MODELS[lobe], l, v, float(alpha_all[idx[j]]), order=12) * l[:, 2]
        pdf = l[:, 2] / np.pi
        rel.append(float(np.cbrt(np.sum(np.abs(got - ref) ** 3 / pdf) / np.sum(ref**3 / pdf))))
    fit_err = table.data[1, ..., 2].reshape(-1)[idx]
    return {
        "texels": AREA_TEXELS,
        "interp_rel_l3": rel,
        "interp_rel_l3_max": max(rel),
        "interp_rel_l3_median": float(np.median(rel)),
        "fit_error_same_texels": [float(x) for x in fit_err],
        "ratio_fit_to_interp_min": float(np.min(fit_err / np.maximum(rel, 1e-30))),
    }


if __name__ == "__main__":
    main()
