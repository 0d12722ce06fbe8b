"""``make bench`` (interpolation part): every table of ``make luts`` that interpolates between texels
(lutbake.sampling.interpolation), against the same table with every texel integrated.

Per table: the share of texels interpolated / coarse / integrated, the CPU seconds of its tiles with interpolation and
without (same run, same tolerance: the ratio), and the honesty of its estimates: every texel's |v - reference| against
its own recorded estimate plus the reference's, the reference being every texel integrated to a tenth of the table's
tolerance (``interpolation = "off"``). Writes outputs/bench/interpolation.json and prints a summary.
``--tables NAME ...``: only those tables; ``--texels FILE.npz``: every texel's worst error / bound per table.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "outputs" / "bench"


def specs():
    """The make-luts tables (configs/ and the Makefile's presets) whose plan interpolates."""
    import re

    from lutbake.config import load_config, preset_path
    from lutbake.kinds import lookup_kind

    presets = re.search(r"^PRESETS \?= (.*?)(?<!\\)\n", (ROOT / "Makefile").read_text(), re.S | re.M).group(1)
    paths = sorted((ROOT / "configs").glob("*.toml")) + [preset_path(p) for p in presets.replace("\\", " ").split()]
    for path in paths:
        for spec in load_config(path, []):
            plan = lookup_kind(spec.kind).plan(spec)
            if "interpolation" in plan.extra:
                yield spec


def stored_error(spec):
    """A dfg layout's map from integral error bounds to stored-channel bounds (the identity otherwise: the dielectric
    kinds' tiles carry stored bounds already, lutbake.sampling.dielectric_layout)."""
    from lutbake.layouts import lookup_layout

    layout = spec.options.get("layout")
    return lookup_layout("dfg", layout).stored_error if spec.kind == "dfg" and layout else (lambda err: err)


def tiles(spec, **overrides):
    """(data (n, tile width), CPU seconds of the tiles, wall seconds, the plan's channel count) of spec with
    ``overrides``."""
    from lutbake.config import validate_table
    from lutbake.kinds import lookup_kind
    from lutbake.runtime.executor import execute_tiles

    s = validate_table({**{k: v for k, v in spec.options.items() if v is not None}, **overrides}, "<bench>", 0)
    cpu: list[float] = []
    t0 = time.perf_counter()
    plan = lookup_kind(s.kind).plan(s)
    data = execute_tiles(plan, cpu=cpu)
    return data, sum(cpu), time.perf_counter() - t0, plan.n_channels


def main() -> None:
    import warp as wp

    from lutbake.sampling.interpolation import COARSE, INTERPOLATED
    from lutbake.tolerance import tolerance_of

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=OUT / "interpolation.json")
    ap.add_argument("--tables", nargs="+", metavar="NAME", help="only these tables (default: every one)")
    ap.add_argument("--texels", type=Path, help="also write every texel's error / bound of each table here (.npz)")
    args = ap.parse_args()
    wp.config.quiet = True
    rows, per_texel = [], {}
    for spec in specs():
        if args.tables and spec.name not in args.tables:
            continue
        tol = tolerance_of(spec.options)
        data, cpu, wall, width = tiles(spec)
        off, cpu_off, wall_off, _ = tiles(spec, interpolation="off")
        ref = tiles(spec, interpolation="off", tolerance=tol.absolute / 10, relative_tolerance=tol.relative / 10)[0]
        # the aux columns: estimates of the first nch channels, then the flag (a channel an engine layout appends,
        # Unity HDRP's diffuse term, has none: lutbake.integrands.engine_diffuse)
        nch = data.shape[1] - width - 1
        v, e, flag = data[:, :nch], data[:, width : width + nch], data[:, -1]
        err = np.abs(v - ref[:, :nch])
        # the estimates are the integrals' (the tiles' aux columns); a layout that stores other combinations maps
        # them to its stored channels' bounds (Layout.stored_error; Babylon's F82: bias, scale + bias, 16 F82)
        to_stored = stored_error(spec)
        bound = to_stored(e) + to_stored(ref[:, width : width + nch])
        interp = flag == INTERPOLATED
        ratio = np.where(bound > 0, err / np.maximum(bound, 1e-300), 0.0)
        row = {
            "table": spec.name,
            "kind": spec.kind,
            "texels": len(v),
            "tolerance": tol.text(),
            "interpolated": float(interp.mean()),
            "coarse": float(np.mean(flag == COARSE)),
            "cpu_s": cpu,
            "cpu_s_without": cpu_off,
            "wall_s": wall,
            "wall_s_without": wall_off,
            "max_error": float(err.max()),
            "max_error_interpolated": float(err[interp].max()) if interp.any() else 0.0,
            "worst_error_over_bound": float(ratio.max()),
            "worst_error_over_bound_interpolated": float(ratio[interp].max()) if interp.any() else 0.0,
            "texels_over_bound": int(np.count_nonzero(np.any(err > bound, axis=1))),
        }
        rows.append(row)
        per_texel[spec.name] = ratio.max(axis=1)
        print(
            f"{spec.name:<40} {row['texels']:>8} texels, {100 * row['interpolated']:5.1f} % interpolated: "
            f"{cpu:6.2f} s CPU vs {cpu_off:6.2f} s without ({cpu_off / max(cpu, 1e-9):4.1f}x); max error "
            f"{row['max_error']:.2e}, worst error / (estimate + reference's) {row['worst_error_over_bound']:.2f} "
            f"(interpolated texels {row['worst_error_over_bound_interpolated']:.2f}), texels over: "
            f"{row['texels_over_bound']}"
        )
    total, total_off = sum(r["cpu_s"] for r in rows), sum(r["cpu_s_without"] for r in rows)
    print(f"all {len(rows)} tables: {total:.1f} s CPU vs {total_off:.1f} s without ({total_off / total:.2f}x)")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({"tables": rows, "cpu_s": total, "cpu_s_without": total_off}, indent=2) + "\n")
    if args.texels:
        np.savez_compressed(args.texels, **per_texel)
    print(f"wrote {args.out.relative_to(ROOT) if args.out.is_relative_to(ROOT) else args.out}")


if __name__ == "__main__":
    main()
