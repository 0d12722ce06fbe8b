"""``lutbake audit FILE``: compare a shipped LUT with a converged re-bake under declared conventions, and
diagnose the usual hand-over mistakes by testing each one against the data.

The conventions are a ``dfg`` table spec (a preset or config, plus ``--set`` keys; the size is the file's); a
preset or config of kind ``ltc`` or layout ``openpbr`` is audited by lutbake.commands.audit_tables instead.
Every file texel (row y, column x) then has a declared (NoV, alpha) (lutbake.kinds.dfg.axes_for); the
reference is lutbake's Gauss-Legendre integral at those points (error ~4e-7), on a strided subset of at most
``max_side`` x ``max_side`` texels (the last row and column always included).

Hypotheses (each one a prediction of the whole file, compared with the data by RMS over the channels the
declared layout and the file share; the nominal one is the declared conventions):
- positions: rows or columns flipped, axes swapped (square tables), the roughness or NoV axis shifted by
  +-1/2 or +-1 texel (t -> t + s/N before the mapping), the roughness axis read as alpha (alpha = value) or
  squared twice (alpha = value^4) -- each re-integrated at its own points;
- values: sRGB-decoded (file = EOTF(truth), what a linear LUT loaded as sRGB and saved back holds) or
  sRGB-encoded (file = OETF(truth)), R and G swapped, the other split-sum layout (scale/bias <-> multiscatter:
  multiscatter (R, G) = (bias, scale + bias)).
A hypothesis is reported as the diagnosis when its RMS is below MISMATCH_RATIO x the nominal RMS.
Then, with the best conventions:
- quantisation: the smallest UNORM bit depth (8, 10, 12, 16) on whose code grid every value lies, or half
  floats (every value exactly representable); the rounding error it alone explains, q / sqrt(12);
- Monte-Carlo noise: the residual against the converged integral, compared with lutbake's own estimate by
  the engines' usual generator (Hammersley points, NDF importance sampling: Filament cmgen, the glTF IBL
  sampler, UE4) at N = 64 ... 16384 samples, quantised the same way; the N whose residual matches the file's
  (log-log interpolation) is the estimated sample count.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..axes import Axis
from ..edge import NOV_MIN
from ..io.bounded import reading_for
from ..io.lut_files import LutFile, read_lut
from .audit_report import (
    METRICS,
    MISMATCH_RATIO,
    PERCENTILES,
    metric_value,
    stats,
    subset,
    verdict,
    write_error_map,
)
from .audit_tables import dispatch
from .reference import Conventions, Reference, conventions

MAX_SIDE = 128  # default subset: at most this many rows and columns are re-integrated
QUANT_TOL = 1e-3  # a value is on a UNORM code grid when |v (2^b - 1) - round| <= this (in codes)
UNORM_BITS = (8, 10, 12, 16)
NOISE_SAMPLES = (64, 256, 1024, 4096, 16384)  # the calibration bakes of the noise estimate
NOISE_TEXELS = 1024  # texels of the subset used for the noise calibration (fixed, evenly spread)
NOISE_FLOOR_RATIO = 1.5  # noise is reported when the residual exceeds this x what the quantisation explains


def srgb_eotf(v):
    """sRGB decoding (IEC 61966-2-1): what a sampler returns for a texture stored as sRGB."""
    v = np.clip(v, 0.0, None)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def srgb_oetf(v):
    """sRGB encoding (IEC 61966-2-1), the inverse of srgb_eotf."""
    v = np.clip(v, 0.0, None)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)


def other_layout(pred: np.ndarray, split_sum: str | None) -> np.ndarray:
    """The same table written in the other split-sum layout (channels R, G; a third channel is kept); ``split_sum``:
    the declared layout's pair (lutbake.layouts.base.Layout.split_sum)."""
    out = pred.copy()
    r, g = pred[..., 0], pred[..., 1]
    if split_sum == "multiscatter":  # (Fc, E) -> (scale, bias) = (E - Fc, Fc)
        out[..., 0], out[..., 1] = g - r, r
    else:  # (scale, bias) -> (Fc, E) = (bias, scale + bias)
        out[..., 0], out[..., 1] = g, r + g
    return out


@dataclass
class Positions:
    """Per-texel (NoV, alpha, perceptual roughness) of a file-sized grid: rows x columns."""

    nov: np.ndarray
    alpha: np.ndarray
    rough: np.ndarray  # perceptual roughness before the alpha floor (the Disney diffuse channel's parameter)

    def map(self, fn) -> Positions:
        """The same index operation (flip, transpose, subset) applied to every field."""
        return Positions(fn(self.nov), fn(self.alpha), fn(self.rough))


@dataclass
class Hypothesis:
    name: str
    description: str
    positions: Positions
    transform: object = None  # values: callable(pred) -> pred, or None
    rms: float = math.nan
    max: float = math.nan


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


def hypotheses(conv: Conventions) -> list[Hypothesis]:
    nominal = positions(conv)
    rname = next(a.name for a in conv.axes if a.name != "NoV")
    declared_power = 2.0 if rname == "perceptual_roughness" else 1.0
    hs = [Hypothesis("nominal", f"the declared conventions ({conv.source})", nominal)]
    row_axis = conv.axes[0].name
    hs.append(
        Hypothesis(
            "rows_flipped",
            f"rows in reverse order (the {row_axis} axis flipped: row 0 at the other end)",
            nominal.map(lambda a: a[::-1]),
        )
    )
    hs.append(
        Hypothesis(
            "columns_flipped",
            f"columns in reverse order (the {conv.axes[1].name} axis flipped)",
            nominal.map(lambda a: a[:, ::-1]),
        )
    )
    if nominal.nov.shape[0] == nominal.nov.shape[1]:
        hs.append(
            Hypothesis(
                "axes_swapped", "rows and columns swapped (NoV and roughness exchanged)", nominal.map(lambda a: a.T)
            )
        )
    for axis, key in (("roughness", "shift_rough"), ("NoV", "shift_nov")):
        for s in (-1.0, -0.5, 0.5, 1.0):
            what = "one texel" if abs(s) == 1 else "half a texel"
            toward = "toward t = 1 (rougher)" if axis == "roughness" else "toward t = 1 (larger NoV)"
            if s < 0:
                toward = toward.replace("t = 1", "t = 0").replace("rougher", "smoother").replace("larger", "smaller")
            hs.append(
                Hypothesis(
                    f"{axis.lower()}_offset_{s:+g}",
                    f"the {axis} axis offset by {what} {toward}: every texel holds t {s:+g}/N",
                    positions(conv, **{key: s}),
                )
            )
    if declared_power == 2.0:
        hs.append(
            Hypothesis(
                "roughness_is_alpha",
                "the roughness axis holds alpha (alpha = t), not perceptual roughness (alpha = t^2)",
                positions(conv, alpha_power=1.0),
            )
        )
        hs.append(
            Hypothesis(
                "roughness_squared_twice",
                "alpha = t^4: perceptual roughness squared twice",
                positions(conv, alpha_power=4.0),
            )
        )
    else:
        hs.append(
            Hypothesis(
                "roughness_is_perceptual",
                "the roughness axis holds perceptual roughness (alpha = t^2), not alpha",
                positions(conv, alpha_power=2.0),
            )
        )
    hs.append(
        Hypothesis(
            "srgb_decoded",
            "values sRGB-decoded (file = sRGB EOTF(truth): a linear LUT read or converted as sRGB)",
            nominal,
            srgb_eotf,
        )
    )
    hs.append(Hypothesis("srgb_encoded", "values sRGB-encoded (file = sRGB OETF(truth))", nominal, srgb_oetf))
    hs.append(
        Hypothesis(
            "channels_swapped",
            "R and G swapped",
            nominal,
            lambda p: np.concatenate([p[..., 1:2], p[..., 0:1], p[..., 2:]], axis=-1),
        )
    )
    if "other_split_sum" not in conv.record.audit:
        return hs
    other = "scale_bias" if conv.record.split_sum == "multiscatter" else "multiscatter"
    hs.append(
        Hypothesis(
            "layout_" + other,
            f"the file is in the {other} layout, declared {conv.layout} (multiscatter (R, G) = (bias, scale + bias))",
            nominal,
            lambda p: other_layout(p, conv.record.split_sum),
        )
    )
    return hs


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


def _noise_estimate(integ: Reference, pos_sub: Positions, data: np.ndarray, ref: np.ndarray, quant: dict) -> dict:
    """Estimated Monte-Carlo sample count of the file's generator (see the module docstring)."""
    flat = np.arange(pos_sub.nov.size)
    pick = flat[np.linspace(0, flat.size - 1, min(NOISE_TEXELS, flat.size)).round().astype(int)]
    nov, alpha = pos_sub.nov.ravel()[pick], pos_sub.alpha.ravel()[pick]
    ref2 = ref.reshape(-1, ref.shape[-1])[pick, :2]
    obs = data.reshape(-1, data.shape[-1])[pick, :2]
    rms_obs = float(np.sqrt(np.mean((obs - ref2) ** 2)))
    rms_quant = float(np.sqrt(np.mean((quantise(ref2, quant) - ref2) ** 2)))
    out = {"rms_residual": rms_obs, "rms_quantisation_alone": rms_quant, "texels": int(len(pick))}
    if rms_obs <= max(NOISE_FLOOR_RATIO * rms_quant, 1e-6):
        out.update(
            detected=False,
            samples=None,
            description=f"no sampling noise above the storage rounding (residual RMS {rms_obs:.3g}, rounding "
            f"alone {rms_quant:.3g})",
        )
        return out
    curve = []
    for n in NOISE_SAMPLES:
        est = integ.hammersley(nov, alpha, n)
        if est is None:
            out.update(
                detected=True,
                samples=None,
                description=f"residual RMS {rms_obs:.3g} above the rounding "
                f"({rms_quant:.3g}); no sample-count calibration for layout {integ.layout}",
            )
            return out
        curve.append((n, float(np.sqrt(np.mean((quantise(est, quant) - ref2) ** 2)))))
    out["calibration"] = [{"samples": n, "rms": e} for n, e in curve]
    ns, es = np.log([c[0] for c in curve]), np.log([c[1] for c in curve])
    order = np.argsort(es)  # np.interp needs increasing x: the error falls with N
    if rms_obs >= curve[0][1]:
        n_est, bound = None, f"<= {curve[0][0]}"
    elif rms_obs <= curve[-1][1]:
        n_est, bound = None, f">= {curve[-1][0]}"
    else:
        n_est = float(np.exp(np.interp(np.log(rms_obs), es[order], ns[order])))
        bound = f"~{n_est:.0f}"
    out.update(
        detected=True,
        samples=n_est,
        samples_bound=bound,
        description=f"Monte-Carlo noise: residual RMS {rms_obs:.3g} vs {rms_quant:.3g} from rounding alone; "
        f"matches a Hammersley NDF-sampled estimate with {bound} samples per texel",
    )
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
    nch = min(fch, len(names))
    # the sheen layouts keep their value in B only (charlie) or R, G: compare what the layout fills
    compared = [c for c in range(nch) if not names[c].startswith("zero")]
    iy, ix = subset(rows, max_side), subset(cols, max_side)
    data = lut.data[np.ix_(iy, ix)][..., :nch]
    hs = hypotheses(conv)
    preds = {}
    for h in hs:
        sub = h.positions.map(lambda a: a[np.ix_(iy, ix)])
        pred = integ.converged(sub.nov.ravel(), sub.alpha.ravel(), sub.rough.ravel()).reshape(len(iy), len(ix), -1)[
            ..., :nch
        ]
        if h.transform is not None:
            pred = h.transform(pred)
        d = (data - pred)[..., compared]
        h.rms, h.max = float(np.sqrt(np.mean(d**2))), float(np.max(np.abs(d)))
        preds[h.name] = (pred, sub)
    nominal = hs[0]
    best = min(hs, key=lambda h: h.rms)
    diagnosis = []
    if best is not nominal and best.rms < MISMATCH_RATIO * nominal.rms:
        diagnosis.append(
            f"convention mismatch: {best.name}: {best.description} (RMS {nominal.rms:.3g} -> "
            f"{best.rms:.3g}, max {nominal.max:.3g} -> {best.max:.3g})"
        )
        chosen = best
    else:
        alt = min((h for h in hs if h is not nominal), key=lambda h: h.rms)
        diagnosis.append(
            f"the declared conventions fit: no alternative explains the data better by {1 / MISMATCH_RATIO:g}x "
            f"(nominal RMS {nominal.rms:.3g}; best alternative {alt.name}, {alt.rms:.3g})"
        )
        chosen = nominal
    quant = detect_quantisation(lut.data[..., [c for c in compared if c < fch]], lut.storage)
    ref_nominal, sub_nominal = preds["nominal"]
    pred_c, sub_c = preds[chosen.name]
    noise = {"detected": False, "description": "not estimated (values were transformed)"}
    if chosen.transform is None:
        noise = _noise_estimate(integ, sub_c, data, pred_c, quant)
    if quant["kind"] != "float":
        diagnosis.append(f"stored as {quant['description']}")
    diagnosis.append(noise["description"])
    err = data - ref_nominal
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
    step = rounding_step(data[..., compared], quant)
    beyond = np.clip(allerr - step, 0.0, None)
    value = metric_value(beyond, metric)
    k = np.unravel_index(np.argmax(allerr), allerr.shape)
    raw = {"max": float(allerr.max()), "step_at_max": float(step[k]), "metric": metric_value(allerr, metric)}
    report = AuditReport(
        file=str(path),
        conventions=f"{conv.source} (layout {conv.layout}, {conv.axes[0].name} rows "
        f"{conv.axes[0].texel}/{conv.axes[0].mapping}/{conv.axes[0].order}, "
        f"{conv.axes[1].name} columns {conv.axes[1].texel}/{conv.axes[1].mapping}/"
        f"{conv.axes[1].order})",
        channels=["RGBA"[c] for c in compared],
        evaluated={
            "rows": len(iy),
            "columns": len(ix),
            "file_rows": rows,
            "file_columns": cols,
            "stride": int(max(1, math.ceil(max(rows, cols) / max_side))),
        },
        errors=errors,
        hypotheses=[{"name": h.name, "description": h.description, "rms": h.rms, "max": h.max} for h in hs],
        diagnosis=diagnosis,
        quantisation=quant,
        noise=noise,
        **verdict(metric, tolerance, value),
        extra={"best": best.name, "chosen": chosen.name, "storage": lut.storage, "raw_error": raw},
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
