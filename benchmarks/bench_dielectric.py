"""Accuracy and wall time of the rough dielectric tables (issue 15 targets): a 32^3 NoV x roughness x IOR E_R/E_T table
in <= 10 s, and Blender EEVEE's 16 x 64^2 pair (btdf_ggx, bsdf_ggx) in <= 30 s, on this machine (all cores).

Reference: the same texel grid at Gauss-Legendre order 24 (3 * 24^2 nominal samples) on REF_TEXELS random texels plus
every texel at the most grazing NoV of the table (cached under outputs/bench/, keyed by the kernel sources). Order 24
agrees with order 32 to < 1e-8 there and with the independent numpy integral over the outgoing sphere to ~1e-7
(tests/test_dielectric.py). Reported: max and mean |table - reference| per budget, and the default (samples unset:
adaptive to the storage tolerance, lutbake.sampling.dielectric.DielectricAdaptive) against the fixed order 12 as a
ratio of bake seconds.
Run: PYTHONPATH=. python benchmarks/bench_dielectric.py  (writes outputs/bench/dielectric.json)
"""

from __future__ import annotations

import hashlib
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import warp as wp  # noqa: E402

wp.config.quiet = True

from lutbake.api import bake_table  # noqa: E402
from lutbake.config import validate_table  # noqa: E402
from lutbake.integrands.dielectric import integrate  # noqa: E402
from lutbake.kinds import dielectric as kd  # noqa: E402
from lutbake.layouts import lookup_layout  # noqa: E402
from lutbake.runtime.executor import default_workers  # noqa: E402
from lutbake.sources import sources_digest  # noqa: E402

OUT = ROOT / "outputs" / "bench"
REF_ORDER = 24
REF_TEXELS = 2048
CASES = {
    "energy_32^3": {
        "kind": "dielectric",
        "size": [32, 32],
        "ior_size": 32,
        "ior_mapping": "symmetric",
        "ior_range": [0.4, 2.5],
    },
    "eevee_btdf_16x64^2": {"kind": "dielectric", "layout": "eevee_btdf"},
    "eevee_bsdf_16x64^2": {"kind": "dielectric", "layout": "eevee_bsdf"},
}
BUDGETS = (3 * 8**2, 3 * 10**2, 3 * 12**2, 3 * 16**2)  # GL order 8, 10, 12 (default), 16
TARGETS = {"energy_32^3": 10.0, "eevee_btdf_16x64^2": 30.0, "eevee_bsdf_16x64^2": 30.0}


def spec(kw, samples=None):
    return validate_table({"name": "bench", **kw, **({"samples": samples} if samples else {})}, "<bench>", 0)


def reference(name: str, kw: dict):
    o = spec(kw).options
    _, nov, alpha, eta, _ = kd.texel_grid(o)
    rng = np.random.default_rng(15)
    idx = np.unique(np.concatenate([rng.choice(len(nov), REF_TEXELS, replace=False), np.flatnonzero(nov <= nov.min())]))
    key = hashlib.sha256(json.dumps(kw, sort_keys=True).encode() + sources_digest()).hexdigest()[:16]
    path = OUT / f"ref_dielectric_{key}.npz"
    if path.exists():
        return np.load(path)["idx"], np.load(path)["ref"]
    layout = lookup_layout("dielectric", o["layout"])
    k = (*kd.terms_of(o), layout.integrand, "gauss_legendre")  # the layout's Fresnel mode
    f = [np.asarray(a[idx], np.float32) for a in (nov, alpha, eta)]
    ref = layout.stored(integrate(k, *f, 3 * REF_ORDER**2, 0))
    OUT.mkdir(parents=True, exist_ok=True)
    np.savez(path, idx=idx, ref=ref)
    return idx, ref


def main() -> None:
    workers = default_workers()
    report = {
        "workers": workers,
        "reference": f"GL order {REF_ORDER} at {REF_TEXELS} random + most grazing texels",
        "cases": {},
    }
    for name, kw in CASES.items():
        idx, ref = reference(name, kw)
        rows = []
        for budget in BUDGETS + (None,):  # None: the default, adaptive to the tolerance
            t0 = time.perf_counter()
            table, seconds, _ = bake_table(spec(kw, budget), workers=workers)
            wall = time.perf_counter() - t0
            flat = table.data.reshape(-1, table.data.shape[-1]).astype(np.float64)[idx]
            err = np.abs(flat - ref)
            order = int(round(np.sqrt(budget / 3))) if budget else None
            rows.append(
                {
                    "samples": budget,
                    "gl_order": order,
                    "bake_s": round(seconds, 2),
                    "wall_s": round(wall, 2),
                    "max_abs": float(err.max()),
                    "mean_abs": float(err.mean()),
                    **({"error_estimate": table.attributes["error_estimate"]} if budget is None else {}),
                }
            )
            label = f"order {order:2d}" if budget else "adaptive"
            print(
                f"{name:22s} {label}: {seconds:6.2f} s  max {err.max():.2e}  "
                f"mean {err.mean():.2e}  (target {TARGETS[name]:.0f} s)",
                flush=True,
            )
        fixed12 = next(r for r in rows if r["gl_order"] == 12)
        ratio = rows[-1]["bake_s"] / max(fixed12["bake_s"], 1e-9)
        print(
            f"{name:22s} adaptive / order 12: {ratio:.2f}x the seconds, max error {rows[-1]['max_abs']:.2e} vs "
            f"{fixed12['max_abs']:.2e} (estimate {rows[-1]['error_estimate']})",
            flush=True,
        )
        report["cases"][name] = {"target_s": TARGETS[name], "runs": rows, "adaptive_over_order_12": round(ratio, 3)}
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "dielectric.json").write_text(json.dumps(report, indent=1) + "\n")


if __name__ == "__main__":
    main()
