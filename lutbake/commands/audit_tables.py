"""``lutbake audit`` for the table kinds beyond the split-sum family: LTC tables (``--preset ltc-ggx``) and OpenPBR's
energy arrays (``--preset openpbr``). lutbake.commands.audit dispatches here by the preset's kind.

LTC (Heitz, Dupuy, Hill, Neubelt 2016, "Real-Time Polygonal-Light Shading with Linearly Transformed Cosines").
A user auditing a shipped LTC table needs to know (1) whether the *unique* quantities are right: the magnitude
(the lobe's directional albedo ∫ f cos), the Fresnel term and the sphere table, each an integral with one answer
-- compared with lutbake's converged Gauss-Legendre integrals, as the dfg audit does; (2) whether the matrices
are a *good* fit. The matrix is the minimiser of a non-convex fit error with several near-equivalent minima (and
ltc_code's own fit walks its table from a neighbour's solution), so two correct tables can differ in their
coefficients by far more than any tolerance: the raw coefficient differences are reported but not judged.
Judged instead is what the matrices are for: Heitz's fit error of the file's matrices against the lobe, next to
that of lutbake's own fit at the same texels (``fit_ratio``: the file's median error / lutbake's; a packing or
axis mistake in a file makes its error many times a proper fit's), and the area-light result (magnitude x polygon
integral) against a brute-force integral of the lobe over lights of several sizes and positions
(lutbake.validate.ltc_area), for the file and for lutbake's fit. PASS when the magnitude/Fresnel ``metric`` is
within the tolerance and ``fit_ratio`` <= FIT_RATIO_MAX.

OpenPBR (adobe/openpbr-bsdf ``impl/data/openpbr_*_data.h``, UNORM16): each energy array against lutbake's bake
under the ``openpbr`` preset's conventions (its [ior][alpha][cos] grid, separable Smith, exact Fresnel), at a
strided subset of IOR slices and roughness rows; the reflection ratio against lutbake's (its Kulla-Conty split of
the two sides' averages, lutbake.integrands.dielectric_ratio) where OpenPBR reads it (alpha index >= 2, eta != 1;
the rest reported apart), and against the reciprocity identity of OpenPBR's multiple-scattering lobe
(1 - x(eta)) E_avg(eta) = (1 - x(1/eta)) E_avg(1/eta). The cos = 0 column is reported apart: lutbake evaluates
NoV >= NOV_MIN there (lutbake.edge), a limit the shipped Monte Carlo estimator does not take.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .audit_report import MISMATCH_RATIO, PERCENTILES, metric_value, stats, subset, verdict, write_error_map

FIT_RATIO_MAX = 2.0  # the file's median Heitz fit error may be at most this x lutbake's fit at the same texels
AREA_TEXELS = 6  # texels (a spread of roughness and view) of the area-light comparison
AREA_SAMPLES = 256  # brute-force samples per side (stratified) per light
UNORM16_STEP = 1.0 / 65535.0
OPENPBR_KEYS = (
    ("ideal_dielectric_energy_complement", "dielectric", 0),
    ("opaque_dielectric_energy_complement", "dielectric", 1),
    ("ideal_metal_energy_complement", "dielectric", 2),
    ("ideal_dielectric_avg_energy_complement", "dielectric_avg", 0),
    ("opaque_dielectric_avg_energy_complement", "dielectric_avg", 1),
    ("ideal_metal_avg_energy_complement", "dielectric_avg", 2),
)
RATIO_CHANNEL = 3  # of the openpbr dielectric_avg layout: ideal_dielectric_reflection_ratio


@dataclass
class TableAuditReport:
    """The report of an LTC or OpenPBR audit (same interface as lutbake.commands.audit.AuditReport: text, as_dict,
    passed)."""

    file: str
    conventions: str
    kind: str
    errors: dict  # quantity -> stats (+ "where")
    findings: list[str]
    metric: str
    tolerance: float
    value: float
    passed: bool
    extra: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}

    def text(self) -> str:
        lines = [f"audit {self.file}", f"  conventions: {self.conventions}", "  |file - converged re-bake|:"]
        for c, s in self.errors.items():
            where = f" at {s['where']}" if "where" in s else ""
            lines.append(
                f"    {c}: max {s['max']:.3g}{where}, mean {s['mean']:.3g}, "
                + ", ".join(f"p{p} {s[f'p{p}']:.3g}" for p in PERCENTILES)
            )
        lines.append("  findings:")
        lines += [f"    - {f}" for f in self.findings]
        verdict = "PASS" if self.passed else "FAIL"
        lines.append(f"  {verdict}: {self.metric} error {self.value:.3g} (tolerance {self.tolerance:g})")
        return "\n".join(lines)


def _read_text(path: Path) -> str:
    from ..io import bounded  # size caps: a text table or its gzip at most bounded.MAX_TEXT_BYTES

    raw = bounded.read_bytes(path, bounded.MAX_TEXT_BYTES, "a text table")
    return (bounded.gunzip(raw) if path.suffix == ".gz" else raw).decode("utf-8", "replace")


# --------------------------------------------------------------------------------------------------- LTC


def read_ltc_pair(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(ltc_1, ltc_2) as (N, N, 4) float64, row = view index, column = roughness index: ltc_code's ``ltc.js``
    (``g_ltc_1``, ``g_ltc_2``; three.js' ``LTC_MAT_1/2`` alike; also gzip-compressed), lutbake's ``_1.dds`` pair, or
    any text holding two numeric arrays of N x N x 4 values (the first two are taken)."""
    from ..io import dds

    path = Path(path)
    if path.name.endswith("_1.dds"):
        second = path.with_name(path.name.replace("_1.dds", "_2.dds"))
        from ..io.bounded import read_bytes

        return tuple(dds.decode(read_bytes(p))[0].astype(np.float64) for p in (path, second))
    text = _read_text(path)
    num = re.compile(r"-?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
    arrays = []
    for body in re.findall(r"\[([^\[\]]*)\]", text):
        vals = num.findall(body)
        n = math.isqrt(len(vals) // 4) if len(vals) >= 4 else 0
        if n >= 2 and n * n * 4 == len(vals):
            arrays.append(np.array([float(v) for v in vals]).reshape(n, n, 4))
        if len(arrays) == 2:
            break
    if len(arrays) != 2 or arrays[0].shape != arrays[1].shape:
        raise ValueError(
            f"{path}: expected two [...] arrays of N x N x 4 numbers (ltc_1, ltc_2: ltc_code's ltc.js, three.js' "
            f"LTC_MAT_1/2, lutbake's ltc js output) or a lutbake _1.dds, found {len(arrays)}; Blender's and HDRP's "
            "C/C# layouts (ltc_mag with 2 channels, HDRP's packing) are not read"
        )
    return arrays[0], arrays[1]


def ltc_hypotheses(lobe, axes, iy, ix, nov_all, alpha_mag, mag, got) -> list[dict]:
    """The usual hand-over mistakes, each a prediction of the file's magnitudes (t2.x) at the subset texels (median
    and RMS of |file - prediction|):
    rows or columns in reverse order, axes swapped (square tables), the roughness axis read as alpha (alpha = r,
    not r^2), and the view rows in ltc_code's parameterisation before fa68f58 (theta = t pi/2 linear, NoV =
    cos theta, not sqrt(1 - NoV) = t) -- a table of one used with the other's uv."""
    from ..ltc.magnitude import magnitude_fresnel

    n_view, n_rough = axes[1].count, axes[2].count
    nov_row, alpha_col = nov_all[::n_rough].astype(np.float64), alpha_mag[:n_rough].astype(np.float64)
    ny, nx = len(iy), len(ix)

    def grid(nov_rows, alpha_cols):  # NoV per subset row, alpha per subset column -> per texel, row-major
        return np.repeat(nov_rows, nx), np.tile(alpha_cols, ny)

    r = axes[2].values().astype(np.float64)[ix]
    t = iy / max(n_view - 1, 1)
    cases = [
        ("nominal", "the declared conventions", *grid(nov_row[iy], alpha_col[ix])),
        ("rows_flipped", "view rows in reverse order", *grid(nov_row[n_view - 1 - iy], alpha_col[ix])),
        ("columns_flipped", "roughness columns in reverse order", *grid(nov_row[iy], alpha_col[n_rough - 1 - ix])),
        ("roughness_is_alpha", "the roughness axis holds alpha (alpha = r, not r^2)", *grid(nov_row[iy], r)),
        (
            "view_theta_linear",
            "view rows linear in theta (NoV = cos(t pi/2): ltc_code before fa68f58)",
            *grid(np.maximum(np.cos(t * np.pi / 2), nov_row.min()), alpha_col[ix]),
        ),
    ]
    if n_view == n_rough:  # the file's (row y, column x) holds the truth of (row x, column y)
        cases.append(
            (
                "axes_swapped",
                "rows and columns exchanged (roughness down, view across)",
                np.tile(nov_row[ix], ny),
                np.repeat(alpha_col[iy], nx),
            )
        )
    out = []
    for name, desc, nov, alpha in cases:
        pred = mag if name == "nominal" else magnitude_fresnel(lobe, np.asarray(nov), np.asarray(alpha), None)[0]
        d = np.abs(got - pred)
        out.append(
            {"name": name, "description": desc, "rms": float(np.sqrt(np.mean(d**2))), "median": float(np.median(d))}
        )
    return out


def audit_ltc(
    path, spec, tolerance: float, metric: str, max_side: int, area_texels: int = AREA_TEXELS, error_map=None
) -> TableAuditReport:
    from ..kinds.ltc import axes_for
    from ..ltc import fit, sphere
    from ..ltc.magnitude import magnitude_alpha, magnitude_fresnel, texel_params
    from ..validate import ltc_area

    t1, t2 = read_ltc_pair(Path(path))
    n_view, n_rough = t1.shape[:2]
    o = {**spec.options, "size": [n_view, n_rough]}
    lobe = spec.records["lobe"].obj
    axes = axes_for(o, lobe)
    nov_all, alpha_fit = texel_params(axes, o["alpha_min"])
    alpha_mag = magnitude_alpha(axes, o["alpha_min"])
    iy, ix = subset(n_view, max_side), subset(n_rough, max_side)
    texel = (iy[:, None] * n_rough + ix[None, :]).ravel()
    nov, a_fit, a_mag = nov_all[texel], alpha_fit[texel], alpha_mag[texel]
    mag, fres = magnitude_fresnel(lobe, nov, a_mag, None)
    f_t2 = t2.reshape(-1, 4)[texel]
    errors, findings = {}, []
    rough = axes[2].values()
    hyps = ltc_hypotheses(lobe, axes, iy, ix, nov_all, alpha_mag, mag, f_t2[:, 0])
    # judged by the median |error| (the grazing row's sampling noise dominates an RMS; see the module docstring)
    nominal, best = hyps[0], min(hyps, key=lambda h: h["median"])
    mismatch = best is not nominal and best["median"] < MISMATCH_RATIO * nominal["median"]
    if mismatch:
        findings.append(
            f"convention mismatch: {best['name']}: {best['description']} (magnitude median |error| "
            f"{nominal['median']:.3g} -> {best['median']:.3g})"
        )
    else:
        alt = min(hyps[1:], key=lambda h: h["median"])
        findings.append(
            f"the declared conventions fit the magnitudes: no alternative explains them better by "
            f"{1 / MISMATCH_RATIO:g}x (median |error| {nominal['median']:.3g}; best alternative {alt['name']}, "
            f"{alt['median']:.3g})"
        )

    def where(k):
        y, x = divmod(int(texel[k]), n_rough)
        return f"row {y} (NoV {nov[k]:.4g}), column {x} ({axes[2].name} {rough[x]:.4g})"

    for name, got, want in (("magnitude (t2.x)", f_t2[:, 0], mag), ("fresnel (t2.y)", f_t2[:, 1], fres)):
        err = got - want
        s = stats(err)
        s["where"] = where(int(np.argmax(np.abs(err))))
        errors[name] = s
    if n_view == n_rough:
        sph = sphere.sphere_table(n_rough).reshape(-1)[texel]
        errors["sphere (t2.w)"] = stats(f_t2[:, 3] - sph)
    # the matrices: fit quality, not coefficients
    sub_ny, sub_nx = len(iy), len(ix)
    problem = fit.Problem(lobe, nov, a_fit, mag, o["fit_samples"])
    idx = np.arange(len(texel))
    # lutbake.ltc.fit.MEMO: audits of one table size (or the bake of its preset) share their texels' fits, same bits
    coarse = fit.coarse_pass(problem, sub_ny, sub_nx, fit.MEMO)
    m_ours, e_ours = fit.fit_texels(problem, idx, sub_nx, coarse, fit.MEMO)
    packed_file = t1.reshape(-1, 4)[texel]
    e_file = fit.heitz_error_of_packed(problem, idx, packed_file)
    rel_file, rel_ours = problem.relative(idx, e_file), problem.relative(idx, e_ours)
    # per texel, file / lutbake; the median is robust to the subset's share of grazing texels, where both fits are
    # poor and ltc_code's magnitudes are noisy
    fit_ratio = float(np.median(rel_file / np.maximum(rel_ours, 1e-300)))
    no_worse = float(np.mean(e_file <= e_ours * (1 + 1e-6)))
    coef = np.abs(packed_file - fit.pack_inverse(m_ours))
    findings.append(
        f"matrices (fit quality, Heitz's error, scale-free): file median {np.median(rel_file):.3g} / p90 "
        f"{np.quantile(rel_file, 0.9):.3g}; lutbake's fit at the same texels median {np.median(rel_ours):.3g} / p90 "
        f"{np.quantile(rel_ours, 0.9):.3g}; median per-texel ratio {fit_ratio:.4g} (limit {FIT_RATIO_MAX:g}); "
        f"lutbake's fit minimises this error, so the file is no worse at only {100 * no_worse:.0f} % of "
        f"{len(idx)} texels"
    )
    findings.append(
        "raw coefficients differ from lutbake's fit by up to "
        + ", ".join(f"{c} {coef[:, k].max():.3g}" for k, c in enumerate("xyzw"))
        + " (median "
        + ", ".join(f"{np.median(coef[:, k]):.2g}" for k in range(4))
        + "): LTC fits are not unique, so these are not judged"
    )
    # area lights: magnitude x polygon integral vs a brute-force integral of the lobe, file and lutbake's fit
    area = {}
    if area_texels:
        pick = np.unique(np.linspace(0, len(idx) - 1, area_texels).round().astype(int))
        ours_t1 = fit.pack_inverse(m_ours)
        references: dict = {}  # the brute force at a texel, the same for the file and lutbake's fit
        for label, m1 in (("file", packed_file), ("lutbake fit", ours_t1)):
            t2_sub = np.stack([mag, fres, np.zeros_like(mag), np.zeros_like(mag)], 1) if label != "file" else f_t2
            rows = []
            for i in pick:  # one texel at a time: compare() indexes NoV by row and alpha by column
                m1_i, t2_i = m1[[i]][:, None], t2_sub[[i]][:, None]
                rows += ltc_area.compare(
                    o["lobe"], m1_i, t2_i, nov[[i]], a_fit[[i]], [(0, 0)], AREA_SAMPLES, references=references
                )
            rel = np.array([r["rel_error"] for r in rows if r["rel_error"] is not None])
            area[label] = {"median": float(np.median(rel)), "p90": float(np.quantile(rel, 0.9)), "cases": len(rel)}
        findings.append(
            f"area lights ({len(pick)} texels x {len(ltc_area.LIGHTS)} lights, brute force {AREA_SAMPLES}^2): "
            f"median relative error file {area['file']['median']:.3g} (p90 {area['file']['p90']:.3g}), lutbake's "
            f"fit {area['lutbake fit']['median']:.3g} (p90 {area['lutbake fit']['p90']:.3g})"
        )
    allerr = np.abs(np.concatenate([f_t2[:, 0] - mag, f_t2[:, 1] - fres]))
    value = metric_value(allerr, metric)
    passed = bool(value <= tolerance and fit_ratio <= FIT_RATIO_MAX and not mismatch)
    if error_map is not None:
        err = np.stack([f_t2[:, 0] - mag, f_t2[:, 1] - fres], 1).reshape(len(iy), len(ix), 2)
        error_map = str(write_error_map(error_map, err, ["magnitude", "fresnel"], axes[1:], iy, ix, Path(path).name))
        findings.append(f"error map: {error_map}")
    findings.insert(
        0,
        f"magnitude / fresnel (unique integrals) {metric} |error| {value:.3g}; storage "
        + ("6 significant digits (text)" if not str(path).endswith(".dds") else "as the DDS"),
    )
    conventions = (
        f"preset ltc (lobe {o['lobe']}, rows NoV = 1 - t^2 endpoints, columns {axes[2].name} endpoints, "
        f"alpha >= {o['alpha_min']:g}); {len(iy)} x {len(ix)} of {n_view} x {n_rough} texels"
    )
    return TableAuditReport(
        str(path),
        conventions,
        "ltc",
        errors,
        findings,
        **verdict(metric, tolerance, value, passed),
        extra={
            "fit_ratio": fit_ratio,
            "fit_no_worse_fraction": no_worse,
            "area": area,
            "hypotheses": hyps,
            "chosen": best["name"] if mismatch else "nominal",
        },
    )


# ----------------------------------------------------------------------------------------------- OpenPBR


def audit_openpbr(path, specs, tolerance: float, metric: str, max_side: int) -> TableAuditReport:
    from ..layouts.openpbr import OPENPBR_SIZE
    from ..pipeline import plan_of

    n = OPENPBR_SIZE
    from ..io.bounded import load_npz_all

    shipped = {k: v.astype(np.float64) / 65535.0 for k, v in load_npz_all(Path(path)).items()}
    missing = [k for k, _, _ in OPENPBR_KEYS if k not in shipped]
    if missing:
        raise ValueError(f"{path}: missing OpenPBR arrays {missing} (keys: {sorted(shipped)})")
    by_kind = {s.kind: s for s in specs}
    iz, iy = subset(n, max_side), subset(n, max_side)
    plan3 = plan_of(by_kind["dielectric"])
    plan_avg = plan_of(by_kind["dielectric_avg"])
    ours3 = np.stack([np.stack([plan3.run_tile((z * n + y) * n, (z * n + y + 1) * n, "cpu") for y in iy]) for z in iz])
    ours_avg = np.stack([plan_avg.run_tile(z * n, (z + 1) * n, "cpu") for z in iz])  # (z, alpha, 3)
    errors, findings, judged = {}, [], []
    for key, kind, ch in OPENPBR_KEYS:
        a = shipped[key]
        if kind == "dielectric":
            ours = ours3[..., ch]
            got = a[np.ix_(iz, iy)] if a.ndim == 3 else np.broadcast_to(a[iy][None], ours.shape)
            body, edge = (got - ours)[..., 1:], (got - ours)[..., 0]
            s = stats(body)
            k = np.unravel_index(np.argmax(np.abs(body)), body.shape)
            s["where"] = f"ior index {iz[k[0]]}, alpha index {iy[k[1]]}, cos index {k[2] + 1}"
            errors[f"{key} (cos > 0)"] = s
            errors[f"{key} (cos = 0 column)"] = stats(edge)
            judged.append(body.ravel())
        else:
            ours = ours_avg[..., ch]
            got = a[iz] if a.ndim == 2 else np.broadcast_to(a[None], ours.shape)
            s = stats(got - ours)
            errors[key] = s
            judged.append((got - ours).ravel())
    # the reflection ratio (lutbake.integrands.dielectric_ratio): judged where OpenPBR reads it (alpha index >= 2,
    # eta != 1); at alpha index 0-1 and on the eta = 1 row the averages are ~0 and their rounding decides the ratio
    x = shipped["ideal_dielectric_reflection_ratio"]
    diff = x[iz] - ours_avg[..., RATIO_CHANNEL]
    body = np.zeros(diff.shape, bool)
    body[:, 2:] = True
    body[np.isin(iz, (n // 2 - 1, n // 2)), :] = False  # the two eta = 1 slices (lutbake.kinds.dielectric, openpbr)
    s = stats(diff[body])
    k = np.unravel_index(np.argmax(np.where(body, np.abs(diff), -1.0)), diff.shape)
    s["where"] = f"ior index {iz[k[0]]}, alpha index {k[1]}"
    errors["ideal_dielectric_reflection_ratio (alpha index >= 2, eta != 1)"] = s
    errors["ideal_dielectric_reflection_ratio (alpha index < 2 or eta = 1)"] = stats(diff[~body])
    judged.append(diff[body].ravel())
    ec = shipped["ideal_dielectric_avg_energy_complement"]
    k = np.arange(1, n // 2)
    inside, outside = n // 2 - 1 - k, n // 2 + k
    res = (1 - x[outside]) * ec[outside] - (1 - x[inside]) * ec[inside]
    findings.append(
        f"ideal_dielectric_reflection_ratio: re-baked from lutbake's averages (Kulla-Conty split); its reciprocity "
        f"identity (1 - x(eta)) E_avg(eta) = (1 - x(1/eta)) E_avg(1/eta) holds to max {np.abs(res).max():.3g} "
        f"(UNORM16 step {UNORM16_STEP:.3g})"
    )
    allerr = np.abs(np.concatenate(judged))
    rms_q = UNORM16_STEP / math.sqrt(12)
    findings.insert(
        0,
        f"storage UNORM16 (rounding RMS {rms_q:.2g}); residual RMS over cos > 0 {np.sqrt(np.mean(allerr**2)):.3g}: "
        "Monte Carlo noise of OpenPBR's generator above the rounding",
    )
    value = metric_value(allerr, metric)
    conventions = (
        f"preset openpbr ([ior][alpha][cos] {n}^3, separable Smith, exact Fresnel); {len(iz)} IOR slices "
        f"x {len(iy)} alpha rows x {n} cos of {n}^3"
    )
    return TableAuditReport(
        str(path),
        conventions,
        "openpbr",
        errors,
        findings,
        **verdict(metric, tolerance, value),
        extra={"reciprocity_residual_max": float(np.abs(res).max())},
    )


def dispatch(
    path, conv_args: dict, tolerance: float, metric: str, max_side: int, error_map=None, recorded=None
) -> TableAuditReport | None:
    """The LTC / OpenPBR audit when the declared conventions are one (a preset or config of kind ltc, or layout
    openpbr; without either, the file's ``recorded`` conventions); None for the dfg family
    (lutbake.commands.audit)."""
    from ..layouts import REGISTRY
    from .reference import declared_specs

    specs = declared_specs(conv_args, recorded, path)
    if specs[0].kind == "ltc":
        return audit_ltc(path, specs[0], tolerance, metric, max_side, error_map=error_map)
    record = REGISTRY.get((specs[0].kind, specs[0].options.get("layout")))
    if record is not None and "openpbr_arrays" in record.audit:  # the layout's record names its audit
        if error_map is not None:
            raise ValueError("--error-map: not drawn for OpenPBR's 3D arrays (the report names where each maximum is)")
        return audit_openpbr(path, specs, tolerance, metric, max_side)
    return None
