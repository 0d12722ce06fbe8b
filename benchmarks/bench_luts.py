"""``make bench`` (make-luts part): the bake of ``make luts`` from a clean outputs folder, as a new user runs it.

1. ``make luts OUT=<empty temporary folder>``: wall seconds and CPU seconds (user + sys of every child process),
   the load average before and after (other load on this 2-core machine inflates wall, not CPU), against the
   target TARGET_WALL (issue 13: the bake part <= 30 s).
2. Per table, from the run's report.json: wall seconds of its tiles, CPU seconds of its computation (plan,
   kernel preparation, tiles, error estimate: lutbake.pipeline.Computed.cpu_seconds, thread CPU time) and the
   table whose computation it shared (lutbake.sharing); the top ten by CPU, and the CPU outside the tables'
   computations (start-up, configs, hashing, writing, sidecars: the process total minus the tables' sum).
3. The same ``make luts`` again, every table up to date: the cost of a no-op run (start-up, planning, hashing
   and the integrity check of every output).
4. ``make luts`` of the batch it baked when issue 13 was filed (``configs/`` and FILING_PRESETS: 25 tables, ~190 s
   then), into another empty folder: the same target on the batch it was set for, while later issues' presets grew
   ``make luts`` to 40 tables.
5. Both batches again on a new machine: an empty Warp kernel cache (WARP_CACHE_PATH, a temporary folder per batch),
   so every kernel module compiles first, as on a user's first ``make luts`` (the runs above load the modules from the
   kernel cache of this machine). ``--no-cold`` skips them.

Writes outputs/bench/luts.json and prints a summary.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "outputs" / "bench"
TARGET_WALL = 30.0  # seconds, issue 13: make luts from a clean checkout, the bake part
TOP = 10
# make luts's presets when issue 13 was filed (Makefile PRESETS of 2026-11-22); the LTC, glass and later engine presets
# came with issues 14-16
FILING_PRESETS = "filament filament-corrected gltf gltf-charlie gltf-sheen-e blender-eevee unreal"


def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def make_luts(out: Path, *variables: str, warp_cache: Path | None = None) -> dict:
    """One ``make luts OUT=out`` (and make ``variables``): wall, CPU (user + sys of the children), load average
    before and after. ``warp_cache``: Warp's kernel cache folder for the run (WARP_CACHE_PATH), else the default."""
    env = {**os.environ, **({"WARP_CACHE_PATH": str(warp_cache)} if warp_cache is not None else {})}
    load0, cpu0, t0 = os.getloadavg(), children_cpu(), time.perf_counter()
    r = subprocess.run(
        ["make", "-s", "luts", f"OUT={out}", *variables], cwd=ROOT, capture_output=True, text=True, env=env
    )
    wall, cpu, load1 = time.perf_counter() - t0, children_cpu() - cpu0, os.getloadavg()
    if r.returncode != 0:
        raise SystemExit(f"make luts failed ({r.returncode}):\n{r.stdout}\n{r.stderr}")
    return {"wall_s": wall, "cpu_s": cpu, "load_before": load0, "load_after": load1, "stdout": r.stdout}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=OUT / "luts.json")
    ap.add_argument("--no-cold", action="store_true", help="skip part 5 (the empty kernel cache runs)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="lutbake-bench-luts-") as tmp:
        out = Path(tmp) / "outputs"
        clean = make_luts(out)
        report = json.loads((out / "report.json").read_text())
        cache_bytes = sum(p.stat().st_size for p in (out / ".cache").iterdir())
        rerun = make_luts(out)
        filing_out = Path(tmp) / "filing"
        filing = make_luts(filing_out, f"PRESETS={FILING_PRESETS}")
        filing_tables = len(json.loads((filing_out / "report.json").read_text())["tables"])
        cold = {}
        if not args.no_cold:
            tmp_path = Path(tmp)
            cold["make_luts"] = make_luts(tmp_path / "cold", warp_cache=tmp_path / "warp-all")
            cold["filing_batch"] = make_luts(
                tmp_path / "cold-filing", f"PRESETS={FILING_PRESETS}", warp_cache=tmp_path / "warp-filing"
            )
    tables = report["tables"]
    assert all(t["status"] == "baked" for t in tables), [t["name"] for t in tables if t["status"] != "baked"]
    table_cpu = sum(t["cpu_seconds"] for t in tables)
    top = sorted(tables, key=lambda t: -t["cpu_seconds"])[:TOP]
    shared = {t["name"]: t["values_from"] for t in tables if t["values_from"]}
    doc = {
        "machine": f"{platform.node()} ({platform.machine()}, {os.cpu_count()} cores)",
        "target_wall_s": TARGET_WALL,
        "clean": {k: v for k, v in clean.items() if k != "stdout"},
        "up_to_date_rerun": {k: v for k, v in rerun.items() if k != "stdout"},
        "filing_batch": {
            "presets": FILING_PRESETS,
            "tables": filing_tables,
            **{k: v for k, v in filing.items() if k != "stdout"},
        },
        "empty_kernel_cache": {k: {f: v for f, v in c.items() if f != "stdout"} for k, c in cold.items()},
        "tables": len(tables),
        "computations": len(tables) - len(shared),
        "shared": shared,
        "cache_bytes": cache_bytes,
        "tables_cpu_s": table_cpu,
        "outside_tables_cpu_s": clean["cpu_s"] - table_cpu,
        "per_table": [
            {k: t[k] for k in ("name", "seconds", "cpu_seconds", "values_from", "samples")}
            for t in sorted(tables, key=lambda t: -t["cpu_seconds"])
        ],
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(doc, indent=2) + "\n")
    ok = "meets" if clean["wall_s"] <= TARGET_WALL else "misses"
    print(
        f"make luts (clean, {len(tables)} tables, {doc['computations']} computations): {clean['wall_s']:.1f} s wall, "
        f"{clean['cpu_s']:.1f} s CPU, load {clean['load_before'][0]:.1f} -> {clean['load_after'][0]:.1f}; "
        f"target <= {TARGET_WALL:.0f} s wall: {ok}"
    )
    print(
        f"  tables' computations {table_cpu:.1f} s CPU; outside them (start-up, configs, hashing, writes) "
        f"{doc['outside_tables_cpu_s']:.1f} s CPU; shared: "
        + (", ".join(f"{k} <- {v}" for k, v in shared.items()) or "-")
    )
    print(
        f"  up-to-date rerun: {rerun['wall_s']:.2f} s wall, {rerun['cpu_s']:.2f} s CPU; "
        f"values cache {cache_bytes / 2**20:.1f} MiB"
    )
    print(
        f"  the batch of issue 13's filing (configs/ + {FILING_PRESETS}: {filing_tables} tables): "
        f"{filing['wall_s']:.1f} s wall, {filing['cpu_s']:.1f} s CPU; target <= {TARGET_WALL:.0f} s wall: "
        + ("meets" if filing["wall_s"] <= TARGET_WALL else "misses")
    )
    for what, c in cold.items():
        print(
            f"  {what.replace('_', ' ')} on an empty kernel cache (every module compiles first): {c['wall_s']:.1f} s "
            f"wall, {c['cpu_s']:.1f} s CPU"
        )
    print(f"  top {TOP} tables by CPU:")
    for t in top:
        print(f"    {t['name']:<40} {t['cpu_seconds']:7.2f} s CPU  {t['seconds']:7.2f} s wall (tiles)")
    print(f"wrote {args.out.relative_to(ROOT) if args.out.is_relative_to(ROOT) else args.out}")


if __name__ == "__main__":
    main()
