"""Render docs/benchmarks.md from the JSON files the benchmarks write (outputs/bench/*.json); ``make bench`` runs it.

docs/benchmarks.md is the one page of the documentation that holds measured times: it names the machine and the date
once, and every other page links to it instead of quoting a time. Each section comes from one file; a file that is
missing (a benchmark not run) gives a line saying so, so a partial ``make bench-ltc`` still renders.

An optional ``machine.json`` in the folder overrides the machine line and the date, and may add a note: the first
version of the page was rendered from benchmarks/initial_figures/, the figures the documentation quoted before.

Run: PYTHONPATH=. python benchmarks/write_benchmarks_md.py [--bench-dir outputs/bench] [--out docs/benchmarks.md]
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT / "outputs" / "bench"
DOC = ROOT / "docs" / "benchmarks.md"


def fmt(x) -> str:
    """A number as the docs write it: 3 significant digits, exponent form below 1e-3."""
    if isinstance(x, bool) or x is None:
        return {True: "yes", False: "no", None: "—"}[x]
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        if x == 0:
            return "0"
        if abs(x) < 1e-3 or abs(x) >= 1e5:
            return f"{x:.2e}"
        return f"{x:.3g}" if abs(x) < 100 else f"{x:.1f}"
    if isinstance(x, (list, tuple)):
        return ", ".join(fmt(v) for v in x)
    return str(x)


def table(header: list[str], rows: list[list]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "| " + " | ".join("---" for _ in header) + " |"]
    out += ["| " + " | ".join(fmt(c).replace("|", "\\|") for c in r) + " |" for r in rows]
    return out


def load(bench: Path, name: str) -> dict | None:
    p = bench / name
    return json.loads(p.read_text()) if p.exists() else None


def missing(name: str, target: str) -> list[str]:
    return [f"Not measured in this run (`{name}` missing; `make {target}` writes it).", ""]


def note(doc: dict) -> list[str]:
    return [doc["note"], ""] if doc.get("note") else []


def section_luts(doc: dict | None) -> list[str]:
    out = ["## `make luts`", ""]
    if doc is None:
        return out + missing("luts.json", "bench-luts")
    out += note(doc)
    clean, rerun = doc.get("clean", {}), doc.get("up_to_date_rerun", {})
    rows = [
        ["every table baked, kernels compiled", clean.get("wall_s"), clean.get("cpu_s")],
        ["rerun, every table up to date", rerun.get("wall_s"), rerun.get("cpu_s")],
    ]
    fb = doc.get("filing_batch")
    small = f"the {fb.get('tables', '?')}-table batch" if fb else "the smaller batch"
    if fb:
        rows.append([f"{small} (configs/ + {fb.get('presets', '')})", fb.get("wall_s"), fb.get("cpu_s")])
    for what, c in doc.get("empty_kernel_cache", {}).items():
        label = "every table" if what == "make_luts" else small
        rows.append([f"{label}, empty kernel cache (compiles first)", c.get("wall_s"), c.get("cpu_s")])
    out += [
        f"`make luts` into an empty folder: {doc.get('tables', '?')} tables, {doc.get('computations', '?')} "
        "computations (tables that hold the same values are computed once). Install time not included.",
        "",
    ]
    out += table(["run", "wall s", "CPU s"], rows) + [""]
    per = doc.get("per_table", [])[:10]
    if per:
        out += ["The ten tables that take the most CPU:", ""]
        out += table(
            ["table", "CPU s", "wall s (tiles)"], [[t["name"], t.get("cpu_seconds"), t.get("seconds")] for t in per]
        ) + [""]
    return out


def section_report(doc: dict | None) -> list[str]:
    out = ["## Accuracy per second (`benchmarks/bench.py`)", ""]
    if doc is None:
        return out + missing("report.json", "bench")
    out += note(doc)
    rows = []
    for name, t in doc.get("targets", {}).items():
        shown = {k: v for k, v in t.items() if k not in ("met", "load_average") and not isinstance(v, (dict, list))}
        rows.append([name, "; ".join(f"{k} {fmt(v)}" for k, v in shown.items()), t.get("met")])
    if rows:
        out += table(["target", "measured", "met"], rows) + [""]
    cases = doc.get("cases", {})
    for name in ("dfg_128", "dfg_128_tolerance"):
        rs = cases.get(name)
        if isinstance(rs, list) and rs:
            out += [f"`{name}`:", ""]
            out += table(
                ["estimator", "samples", "wall s", "max error"],
                [
                    [r.get("estimator", r.get("label")), r.get("samples"), r.get("seconds"), r.get("max_error")]
                    for r in rs
                ],
            ) + [""]
    base = doc.get("baselines") or {}
    if base:
        out += [
            f"The same estimator ({base.get('estimator', 'sobol_vndf')}) in Warp, C and numpy: Warp at "
            f"{fmt(base.get('warp_over_c_throughput'))}× the C throughput and "
            f"{fmt(base.get('warp_over_numpy_throughput'))}× numpy's.",
            "",
        ]
    return out


def section_interpolation(doc: dict | None) -> list[str]:
    out = ["## Verified interpolation (`benchmarks/bench_interpolation.py`)", ""]
    if doc is None:
        return out + missing("interpolation.json", "bench")
    out += note(doc)
    rows = [
        [
            t["table"],
            t.get("texels"),
            100 * t.get("interpolated", 0),
            t.get("cpu_s"),
            t.get("cpu_s_without"),
            t.get("max_error"),
            t.get("worst_error_over_bound"),
        ]
        for t in doc.get("tables", [])
    ]
    out += table(
        [
            "table",
            "texels",
            "% interpolated",
            "CPU s",
            "CPU s, every texel integrated",
            "max error",
            "worst error / estimate",
        ],
        rows,
    ) + [""]
    return out


def section_dielectric(doc: dict | None) -> list[str]:
    out = ["## Glass tables (`benchmarks/bench_dielectric.py`)", ""]
    if doc is None:
        return out + missing("dielectric.json", "bench")
    out += note(doc)
    if doc.get("reference"):
        out += [f"Errors against {doc['reference']}.", ""]
    rows = []
    for name, c in doc.get("cases", {}).items():
        for r in c.get("runs", []):
            order = f"order {r['gl_order']}" if r.get("gl_order") else "to the tolerance (default)"
            rows.append([name, order, r.get("bake_s"), r.get("max_abs"), r.get("mean_abs")])
    out += table(["table", "rule", "bake s", "max abs error", "mean abs error"], rows) + [""]
    return out


def section_ltc(docs: dict[str, dict]) -> list[str]:
    out = ["## LTC fits (`benchmarks/bench_ltc.py`)", ""]
    if not docs:
        return out + missing("ltc.json", "bench-ltc")
    rows = []
    for _, doc in sorted(docs.items()):
        out += note(doc)
        for lobe, r in doc.get("lobes", {}).items():
            rows.append(
                [
                    lobe,
                    r.get("size"),
                    r.get("seconds"),
                    r.get("cpu_seconds"),
                    r.get("fit_error_median"),
                    r.get("fit_error_p95"),
                    r.get("fit_error_max"),
                ]
            )
    out += table(["lobe", "size", "wall s", "CPU s", "fit error median", "p95", "max"], rows) + [""]
    shaded = [
        [lobe]
        + [r[fit]["all"][k] for fit in ("l3", "shaded") for k in ("rel_median", "rel_p90", "abs_max")]
        + [r["shaded"].get("cpu_seconds")]
        for doc in docs.values()
        for lobe, s in doc.get("area_lights_shaded", {}).items()
        if "all" in doc.get("area_lights", {}).get(lobe, {})
        for r in [{"l3": doc["area_lights"][lobe], "shaded": s}]
    ]
    if shaded:
        out += [
            'The other lobes fitted with `fit = "shaded"`, at the area-light texels (texel centres; relative error of '
            "magnitude × polygon integral against the brute force, and the largest |error| / magnitude):",
            "",
        ]
        header = ["lobe"] + [f"{fit} {k}" for fit in ("L3", "shaded") for k in ("rel median", "rel p90", "abs max")]
        out += table(header + ["shaded CPU s"], shaded) + [""]
    main = docs.get("ltc.json", {})
    port = main.get("baseline_straight_port")
    if port:
        out += [
            f"A single-threaded straight port of ltc_code's fitLTC ({port.get('texels_run')} texels, extrapolated): "
            f"{fmt(port.get('extrapolated_64x64_s'))} s for 64², {fmt(port.get('ratio_to_lutbake_ggx'))}× lutbake's "
            "GGX wall time.",
            "",
        ]
    pub = main.get("ggx_vs_published")
    if pub:
        med = pub.get("relative_error_median", {})
        out += [
            f"GGX against the published ltc_code table: no worse at {fmt(100 * pub['fraction_no_worse'])} % of the "
            f"texels; median relative L3 error {fmt(med.get('lutbake'))} (ltc_code {fmt(med.get('ltc_code'))}).",
            "",
        ]
    return out + section_area(main.get("area_benchmark"))


def section_area(doc: dict | None) -> list[str]:
    """The area-light benchmark (bench_ltc section 8): every table through the shader's bilinear lookup, per band."""
    if not doc:
        return []
    out = [
        f"### Area lights through the shader (GGX, {doc['cases']} shading points, {doc['lights']} polygon lights)",
        "",
        "Relative error median / p90 and |error| / albedo p90 of the shaded polygon integral against "
        f"{doc['truth']['estimator']} (lutbake.validate.ltc_bench); `two_lobe`: a second LTC for the Schlick part "
        "(a shader change).",
        "",
    ]
    times = doc.get("fit_times", {})
    fit_line = ", ".join(
        f"{k} {fmt(v['seconds'])} s" if isinstance(v, dict) and "seconds" in v else f"{k}: {v}"
        for k, v in times.items()
    )
    out += [f"GGX 64² fit times: {fit_line}.", ""]
    for f0 in ("f0=1", "f0=0.04"):
        res = doc.get(f0)
        if not res:
            continue
        names = list(res["tables"])
        rows = [
            [band]
            + [
                f"{fmt(r[band]['rel_median'])} / {fmt(r[band]['rel_p90'])} / {fmt(r[band]['abs_p90'])}"
                for r in (res["tables"][n] for n in names)
            ]
            for band in res["tables"][names[0]]
            if " / " not in band
        ]
        out += [f"{f0}:", ""] + table(["band"] + names, rows) + [""]
        for fit in ("shaded", "two_lobe"):
            ratio = res.get(f"{fit}_over_published")
            if ratio:
                out += [
                    f"- {fit} over published: median relative {fmt(ratio['rel_median'])}, |error| / albedo p90 "
                    f"{fmt(ratio['abs_p90'])}, roughness × view bands worse: "
                    f"{len(ratio['bands_worse_in_rel_median_or_abs_p90'])} of 16"
                ]
        out += [""]
    return out


def section_cluster(doc: dict | None) -> list[str]:
    out = ["## Dask cluster against the thread executor (`benchmarks/bench_cluster.py`)", ""]
    if doc is None:
        return out + missing("cluster.json", "bench-cluster")
    out += note(doc)
    batch = doc.get("batch", {})
    out += [
        f"The {batch.get('tables', '?')}-table batch on `{batch.get('scheduler', 'local:2')}`: median wall ratio "
        f"{fmt(doc.get('median_ratio'))} (target ≤ {fmt(doc.get('target_ratio'))}), CPU-seconds ratio "
        f"{fmt(doc.get('median_cpu_ratio'))}.",
        "",
    ]
    big = doc.get("largest_table", {})
    proj = big.get("projection", {})
    if proj:
        out += [f"`{big.get('name', 'lut_ggx')}` projected over N workers ({big.get('model', '')}):", ""]
        out += table(
            ["workers", "wall s", "serial fraction"],
            [[n, p.get("seconds"), p.get("serial_fraction")] for n, p in proj.items()],
        ) + [""]
    return out


def section_diffuse(doc: dict | None) -> list[str]:
    out = ["## Diffuse kinds (`benchmarks/bench_diffuse.py`, `make bench-diffuse`)", ""]
    if doc is None:
        return out + missing("diffuse.json", "bench-diffuse")
    out += note(doc)
    rows = []
    for r in doc.get("results", []):
        err = r.get("max_abs_error", r.get("max_rel_error"))
        rows.append(
            [
                f"{r.get('kind', '?')} {r.get('size', '')}".strip(),
                r.get("seconds"),
                r.get("cpu_seconds"),
                err,
                r.get("error_estimate"),
            ]
        )
    out += table(["table", "wall s", "CPU s", "max error", "recorded estimate"], rows) + [""]
    return out


def machine_line(docs: list[dict]) -> str:
    for d in docs:
        m = d.get("machine") if isinstance(d, dict) else None
        if isinstance(m, dict) and m.get("cpu"):
            return (
                f"{m['cpu']}, {m.get('cores', os.cpu_count())} cores; Python {m.get('python', '?')}, Warp "
                f"{m.get('warp', '?')}; {m.get('platform', '')}".rstrip("; ")
            )
        if isinstance(m, str) and m:
            return m
    return f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores"


def render(bench: Path) -> str:
    names = ["luts.json", "report.json", "interpolation.json", "dielectric.json", "cluster.json", "diffuse.json"]
    docs = {n: load(bench, n) for n in names}
    ltc = {p.name: json.loads(p.read_text()) for p in sorted(bench.glob("ltc*.json"))}
    found = [p for p in bench.glob("*.json")] if bench.exists() else []
    stamp = max((p.stat().st_mtime for p in found), default=None)
    meta = load(bench, "machine.json") or {}
    date = meta.get("date") or (
        datetime.datetime.fromtimestamp(stamp, datetime.UTC).strftime("%Y-%m-%d") if stamp else "—"
    )
    machine = meta.get("machine") or machine_line([d for d in docs.values() if d] + list(ltc.values()))
    out = [
        "# Benchmarks",
        "",
        "Written by `make bench` (`benchmarks/write_benchmarks_md.py`, from `outputs/bench/*.json`); do not edit by"
        " hand.",
        "The other pages quote no times: they link here. Rerun `make bench` to measure your machine.",
        "",
        f"**Machine:** {machine}. **Date:** {date}.",
        "",
    ]
    if meta.get("note"):
        out += [meta["note"], ""]
    out += section_luts(docs["luts.json"])
    out += section_report(docs["report.json"])
    out += section_interpolation(docs["interpolation.json"])
    out += section_dielectric(docs["dielectric.json"])
    out += section_ltc(ltc)
    out += section_cluster(docs["cluster.json"])
    out += section_diffuse(docs["diffuse.json"])
    return "\n".join(out).rstrip("\n") + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bench-dir", type=Path, default=BENCH, help="where the benchmarks' JSON files are")
    ap.add_argument("--out", type=Path, default=DOC)
    args = ap.parse_args()
    text = render(args.bench_dir)
    args.out.write_text(text)
    print(f"wrote {args.out} ({len(text.encode())} bytes)")


if __name__ == "__main__":
    main()
