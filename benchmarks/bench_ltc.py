"""``make bench`` (LTC part): fit time and quality of the ``ltc`` kind on this machine -> outputs/bench/ltc.json.

1. GGX 64^2 bake (both cores), then one bake per other lobe (64^2): wall time, fit-error statistics.
2. Baseline: a single-threaded straight numpy port of ltc_code's fitTab loop (tests/ltc_port.py: scalar
   Nelder-Mead, each texel chained off the previous one, the metric vectorised over its 32^2 samples) on a
   subset of texels, extrapolated to 64^2 (time per texel x 4096); the ratio to lutbake's wall time.
3. Objective backends: Heitz's metric per (texel, candidate) in the Warp kernel vs the numpy port, in us/eval.
4. GGX against the published ltc_code table on Heitz's metric (per texel): fraction no worse, medians.
5. Area lights (lutbake.validate.ltc_area): relative error of magnitude x polygon integral against the brute
   force, per lobe and roughness, for lutbake's tables and the published GGX table.
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

import ltc_port  # noqa: E402
import warp as wp  # noqa: E402

from lutbake.api import bake_table  # noqa: E402
from lutbake.config import load_configs  # noqa: E402
from lutbake.executor import default_workers  # noqa: E402
from lutbake.kinds.ltc import axes_for, texel_params  # noqa: E402
from lutbake.ltc import fit  # noqa: E402
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


def bake(lobe: str, workers: int):
    spec = load_configs(
        [ROOT / "lutbake" / "presets" / "ltc-ggx.toml"],
        [f'lobe="{lobe}"', f'name="ltc_{lobe}"', 'format="exr"', 'dtype="float32"'],
    )[0]
    cpu0 = time.process_time()
    table, seconds, _ = bake_table(spec, workers=workers)
    return table, seconds, time.process_time() - cpu0


def area(lobe: str, t1, t2, axes) -> dict:
    rows = ltc_area.compare(lobe, t1, t2, axes[1].values(), axes[2].alpha(), AREA_TEXELS, s=512)
    by_rough = ltc_area.summarise(rows, "a")
    return {f"r={a / (N - 1):.3f}": v for a, v in by_rough.items()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--lobes", default="ggx,beckmann,charlie,lambert")
    ap.add_argument("--port-texels", type=int, default=12, help="texels of the straight-port baseline")
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

    axes = axes_for({"lobe": "ggx", "size": [N, N]})
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

    # area lights
    report["area_lights"] = {
        "lights": [name for name, _ in ltc_area.light_set()],
        "texels": AREA_TEXELS,
        "published_ggx": area("ggx", t1p, t2p, axes),
    }
    for lobe, table in tables.items():
        ax = axes_for({"lobe": lobe, "size": [N, N]})
        report["area_lights"][lobe] = area(lobe, table.data[0].astype(np.float64), table.data[1].astype(np.float64), ax)
        print(f"area lights {lobe}:", json.dumps(report["area_lights"][lobe]), flush=True)
    print("area lights published ggx:", json.dumps(report["area_lights"]["published_ggx"]), flush=True)
    report["machine"]["load_average_at_end"] = list(os.getloadavg())
    (OUT / "ltc.json").write_text(json.dumps(report, indent=1))
    print(f"wrote {OUT / 'ltc.json'}")


if __name__ == "__main__":
    main()
