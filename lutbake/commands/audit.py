"""``lutbake audit FILE``: compare a shipped LUT with a converged re-bake under declared conventions, and
diagnose the usual hand-over mistakes by testing each one against the data.

The conventions are a ``dfg`` table spec (a preset or config, plus ``--set`` keys; the size is the file's); a
preset or config of kind ``ltc`` or layout ``openpbr`` is audited by lutbake.commands.audit_tables instead.
Every file texel (row y, column x) then has a declared (NoV, alpha) (lutbake.kinds.dfg.axes_for); the
reference is lutbake's Gauss-Legendre integral at those points (error ~4e-7), on a strided subset of at most
``max_side`` x ``max_side`` texels (the last row and column always included).

Hypotheses: every combination of four factors (lutbake.commands.audit_search), each a prediction of the whole
file, compared with the decoded file by RMS over the channels the declared layout and the file share; the nominal one
is the declared conventions, with the storage encoding the preset's engine table declares (``EngineTable.encoding``:
Babylon's RGBD PNG) when the file's storage can hold it:
- points: the roughness or NoV axis shifted by +-1/2 or +-1 texel (t -> t + s/N before the mapping), the roughness
  axis read as alpha (alpha = value) or squared twice (alpha = value^4) -- each re-integrated once at its own points;
- channels: R and G swapped, the other split-sum layout (scale/bias <-> multiscatter: (R, G) = (bias, scale + bias));
- order: rows or columns flipped, axes swapped (square tables) and their compositions -- undone on the file;
- encoding: sRGB-encoded (file = OETF(truth)) or sRGB-decoded (file = EOTF(truth), a linear LUT loaded as sRGB and
  saved back), RGBD, RGBM, half floats in 16-bit codes, or the values as stored -- undone by decoding the file.
A combination is the diagnosis when its RMS is below MISMATCH_RATIO x that of the best with fewer mistakes. Its
residual then says whether anything explains the data: the storage rounding alone, sampling noise (as rough from
texel to texel as the engines' estimator's error of the same RMS), or neither ("no hypothesis explains the data").
Then, with the chosen conventions:
- quantisation: the smallest UNORM bit depth (8, 10, 12, 16) on whose code grid every value lies, or half
  floats (every value exactly representable); the rounding it alone leaves (the converged table encoded, rounded and
  decoded as the file is);
- Monte-Carlo noise, when the residual is noise: the residual against the converged integral, compared with
  lutbake's own estimate by the engines' usual generator (Hammersley points, NDF importance sampling: Filament
  cmgen, the glTF IBL sampler, UE4) at N = 64 ... 16384 samples, stored the same way; the N whose residual matches
  the file's (log-log interpolation) is the estimated sample count.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..axes import Axis
from ..edge import NOV_MIN
from ..io.bounded import reading_for
from ..io.lut_files import LutFile, read_lut
from .audit_report import (
    METRICS,
    PERCENTILES,
    metric_value,
    stats,
    subset,
    verdict,
    write_error_map,
)
from .audit_search import (
    DECLARED,
    ENCODINGS,
    EXACT_RMS,
    MISMATCH_RATIO,
    NOISE_ROUGHNESS_MIN,
    Candidate,
    Encoding,
    Factor,
    Search,
    at_rounding,
    channel_ops,
    choose,
    explain,
    listed,
    rms,
    roughness,
    round_trip,
)
from .audit_tables import dispatch
from .reference import Conventions, Reference, conventions

MAX_SIDE = 128  # default subset: at most this many rows and columns are re-integrated
QUANT_TOL = 1e-3  # a value is on a UNORM code grid when |v (2^b - 1) - round| <= this (in codes)
UNORM_BITS = (8, 10, 12, 16)
NOISE_SAMPLES = (64, 256, 1024, 4096, 16384)  # the calibration bakes of the noise estimate
NOISE_SIDE = (
    32  # the noise calibration's grid: NOISE_SIDE + 1 evenly spread rows and columns of the subset (1089 texels)
)


@dataclass
class Positions:
    """Per-texel (NoV, alpha, perceptual roughness) of a file-sized grid: rows x columns."""

    nov: np.ndarray
    alpha: np.ndarray
    rough: np.ndarray  # perceptual roughness before the alpha floor (the Disney diffuse channel's parameter)

    def map(self, fn) -> Positions:
        """The same index operation (flip, transpose, subset) applied to every field."""
        return Positions(fn(self.nov), fn(self.alpha), fn(self.rough))


def _axis_values(axis: Axis, shift: float) -> np.ndarray:
    """The axis' values with t moved by ``shift`` texels (toward t = 1), clamped to [0, 1] as generators do."""
    t = np.clip(axis.t() + shift / axis.count, 0.0, 1.0)
    return axis._map(t)


def positions(
    conv: Conventions, shift_rough: float = 0.0, shift_nov: float = 0.0, alpha_power: float | None = None
) -> Positions:
    """(NoV, alpha) at every file texel; ``alpha_power``: alpha = roughness-axis value ** power (declared:
    2 for perceptual roughness, 1 for alpha)."""
    y_axis, x_axis = conv.axes
    vals = {}
    for a in (y_axis, x_axis):
        vals[a.name] = _axis_values(a, shift_nov if a.name == "NoV" else shift_rough)
    rname = next(n for n in vals if n != "NoV")
    power = alpha_power if alpha_power is not None else (2.0 if rname == "perceptual_roughness" else 1.0)
    nov_1d = np.maximum(vals["NoV"], NOV_MIN)
    alpha_1d = np.clip(vals[rname] ** power, 0.0, None)  # the integrand applies the alpha -> 0 policy (lutbake.edge)
    rough_1d = np.sqrt(np.clip(vals[rname] ** power, 0.0, None))
    if x_axis.name == "NoV":
        nov, alpha = np.meshgrid(nov_1d, alpha_1d)
        rough = np.meshgrid(nov_1d, rough_1d)[1]
    else:
        alpha, nov = np.meshgrid(alpha_1d, nov_1d)
        rough = np.meshgrid(rough_1d, nov_1d)[0]
    return Positions(nov, alpha, rough)


def point_sets(conv: Conventions) -> list[tuple[Factor, Positions]]:
    """The declared texel positions and the positional mistakes, each a set of points integrated once (the search's
    first factor, lutbake.commands.audit_search)."""
    rname = next(a.name for a in conv.axes if a.name != "NoV")
    out = [(DECLARED, positions(conv))]
    for axis, key in (("roughness", "shift_rough"), ("NoV", "shift_nov")):
        for s in (-1.0, -0.5, 0.5, 1.0):
            what = "one texel" if abs(s) == 1 else "half a texel"
            toward = "toward t = 1 (rougher)" if axis == "roughness" else "toward t = 1 (larger NoV)"
            if s < 0:
                toward = toward.replace("t = 1", "t = 0").replace("rougher", "smoother").replace("larger", "smaller")
            name = f"{axis.lower()}_offset_{s:+g}"
            desc = f"the {axis} axis offset by {what} {toward}: every texel holds t {s:+g}/N"
            out.append((Factor(name, f"{axis} axis offset {s:+g} texel", desc), positions(conv, **{key: s})))
    powers = (
        [
            ("roughness_is_alpha", "roughness read as alpha", "alpha = t, not perceptual roughness (alpha = t^2)", 1.0),
            (
                "roughness_squared_twice",
                "roughness squared twice",
                "alpha = t^4: perceptual roughness squared twice",
                4.0,
            ),
        ]
        if rname == "perceptual_roughness"
        else [("roughness_is_perceptual", "roughness read as perceptual", "alpha = t^2, not alpha", 2.0)]
    )
    for name, label, desc, power in powers:
        out.append((Factor(name, label, f"the roughness axis: {desc}"), positions(conv, alpha_power=power)))
    return out


def detect_quantisation(values: np.ndarray, storage: str) -> dict:
    """How the values are stored: the UNORM bit depth whose code grid holds every value, else half floats."""
    v = values[np.isfinite(values)].ravel()
    for bits in UNORM_BITS:
        m = float((1 << bits) - 1)
        if v.size and v.min() >= 0 and v.max() <= 1 and np.max(np.abs(v * m - np.round(v * m))) <= QUANT_TOL:
            return {
                "kind": f"unorm{bits}",
                "step": 1.0 / m,
                "description": f"{bits}-bit UNORM codes (step 1/{int(m)} = {1.0 / m:.3g})",
            }
    if v.size and np.array_equal(v.astype(np.float16).astype(np.float64), v):
        return {"kind": "half", "step": None, "description": "IEEE half floats (relative step 2^-11 = 4.9e-4)"}
    return {"kind": "float", "step": None, "description": f"floats (file storage {storage})"}


def rounding_step(values: np.ndarray, quant: dict) -> np.ndarray:
    """The storage's rounding step at each stored value: 1 / (2^b - 1) for b-bit UNORM, the spacing of half floats
    at |v| (2^-24 below 2^-14) or of float32."""
    if quant["kind"].startswith("unorm"):
        return np.full(np.shape(values), quant["step"])
    dtype = np.float16 if quant["kind"] == "half" else np.float32
    return np.spacing(np.abs(np.asarray(values)).astype(dtype)).astype(np.float64)


def recorded_attributes(path, shape=None) -> tuple[dict, LutFile | None]:
    """The lutbake attributes the file records (EXR header, KTX2 key/value data, or its ``<file>.json`` sidecar),
    {} for another tool's file; and the file read (None where read_lut cannot read it), so it is read once."""
    try:
        lut = read_lut(path, shape=shape)
        return lut.attrs, lut
    except (ValueError, OSError):
        from ..io import bounded

        side = Path(path).with_name(Path(path).name + ".json")
        try:  # a sidecar that cannot be read records nothing: the audit then says what is wrong with the file
            doc = bounded.load_json(side) if side.is_file() else {}
        except (ValueError, OSError, RecursionError, UnicodeDecodeError):
            return {}, None
        return (doc.get("lutbake", {}) if isinstance(doc, dict) else {}), None


def quantise(values: np.ndarray, quant: dict) -> np.ndarray:
    if quant["kind"].startswith("unorm"):
        m = 1.0 / quant["step"]
        return np.round(np.clip(values, 0.0, 1.0) * m) / m
    if quant["kind"] == "half":
        return values.astype(np.float16).astype(np.float64)
    return values


@dataclass
class AuditReport:
    file: str
    conventions: str
    channels: list[str]
    evaluated: dict
    errors: dict  # channel -> stats of |file - reference| under the declared conventions
    hypotheses: list[dict]
    diagnosis: list[str]
    quantisation: dict
    noise: dict
    metric: str
    tolerance: float
    value: float
    passed: bool
    error_map: str | None = None
    extra: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}

    def text(self) -> str:
        lines = [
            f"audit {self.file}",
            f"  conventions: {self.conventions}",
            f"  evaluated: {self.evaluated['rows']} x {self.evaluated['columns']} of "
            f"{self.evaluated['file_rows']} x {self.evaluated['file_columns']} texels "
            f"(stride {self.evaluated['stride']})",
            "  |file - converged re-bake| per channel:",
        ]
        for c, s in self.errors.items():
            lines.append(
                f"    {c}: max {s['max']:.3g} at {s['where']}, mean {s['mean']:.3g}, "
                + ", ".join(f"p{p} {s[f'p{p}']:.3g}" for p in PERCENTILES)
            )
        lines.append("  hypotheses (RMS over " + "/".join(self.channels) + ", best first):")
        for h in sorted(self.hypotheses, key=lambda h: h["rms"])[:6]:
            lines.append(f"    {h['rms']:.3g}  {h['name']}: {h['description']}")
        lines.append(f"  storage: {self.quantisation['description']}")
        lines.append("  diagnosis:")
        lines += [f"    - {d}" for d in self.diagnosis]
        if self.error_map:
            lines.append(f"  error map: {self.error_map}")
        verdict = "PASS" if self.passed else "FAIL"
        raw = self.extra.get("raw_error")
        lines.append(
            f"  {verdict}: {self.metric} error beyond the storage rounding {self.value:.3g} "
            f"{'<=' if self.passed else '>'} tolerance {self.tolerance:g}"
            + (
                f" (|file - converged| max {raw['max']:.3g}, where one rounding step is {raw['step_at_max']:.3g})"
                if raw
                else ""
            )
        )
        return "\n".join(lines)


def _calibration(integ: Reference, chosen: Chosen, quant: dict, gy, gx) -> list[dict] | None:
    """The engines' estimator (Hammersley points, NDF importance sampling) at NOISE_SAMPLES samples, at the chosen
    points of the (gy, gx) grid of the subset, with the chosen channel mistake, stored in the chosen encoding and
    rounded as the file is: per N, the RMS (R, G) of its error against the converged table and its roughness rho
    (lutbake.commands.audit_search.roughness); None for a layout the estimator does not compute (the sheen ones)."""
    grid = chosen.positions.map(lambda a: a[np.ix_(gy, gx)])
    points = chosen.points_prediction[np.ix_(gy, gx)]
    ref = chosen.prediction[np.ix_(gy, gx)][..., :2]

    def stored(values):  # the chosen channel mistake, then the chosen encoding's rounding
        return round_trip(chosen.candidate.channels.apply(values), chosen.encoding, lambda v: quantise(v, quant))

    curve = []
    for n in NOISE_SAMPLES:
        est = integ.hammersley(grid.nov.ravel(), grid.alpha.ravel(), n)
        if est is None:
            return None
        full = points.copy()
        full[..., :2] = est.reshape(points.shape[:2] + (2,))
        err = stored(full)[..., :2] - ref
        curve.append({"samples": n, "rms": rms(err), "roughness": roughness(err)})
    return curve


def _noise(curve: list[dict] | None, rms_obs: float, rms_quant: float, layout: str) -> dict:
    """The estimated sample count of the file's generator: the N whose estimator error (``curve``) matches the file's
    residual RMS, interpolated in log-log (see the module docstring)."""
    out = {"detected": True, "rms_residual": rms_obs, "rms_quantisation_alone": rms_quant, "samples": None}
    if curve is None:
        out["description"] = (
            f"sampling noise: residual RMS {rms_obs:.3g} above the rounding ({rms_quant:.3g}) and rough as noise; "
            f"no sample-count calibration for layout {layout}"
        )
        return out
    out["calibration"] = curve
    ns, es = np.log([c["samples"] for c in curve]), np.log([c["rms"] for c in curve])
    order = np.argsort(es)  # np.interp needs increasing x: the error falls with N
    if rms_obs >= curve[0]["rms"]:
        bound = f"<= {curve[0]['samples']}"
    elif rms_obs <= curve[-1]["rms"]:
        bound = f">= {curve[-1]['samples']}"
    else:
        out["samples"] = float(np.exp(np.interp(np.log(rms_obs), es[order], ns[order])))
        bound = f"~{out['samples']:.0f}"
    out["samples_bound"] = bound
    out["description"] = (
        f"Monte-Carlo noise: residual RMS {rms_obs:.3g} vs {rms_quant:.3g} from rounding alone; matches a "
        f"Hammersley NDF-sampled estimate with {bound} samples per texel"
    )
    return out


def _nearest_roughness(curve: list[dict] | None, rms_obs: float) -> float | None:
    """rho of the calibration point whose RMS is nearest the file's (in log)."""
    if not curve:
        return None
    near = min(curve, key=lambda c: abs(math.log(max(c["rms"], 1e-300)) - math.log(max(rms_obs, 1e-300))))
    return near["roughness"]


@dataclass
class Chosen:
    """The chosen combination at the subset: its candidate, encoding, the decoded re-ordered file (``data``), the
    prediction (``prediction``; before the channel mistake: ``points_prediction``) and the points' positions."""

    candidate: Candidate
    encoding: Encoding
    data: np.ndarray
    prediction: np.ndarray
    points_prediction: np.ndarray
    positions: Positions


def declared_encoding(conv_args: dict | None, lut: LutFile) -> tuple[Encoding, str]:
    """The storage encoding of the preset's engine table (lutbake.layouts.base.EngineTable.encoding) when this file's
    storage can hold it (RGBD: four 8-bit channels), else ``plain``; and the words for the conventions line."""
    from ..layouts import TABLES

    preset = (conv_args or {}).get("preset")
    name = next((t.encoding for t in TABLES if preset and t.preset == preset), "plain")
    enc = ENCODINGS[name]
    if enc.applies(lut.data, lut.storage):
        return enc, f"storage {name}"
    return ENCODINGS["plain"], (
        f"storage plain (the engine ships {name}, which a {lut.storage} file of {lut.data.shape[-1]} channel(s) "
        "does not hold)"
    )


def _diagnosis(nominal: Candidate, chosen: Candidate, cands: list[Candidate], why: str, rho, rounding: float) -> list:
    out = []
    if chosen is not nominal:
        out.append(
            f"convention mismatch: {chosen.label} ({chosen.name}: {chosen.description}): RMS {nominal.rms:.3g} -> "
            f"{chosen.rms:.3g}, max {nominal.max:.3g} -> {chosen.max:.3g}"
        )
    elif why != "smooth":
        alt = next(c for c in cands if c is not nominal)
        out.append(
            f"the declared conventions fit: no combination of the usual mistakes explains the data better by "
            f"{1 / MISMATCH_RATIO:g}x (nominal RMS {nominal.rms:.3g}; best alternative {alt.name}, {alt.rms:.3g})"
        )
    if why == "smooth":
        out.append(
            f"no hypothesis explains the data: the best, {chosen.label}, leaves RMS {chosen.rms:.3g} (declared "
            f"conventions {nominal.rms:.3g}) as a smooth residual (Laplacian energy share {rho:.2g} < "
            f"{NOISE_ROUGHNESS_MIN:g}): neither sampling noise nor the storage rounding (RMS {rounding:.2g}) -- a "
            "model, term or convention the audit does not try"
        )
    elif why == "unknown":
        out.append("too few texels (under 3 x 3) to tell sampling noise from a systematic residual")
    return out


def audit(
    path,
    conv_args: dict | None = None,
    tolerance: float = 1e-3,
    metric: str = "max",
    max_side: int = MAX_SIDE,
    error_map: Path | None = None,
    shape=None,
    workers: int | None = None,
) -> AuditReport:
    """Audit the LUT at ``path`` against the declared conventions (conv_args {"preset", "config", "overrides"}; with
    neither a preset nor a config, the conventions the file records; see the module docstring)."""
    if metric not in METRICS:
        raise ValueError(f"metric {metric!r}: allowed {', '.join(METRICS)}")
    with reading_for("audit"):  # the read's memory budget counts the audit's work on the values
        recorded, lut = recorded_attributes(path, shape)
        other = dispatch(path, conv_args, tolerance, metric, max_side, error_map, recorded)  # LTC and OpenPBR
        if other is not None:
            return other
        lut = lut or read_lut(path, shape=shape)  # read again only to raise what is wrong with it
    rows, cols, fch = lut.data.shape
    bad = ~np.isfinite(lut.data)
    if bad.any():
        r, c, ch = (int(x) for x in np.argwhere(bad)[0])
        raise ValueError(
            f"{path}: {int(bad.sum())} non-finite values (NaN/Inf), the first at row {r}, column {c}, "
            f"channel {'RGBA'[ch] if ch < 4 else ch}: a LUT must hold finite values"
        )
    conv = conventions(**(conv_args or {}), shape=(rows, cols), recorded=lut.attrs, path=path)
    integ = Reference(conv, workers)
    names = list(conv.record.channels)
    declared, storage_words = declared_encoding(conv_args, lut)
    nch = min(declared.channels(fch), len(names))
    # the sheen layouts keep their value in B only (charlie) or R, G: compare what the layout fills
    compared = [c for c in range(nch) if not names[c].startswith("zero")]
    encodings = [declared] + [
        e
        for e in ENCODINGS.values()
        if e is not declared and e.applies(lut.data, lut.storage) and e.channels(fch) >= nch
    ]
    iy, ix = subset(rows, max_side), subset(cols, max_side)
    ops = channel_ops(conv.record, conv.layout)
    preds, points = {}, {}
    for pts, pos in point_sets(conv):  # the search's one cost: each point set integrated once
        sub = pos.map(lambda a: a[np.ix_(iy, ix)])
        pred = integ.converged(sub.nov.ravel(), sub.alpha.ravel(), sub.rough.ravel())
        points[pts] = (sub, pred.reshape(len(iy), len(ix), -1)[..., :nch])
        for op in ops:
            preds[(pts, op)] = op.apply(points[pts][1])
    t_search = time.perf_counter()
    search = Search(lut.data, lut.storage, iy, ix, compared, nch, encodings, preds)
    cands = search.run()
    t_search = time.perf_counter() - t_search
    nominal = next(c for c in cands if c.mistakes == 0)
    chosen = choose(cands)
    enc_c = declared if chosen.encoding is DECLARED else ENCODINGS[chosen.encoding.name]
    pick = Chosen(
        chosen,
        enc_c,
        search.decoded(enc_c, chosen.order),
        preds[(chosen.points, chosen.channels)],
        points[chosen.points][1],
        points[chosen.points][0],
    )
    quant = detect_quantisation(lut.data[..., [c for c in compared if c < fch]], lut.storage)
    rounding = rms(
        round_trip(pick.prediction, enc_c, lambda v: quantise(v, quant))[..., compared] - pick.prediction[..., compared]
    )
    res = pick.data - pick.prediction
    why, rho, noise = "rounding", None, {"detected": False}
    if at_rounding(res[..., compared], rounding):
        noise["description"] = (
            f"no sampling noise above the storage rounding (residual RMS {chosen.rms:.3g}, rounding alone "
            f"{rounding:.3g}, the reference's own error {EXACT_RMS:g})"
        )
    else:  # noise or a smooth residual: held against the engines' estimator on a grid of the subset
        gy, gx = (np.unique(np.linspace(0, n - 1, min(n, NOISE_SIDE + 1)).round().astype(int)) for n in res.shape[:2])
        curve = _calibration(integ, pick, quant, gy, gx)
        rg = [c for c in compared if c < 2] if curve is not None else compared
        grid_res = res[np.ix_(gy, gx)][..., rg]
        why, rho = explain(grid_res, _nearest_roughness(curve, rms(grid_res)))
        if why == "noise":
            rms_quant = rms(
                round_trip(pick.prediction, enc_c, lambda v: quantise(v, quant))[np.ix_(gy, gx)][..., rg]
                - pick.prediction[np.ix_(gy, gx)][..., rg]
            )
            noise = _noise(curve, rms(grid_res), rms_quant, integ.layout)
        else:
            noise["description"] = f"not estimated: the residual is not noise-like ({why})"
        if curve is not None:
            noise["calibration"] = curve
    diagnosis = _diagnosis(nominal, chosen, cands, why, rho, rounding)
    if quant["kind"] != "float" or declared.name != "plain":
        diagnosis.append(
            f"stored as {quant['description']}" + (f", {declared.label}" if declared.name != "plain" else "")
        )
    if why in ("rounding", "noise"):
        diagnosis.append(noise["description"])
    raw_sub = lut.data[np.ix_(iy, ix)]
    ref_nominal = preds[(nominal.points, nominal.channels)]
    err = search.decoded(declared, nominal.order) - ref_nominal
    y_vals = conv.axes[0].values()[iy]
    x_vals = conv.axes[1].values()[ix]
    errors = {}
    for c in compared:
        s = stats(err[..., c])
        k = np.unravel_index(np.argmax(np.abs(err[..., c])), err[..., c].shape)
        s["where"] = (
            f"row {int(iy[k[0]])} ({conv.axes[0].name} {y_vals[k[0]]:.4g}), column {int(ix[k[1]])} "
            f"({conv.axes[1].name} {x_vals[k[1]]:.4g})"
        )
        errors["RGBA"[c] + " = " + names[c]] = s
    allerr = np.abs(err[..., compared])
    # judged: what exceeds one rounding step of the storage at each stored value (a table that is exactly a
    # converged bake, rounded to its storage, is within half a step plus its bake tolerance)
    step = declared.step(raw_sub, rounding_step(raw_sub, quant))[..., :nch][..., compared]
    beyond = np.clip(allerr - step, 0.0, None)
    value = metric_value(beyond, metric)
    k = np.unravel_index(np.argmax(allerr), allerr.shape)
    raw = {"max": float(allerr.max()), "step_at_max": float(step[k]), "metric": metric_value(allerr, metric)}
    report = AuditReport(
        file=str(path),
        conventions=f"{conv.source} (layout {conv.layout}, {conv.axes[0].name} rows "
        f"{conv.axes[0].texel}/{conv.axes[0].mapping}/{conv.axes[0].order}, "
        f"{conv.axes[1].name} columns {conv.axes[1].texel}/{conv.axes[1].mapping}/"
        f"{conv.axes[1].order}; {storage_words})"
        + "".join(
            f"; plugin {r.family} {r.name!r} from {r.origin} (sha256 {r.plugin.sha256[:12]})" for r in conv.spec.plugins
        ),
        channels=["RGBA"[c] for c in compared],
        evaluated={
            "rows": len(iy),
            "columns": len(ix),
            "file_rows": rows,
            "file_columns": cols,
            "stride": int(max(1, math.ceil(max(rows, cols) / max_side))),
        },
        errors=errors,
        hypotheses=[c.as_dict() for c in listed(cands)],
        diagnosis=diagnosis,
        quantisation=quant,
        noise=noise,
        **verdict(metric, tolerance, value),
        extra={
            "best": cands[0].name,
            "chosen": chosen.name,
            "explained": why,
            "roughness": rho,
            "encoding": declared.name,
            "storage": lut.storage,
            "raw_error": raw,
            "search": {"combinations": len(cands), "seconds": t_search},
        },
    )
    if error_map is not None:
        report.error_map = str(
            write_error_map(
                error_map, err[..., compared], [names[c] for c in compared], conv.axes, iy, ix, Path(path).name
            )
        )
    return report


def report_json(report: AuditReport) -> str:
    return json.dumps(report.as_dict(), indent=1, ensure_ascii=False)
