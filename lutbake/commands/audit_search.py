"""The hypothesis search of ``lutbake audit``: the usual hand-over mistakes as four composable factors, tried as one
product space, ranked by residual.

A shipped file is modelled as the declared table after up to four independent mistakes, in this order:
1. **points** (lutbake.commands.audit.point_sets): where each texel's (NoV, alpha) lies -- an axis offset by +-1/2 or
   +-1 texel, the roughness axis read as alpha or squared twice. Each point set is integrated once, at the subset's
   texels: the only cost of the search.
2. **channels** (``channel_ops``): R and G swapped, the other split-sum layout -- a numpy map of a prediction.
3. **order** (``ORDERS``): rows or columns reversed, the axes exchanged and their compositions (the eight symmetries
   of a square table, four of another) -- undone on the file's full array (a view), then the subset taken.
4. **encoding** (``ENCODINGS``): how the file stores a value (UNORM or float as read, sRGB, Babylon's RGBD, PlayCanvas'
   RGBM, half-float bits in 16-bit codes) -- undone by decoding the file, once per encoding.
Every combination predicts the decoded, re-ordered file at the subset; its RMS over the compared channels (decoded
values, so every combination is measured in the same units) ranks it. A combination of k mistakes is the diagnosis
only when it beats the best of fewer mistakes by MISMATCH_RATIO (``choose``): an extra factor must explain something.

Whether the chosen combination *explains* the data is a separate question, asked of its residual (``explain``):
- ``rounding``: the residual RMS is within NOISE_FLOOR_RATIO of what the storage's rounding alone leaves (the
  converged table encoded, rounded to the file's codes and decoded), or below EXACT_RMS;
- ``noise``: the residual is as rough, texel to texel, as sampling noise. The statistic is the share of the
  residual's energy its 5-point Laplacian keeps, rho = E[lap^2] / (20 E[r^2]): white noise (independent estimates,
  rounding) gives 1, a smooth field of wavenumber k on texel spacing h ~(k h)^4. The error of an estimator that reuses
  one point set at every texel (Hammersley, as cmgen) is itself smooth at a fine spacing (rho 0.012 for Filament's
  table at every texel of 128², 0.37 at every 8th), so the file's rho is held against that of the engines' estimator
  (lutbake.commands.reference.Reference.hammersley) of the nearest RMS on the same texels, stored the same way:
  noise when at least NOISE_ROUGHNESS_RATIO of it (measured ratios: the shipped tables of tests/data 0.75 - 1.9,
  Filament's 1.0 at every texel of 128²; smooth random fields of up to three periods 0.003 on 32², 0.02 on the
  33 x 33 calibration grid of 128²). A layout no estimator calibrates: rho >=
  NOISE_ROUGHNESS_MIN (a 64-sample Hammersley table 0.03 at 32², smooth fields below 6e-4);
- ``smooth``: neither -- no hypothesis explains the data.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..io.encodings import srgb_eotf, srgb_oetf
from .audit_report import MISMATCH_RATIO  # a combination must leave at most this x the RMS of one with fewer mistakes

EXACT_RMS = 1e-6  # a residual below this is the reference's own convergence (lutbake.commands.reference: 1e-7)
NOISE_FLOOR_RATIO = 1.5  # a residual within this x the storage's rounding RMS is that rounding alone
NOISE_ROUGHNESS_RATIO = 0.1  # noise is at least this x as rough as the engines' estimator's error of its RMS
NOISE_ROUGHNESS_MIN = 0.01  # ... and, for a layout no estimator calibrates, rho >= this (module docstring)
WHITE_LAPLACIAN = 20.0  # E[lap^2] / E[r^2] of white noise under the 5-point Laplacian (4^2 + 4 x 1)
LISTED_COMBINATIONS = 10  # combinations of several mistakes kept in the report (every single mistake is)
RGBD_RANGE = 255.0  # Babylon's rgbdMaxRange (Shaders/ShadersInclude/helperFunctions toRGBD)
BABYLON_GAMMA = 2.2  # Babylon's toLinearSpace = pow(x, 2.2) (ToLinearSpace, Maths/math.constants)
RGBM_RANGE = 8.0  # PlayCanvas decodeRGBM: ((8 a) rgb)^2 (src/scene/shader-lib/chunks/common/frag/decode.js)
CODE8 = 255.0


def _gamma(v):
    return np.clip(v, 0.0, None) ** BABYLON_GAMMA


def _degamma(v):
    return np.clip(v, 0.0, None) ** (1.0 / BABYLON_GAMMA)


def _rgb3(v: np.ndarray) -> np.ndarray:
    """The first three channels of ``v``, zero-padded (a two-channel prediction packed into RGB + D or M)."""
    pad = max(0, 3 - v.shape[-1])
    return np.concatenate([v[..., :3], np.zeros(v.shape[:-1] + (pad,))], axis=-1)


def rgbd_decode(stored: np.ndarray, to_linear=_gamma) -> np.ndarray:
    """Babylon's fromRGBD (Shaders/ShadersInclude/helperFunctions): rgb = toLinearSpace(png.rgb) / png.a."""
    return to_linear(stored[..., :3]) / stored[..., 3:4]


def rgbd_encode(v: np.ndarray, to_gamma=_degamma) -> np.ndarray:
    """Babylon's toRGBD: D = clamp(floor(max(255 / max(rgb), 1)) / 255, 0, 1), png = (toGammaSpace(rgb D), D)."""
    rgb = _rgb3(v)
    top = np.maximum(rgb.max(axis=-1, keepdims=True), 1e-300)
    d = np.clip(np.floor(np.maximum(RGBD_RANGE / top, 1.0)) / CODE8, 0.0, 1.0)
    return np.concatenate([np.clip(to_gamma(rgb * d), 0.0, 1.0), d], axis=-1)


def rgbm_decode(stored: np.ndarray) -> np.ndarray:
    """PlayCanvas' decodeRGBM: ((8 a) rgb)^2 (values up to 64, stored with gamma 2)."""
    return (RGBM_RANGE * stored[..., 3:4] * stored[..., :3]) ** 2


def rgbm_encode(v: np.ndarray) -> np.ndarray:
    """PlayCanvas' encodeRGBM: c = sqrt(rgb) / 8, a = ceil(clamp(max(c), 1/255, 1) 255) / 255, png = (c / a, a)."""
    c = np.sqrt(np.clip(_rgb3(v), 0.0, None)) / RGBM_RANGE
    a = np.ceil(np.clip(c.max(axis=-1, keepdims=True), 1 / CODE8, 1.0) * CODE8) / CODE8
    return np.concatenate([np.clip(c / a, 0.0, 1.0), a], axis=-1)


def half_bits_decode(stored: np.ndarray) -> np.ndarray:
    """16-bit UNORM codes that are IEEE half floats (a half texture saved as a 16-bit PNG)."""
    return np.round(stored * 65535.0).astype(np.uint16).view(np.float16).astype(np.float64)


def half_bits_encode(v: np.ndarray) -> np.ndarray:
    return np.asarray(v, np.float16).view(np.uint16).astype(np.float64) / 65535.0


@dataclass(frozen=True)
class Encoding:
    """How a file stores a value: ``decode`` (the file's values as read -> values), ``encode`` (its inverse, to model
    the rounding), ``packed`` (RGB + a shared fourth channel: three values from four stored), ``storages`` (the file
    storages it applies to, by prefix; () any)."""

    name: str
    label: str
    description: str
    decode: Callable
    encode: Callable
    packed: bool = False
    storages: tuple[str, ...] = ()

    def applies(self, data: np.ndarray, storage: str) -> bool:
        if self.storages and not storage.startswith(self.storages):
            return False
        return not self.packed or (data.shape[-1] == 4 and bool(np.all(data[..., 3] > 0)))

    def channels(self, stored: int) -> int:
        return 3 if self.packed else stored

    def step(self, raw: np.ndarray, raw_step: np.ndarray) -> np.ndarray:
        """The value change of one rounding step of each stored channel (``raw_step`` at ``raw``), per decoded
        channel: a file that is a converged table, rounded to its storage, is within it."""
        base = self.decode(raw)
        out = np.empty_like(base)
        for k in range(base.shape[-1]):
            bumped = raw.copy()
            bumped[..., k] += raw_step[..., k]
            out[..., k] = np.abs(self.decode(bumped)[..., k] - base[..., k])
        return out


def _identity(v):
    return v


ENCODINGS = {
    e.name: e
    for e in (
        Encoding(
            "plain", "values as stored", "values as stored (UNORM code / (2^b - 1), or the float)", _identity, _identity
        ),
        Encoding("srgb_encoded", "sRGB-encoded", "values sRGB-encoded (file = sRGB OETF(truth))", srgb_eotf, srgb_oetf),
        Encoding(
            "srgb_decoded",
            "sRGB-decoded",
            "values sRGB-decoded (file = sRGB EOTF(truth): a linear LUT read or converted as sRGB)",
            srgb_oetf,
            srgb_eotf,
        ),
        Encoding(
            "rgbd",
            "RGBD-packed",
            "RGBD-packed (Babylon.js: value = toLinearSpace(rgb) / a, toLinearSpace = x^2.2)",
            rgbd_decode,
            rgbd_encode,
            packed=True,
            storages=("unorm",),
        ),
        Encoding(
            "rgbd_srgb",
            "RGBD-packed (exact sRGB)",
            "RGBD-packed with the exact sRGB curve (Babylon.js USE_EXACT_SRGB_CONVERSIONS: value = EOTF(rgb) / a)",
            lambda s: rgbd_decode(s, srgb_eotf),
            lambda v: rgbd_encode(v, srgb_oetf),
            packed=True,
            storages=("unorm",),
        ),
        Encoding(
            "rgbm",
            "RGBM-packed",
            "RGBM-packed (PlayCanvas: value = (8 a rgb)^2)",
            rgbm_decode,
            rgbm_encode,
            packed=True,
            storages=("unorm",),
        ),
        Encoding(
            "half_bits",
            "half floats in 16-bit codes",
            "16-bit codes holding IEEE half-float bit patterns (a half texture saved as 16-bit UNORM)",
            half_bits_decode,
            half_bits_encode,
            storages=("unorm16",),
        ),
    )
}


@dataclass(frozen=True)
class Factor:
    """One choice of one factor: ``name`` ("" for the declared choice), ``label`` (short, for the diagnosis),
    ``description``, ``mistakes`` (how many mistakes it stands for)."""

    name: str
    label: str
    description: str
    mistakes: int = 1


DECLARED = Factor("", "", "as declared", 0)


@dataclass(frozen=True)
class Order(Factor):
    """A texel order: ``undo`` maps the file's full (rows, columns, C) array to the declared order."""

    undo: Callable = _identity
    square_only: bool = False


def _transposed(a):
    return a.transpose(1, 0, 2)


ORDERS = (
    Order("", "", "as declared", 0),
    Order("rows_flipped", "rows flipped", "rows in reverse order (row 0 at the other end)", 1, lambda a: a[::-1]),
    Order("columns_flipped", "columns flipped", "columns in reverse order", 1, lambda a: a[:, ::-1]),
    Order(
        "rows_columns_flipped",
        "rows and columns flipped",
        "rows and columns in reverse order (turned 180 degrees)",
        2,
        lambda a: a[::-1, ::-1],
    ),
    Order(
        "axes_swapped", "axes swapped", "rows and columns swapped (NoV and roughness exchanged)", 1, _transposed, True
    ),
    Order(
        "axes_swapped+rows_flipped",
        "axes swapped + rows flipped",
        "axes swapped, then the rows reversed",
        2,
        lambda a: _transposed(a[::-1]),
        True,
    ),
    Order(
        "axes_swapped+columns_flipped",
        "axes swapped + columns flipped",
        "axes swapped, then the columns reversed",
        2,
        lambda a: _transposed(a[:, ::-1]),
        True,
    ),
    Order(
        "axes_swapped+rows_columns_flipped",
        "axes swapped + rows and columns flipped",
        "axes swapped, then rows and columns reversed",
        3,
        lambda a: _transposed(a[::-1, ::-1]),
        True,
    ),
)


@dataclass(frozen=True)
class ChannelOp(Factor):
    """A channel mistake: ``apply`` maps a prediction (.., C) to what the file holds."""

    apply: Callable = _identity


def _swap_rg(p):
    return np.concatenate([p[..., 1:2], p[..., 0:1], p[..., 2:]], axis=-1)


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


def channel_ops(record, layout: str) -> list[ChannelOp]:
    """The channel mistakes the declared layout's record allows (lutbake.layouts.base.Layout.audit)."""
    ops = [
        ChannelOp("", "", "as declared", 0),
        ChannelOp("channels_swapped", "R and G swapped", "R and G swapped", 1, _swap_rg),
    ]
    if "other_split_sum" in record.audit:
        other = "scale_bias" if record.split_sum == "multiscatter" else "multiscatter"
        ops.append(
            ChannelOp(
                "layout_" + other,
                f"{other} layout",
                f"the file is in the {other} layout, declared {layout} (multiscatter (R, G) = (bias, scale + bias))",
                1,
                lambda p: other_layout(p, record.split_sum),
            )
        )
    return ops


@dataclass
class Candidate:
    """One combination of the four factors and its residual (RMS, max |.| over the compared channels)."""

    points: Factor
    channels: ChannelOp
    order: Order
    encoding: Factor
    rms: float
    max: float

    @property
    def factors(self) -> tuple[Factor, ...]:
        return (self.points, self.channels, self.order, self.encoding)

    @property
    def mistakes(self) -> int:
        return sum(f.mistakes for f in self.factors)

    @property
    def name(self) -> str:
        return "+".join(f.name for f in self.factors if f.mistakes) or "nominal"

    @property
    def label(self) -> str:
        return " + ".join(f.label for f in self.factors if f.mistakes) or "the declared conventions"

    @property
    def description(self) -> str:
        return "; ".join(f.description for f in self.factors if f.mistakes) or "the declared conventions"

    def as_dict(self) -> dict:
        keys = ("name", "label", "description", "mistakes", "rms", "max")
        return {k: getattr(self, k) for k in keys}


@dataclass
class Search:
    """The search's inputs, prepared once: the file's decodings, the predictions of every point set x channel op."""

    raw: np.ndarray  # the file's full array as read (rows, columns, C)
    storage: str
    iy: np.ndarray
    ix: np.ndarray
    compared: list[int]
    nch: int
    encodings: list[Encoding]  # declared first
    predictions: dict  # (points Factor, ChannelOp) -> (ny, nx, nch) prediction

    def decoded(self, enc: Encoding, order: Order) -> np.ndarray:
        """The file decoded by ``enc``, put in the declared order by ``order``, at the subset: (ny, nx, nch)."""
        return order.undo(enc.decode(self.raw))[np.ix_(self.iy, self.ix)][..., : self.nch]

    def run(self) -> list[Candidate]:
        """Every combination, best first."""
        keys = list(self.predictions)
        stack = np.stack([self.predictions[k][..., self.compared] for k in keys])  # (K, ny, nx, nc)
        square = self.raw.shape[0] == self.raw.shape[1]
        out = []
        for enc in self.encodings:
            full = enc.decode(self.raw)
            if not np.all(np.isfinite(full)):
                continue  # e.g. half bits that are NaN or Inf: not this file's encoding
            enc_factor = DECLARED if enc is self.encodings[0] else Factor(enc.name, enc.label, enc.description)
            for order in ORDERS:
                if order.square_only and not square:
                    continue
                d = order.undo(full)[np.ix_(self.iy, self.ix)][..., self.compared]
                diff = stack - d[None]
                rms = np.sqrt(np.mean(diff**2, axis=(1, 2, 3)))
                mx = np.max(np.abs(diff), axis=(1, 2, 3))
                for (pts, op), r, m in zip(keys, rms, mx):
                    out.append(Candidate(pts, op, order, enc_factor, float(r), float(m)))
        return sorted(out, key=lambda c: c.rms)


def choose(cands: list[Candidate]) -> Candidate:
    """The diagnosis: from the declared conventions, a combination of more mistakes replaces the current one when its
    RMS is below MISMATCH_RATIO x the current RMS (fewest mistakes first)."""
    chosen = next(c for c in cands if c.mistakes == 0)
    for k in sorted({c.mistakes for c in cands} - {0}):
        best = min((c for c in cands if c.mistakes == k), key=lambda c: c.rms)
        if best.rms < MISMATCH_RATIO * chosen.rms:
            chosen = best
    return chosen


def listed(cands: list[Candidate]) -> list[Candidate]:
    """The report's hypotheses: the declared conventions first, then every single mistake and the best few
    combinations, each best first."""
    singles = [c for c in cands if c.mistakes == 1]
    return [c for c in cands if c.mistakes == 0] + singles + [c for c in cands if c.mistakes > 1][:LISTED_COMBINATIONS]


def roughness(res: np.ndarray) -> float | None:
    """rho of the module docstring: the share of the residual's energy its 5-point Laplacian keeps (white noise 1);
    ``res`` (ny, nx, C); None on a subset under 3 x 3 or a zero residual."""
    if res.shape[0] < 3 or res.shape[1] < 3:
        return None
    inner = res[1:-1, 1:-1]
    lap = 4 * inner - res[2:, 1:-1] - res[:-2, 1:-1] - res[1:-1, 2:] - res[1:-1, :-2]
    energy = float(np.mean(inner**2))
    return float(np.mean(lap**2)) / (WHITE_LAPLACIAN * energy) if energy > 0 else None


def at_rounding(res: np.ndarray, rounding_rms: float) -> bool:
    """The residual is the storage's rounding alone (or the reference's own error)."""
    return rms(res) <= max(NOISE_FLOOR_RATIO * rounding_rms, EXACT_RMS)


def explain(res: np.ndarray, reference_rho: float | None) -> tuple[str, float | None]:
    """("noise" | "smooth" | "unknown", rho) of a residual above the rounding: noise when it is at least
    NOISE_ROUGHNESS_RATIO x as rough as the engines' estimator's error of the same RMS on the same texels
    (``reference_rho``), or, where no estimator calibrates the layout, when rho >= NOISE_ROUGHNESS_MIN."""
    rho = roughness(res)
    if rho is None:
        return "unknown", None
    need = NOISE_ROUGHNESS_MIN if reference_rho is None else NOISE_ROUGHNESS_RATIO * reference_rho
    return ("noise" if rho >= need else "smooth"), rho


def round_trip(values: np.ndarray, enc: Encoding, quantise: Callable) -> np.ndarray:
    """``values`` (.., C) encoded as ``enc``, rounded to the file's storage (``quantise``) and decoded: what a
    converged table becomes in this file's storage."""
    return enc.decode(quantise(enc.encode(values)))[..., : values.shape[-1]]


def rms(a: np.ndarray) -> float:
    return float(math.sqrt(np.mean(np.square(a)))) if a.size else 0.0
