"""``lutbake size``: the smallest table resolution per storage format that meets a max error *after the
shader's bilinear filtering*.

For a square N x N ``dfg`` table under the declared conventions (a preset or config, ``--set`` keys):
1. the integral is evaluated (Gauss-Legendre, ~4e-7) on the (2N - 1)^2 grid of fractional texel indices
   x, y in {0, 1/2, 1, ..., N - 1}: the texel centres (even points: the table) and the points between them
   (odd: edge midpoints between two centres and cell centres between four), each at the parameter the axis
   convention gives that fractional index (lutbake.axes: texel, mapping, order; the same uv a shader uses);
2. the table is stored in each format (UNORM8/10/16: round(v (2^b - 1)) / (2^b - 1), values clipped to [0, 1];
   F16: IEEE half; F32: float32) and bilinearly filtered at every point, as the GPU does in exact arithmetic;
3. the error is max |filtered - integral| over the points and channels. For a smooth integrand the bilinear
   error peaks between texels (it vanishes at the centres), so the odd points carry the interpolation error,
   the even ones the storage rounding.
Not measured: the clamp-to-edge band outside the outermost texel centres (NoV < 0.5/N, r < 0.5/N with
centre texels), which no resolution removes (it shrinks as 1/N), and the GPU's own fixed-point filter weights
(8 fractional bits on many GPUs: at most 1/512 of a texel-to-texel step).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..axes import Axis
from ..edge import NOV_MIN
from .audit import Conventions, Integrator, conventions

STORAGE = {
    "unorm8": "8-bit UNORM (R8G8)",
    "unorm10": "10-bit UNORM (A2R10G10B10)",
    "unorm16": "16-bit UNORM (R16G16)",
    "f16": "half float (R16G16_FLOAT)",
    "f32": "float (R32G32_FLOAT)",
}
SIZES = (8, 16, 32, 64, 128, 256, 512)


def store(values: np.ndarray, fmt: str) -> np.ndarray:
    """``values`` as the GPU reads them back from a texture of format ``fmt`` (STORAGE)."""
    if fmt.startswith("unorm"):
        m = float((1 << int(fmt[5:])) - 1)
        return np.round(np.clip(values, 0.0, 1.0) * m) / m
    if fmt == "f16":
        return values.astype(np.float16).astype(np.float64)
    if fmt == "f32":
        return values.astype(np.float32).astype(np.float64)
    raise ValueError(f"storage format {fmt!r}: allowed {', '.join(STORAGE)}")


def axis_at(axis: Axis, x: np.ndarray) -> np.ndarray:
    """The axis' parameter at fractional texel index ``x`` (the value bilinear filtering at that index
    should reconstruct), after the edge policy."""
    n = axis.count
    i = (n - 1) - x if axis.order == "hi_first" else x
    t = (i + 0.5) / n if axis.texel == "center" else i / max(n - 1, 1)
    return axis._map(np.clip(t, 0.0, 1.0))


def half_grid(conv: Conventions) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(NoV, alpha, perceptual roughness) on the (2H - 1) x (2W - 1) grid of half-integer texel indices."""
    y_axis, x_axis = conv.axes
    vals = {a.name: axis_at(a, np.arange(2 * a.count - 1) / 2.0) for a in (y_axis, x_axis)}
    rname = next(n for n in vals if n != "NoV")
    a = np.clip(vals[rname] ** (2.0 if rname == "perceptual_roughness" else 1.0), 0.0, None)
    alpha_1d, rough_1d = a, np.sqrt(a)  # the integrand applies the alpha -> 0 policy (lutbake.edge)
    nov_1d = np.maximum(vals["NoV"], NOV_MIN)
    if x_axis.name == "NoV":
        nov, alpha = np.meshgrid(nov_1d, alpha_1d)
        return nov, alpha, np.meshgrid(nov_1d, rough_1d)[1]
    alpha, nov = np.meshgrid(alpha_1d, nov_1d)
    return nov, alpha, np.meshgrid(rough_1d, nov_1d)[0]


def bilinear_half(table: np.ndarray) -> np.ndarray:
    """Bilinear filtering of an (H, W, C) table at every half-integer index: (2H - 1, 2W - 1, C)."""
    h, w, c = table.shape
    out = np.empty((2 * h - 1, 2 * w - 1, c))
    out[::2, ::2] = table
    out[1::2, ::2] = 0.5 * (table[:-1] + table[1:])
    out[:, 1::2] = 0.5 * (out[:, :-1:2] + out[:, 2::2])
    return out


@dataclass
class SizeResult:
    target: float
    conventions: str
    errors: dict  # N -> {format: max error}
    smallest: dict  # format -> N or None
    sizes: tuple

    def text(self) -> str:
        fmts = list(STORAGE)
        lines = [
            f"max |bilinear(table) - integral| between texels, {self.conventions}",
            "N      " + "".join(f"{f:>10}" for f in fmts),
        ]
        for n in self.sizes:
            if n in self.errors:
                lines.append(f"{n:<7}" + "".join(f"{self.errors[n][f]:>10.2e}" for f in fmts))
        lines.append(f"smallest N with max error <= {self.target:g}:")
        for f in fmts:
            n = self.smallest[f]
            lines.append(
                f"  {f:8} {STORAGE[f]:28} "
                + (f"{n}^2 (error {self.errors[n][f]:.2e})" if n else f"none up to {max(self.errors)}^2")
            )
        return "\n".join(lines)

    def as_dict(self) -> dict:
        return {
            "target": self.target,
            "conventions": self.conventions,
            "storage": STORAGE,
            "errors": {str(n): e for n, e in self.errors.items()},
            "smallest": self.smallest,
        }


def measure(conv_args: dict, n: int, channels=None, workers=None, nov_min: float = 0.0) -> dict:
    """{format: max error after bilinear filtering} of an n x n table (module docstring), over the points
    with NoV >= ``nov_min``."""
    conv = conventions(**conv_args, shape=(n, n))
    integ = Integrator(conv, workers)
    nov, alpha, rough = half_grid(conv)
    ref = integ.converged(nov.ravel(), alpha.ravel(), rough.ravel()).reshape(nov.shape + (-1,))
    if channels is not None:
        ref = ref[..., channels]
    table = ref[::2, ::2]
    inside = nov >= nov_min
    return {f: float(np.max(np.abs(bilinear_half(store(table, f)) - ref)[inside])) for f in STORAGE}


def smallest_sizes(
    conv_args: dict, target: float, sizes=SIZES, channels=None, workers=None, nov_min: float = 0.0
) -> SizeResult:
    """Measure each size in increasing order until every format meets ``target`` (or the sizes run out)."""
    errors, smallest = {}, {f: None for f in STORAGE}
    for n in sorted(sizes):
        errors[n] = measure(conv_args, n, channels, workers, nov_min)
        for f, e in errors[n].items():
            if smallest[f] is None and e <= target:
                smallest[f] = n
        if all(v is not None for v in smallest.values()):
            break
    conv = conventions(**conv_args, shape=(8, 8))
    label = f"{conv.source} (layout {conv.layout}), NoV >= {nov_min:g}"
    return SizeResult(target, label, errors, smallest, tuple(sorted(sizes)))
