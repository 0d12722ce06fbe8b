"""The error a table aims for: the common keys ``tolerance`` (absolute) and ``relative_tolerance``.

A texel value v (each channel) is done when its error estimate e satisfies

    e <= max(tolerance, relative_tolerance * |v|)

Unset keys take their default from the table's storage precision (``default_tolerance``): a quarter of what the
stored value can resolve, so the quadrature error never moves a stored code by more than a quarter quantum:

| storage | tolerance (absolute) | relative_tolerance |
| --- | --- | --- |
| ``format = "png16"``, ``"openpbr_h"`` (16-bit UNORM) | 1 / (4 * 65535) = 3.8e-6 | 0 |
| ``dtype = "half"`` | 2^-26 = 1.5e-8 (1/4 of the subnormal step) | 2^-13 = 1.2e-4 (1/4 of the relative step 2^-11) |
| ``dtype = "float32"`` | 1e-6 | 0 |

float32 is not held to its own quantum (6e-8 relative): the BRDF terms are evaluated in float32, so ~1e-7 is the
floor of what any quadrature here resolves, and reaching 1e-7 relative costs 4.3x the time of 1e-6 (128^2 dfg,
measured: 3.87 s CPU against 0.90 s). 1e-6 is the project's accuracy bar for float32 tables (dfg <= 1e-6 against a
converged reference); set ``tolerance`` / ``relative_tolerance`` for more.

The estimators that adapt to it (lutbake.sampling.hemisphere.AdaptiveGaussLegendre) record the tolerance and the
reached error per table (``lutbake:tolerance``, ``lutbake:error_estimate``).
"""

from __future__ import annotations

from dataclasses import dataclass

UNORM16_QUANTUM = 1.0 / 65535.0
UNORM16_FORMATS = ("png16", "openpbr_h")  # formats that store codes round(v * 65535)
HALF_REL_STEP = 2.0**-11  # half: 10 stored mantissa bits, relative spacing between 2^-11 and 2^-10
HALF_SUBNORMAL_STEP = 2.0**-24
FLOAT32_ABSOLUTE = 1.0e-6  # the project's float32 accuracy bar (module docstring)
FLOAT32_RELATIVE = 0.0  # absolute only (the module docstring: 1e-6 is the float32 bar for values up to ~1)
QUARTER = 0.25
# the float32 BRDF terms' rounding carried by a texel value, relative (lutbake.sampling.hemisphere adds it to every
# adaptive estimate; lutbake.sampling.interpolation to the interpolated texels')
TERMS_ROUNDING = 1.0e-7


@dataclass(frozen=True)
class Tolerance:
    """Target: e <= max(absolute, relative * |v|) per texel value."""

    absolute: float
    relative: float

    def text(self) -> str:
        return f"max({self.absolute:.3g}, {self.relative:.3g} |v|) per value"


def default_tolerance(options, float32: Tolerance | None = None) -> Tolerance:
    """The storage-derived default (module docstring) for a spec's ``format`` and ``dtype``; ``float32``: a kind's
    own float32 default (kind btf: 1e-5 relative, its values spanning five decades), else FLOAT32_ABSOLUTE."""
    if options.get("format") in UNORM16_FORMATS:
        return Tolerance(QUARTER * UNORM16_QUANTUM, 0.0)
    if options.get("dtype") == "half":
        return Tolerance(QUARTER * HALF_SUBNORMAL_STEP, QUARTER * HALF_REL_STEP)
    return float32 or Tolerance(FLOAT32_ABSOLUTE, FLOAT32_RELATIVE)


def tolerance_of(options, float32: Tolerance | None = None) -> Tolerance:
    """The spec's tolerance: its ``tolerance`` / ``relative_tolerance`` keys where set, the default otherwise.
    Setting only ``tolerance`` drops the default relative part (and vice versa): the keys say the whole target."""
    tol, rel = options.get("tolerance"), options.get("relative_tolerance")
    if tol is None and rel is None:
        return default_tolerance(options, float32)
    return Tolerance(float(tol or 0.0), float(rel or 0.0))


# a texel is over its tolerance when its estimate exceeds the target by more than float rounding (the kernels compare
# in float64 after a division by pi)
OVER_SLACK = 1.0e-9
AXIS_WORDS = {"x": "columns", "y": "rows", "z": "slices", "y_block": "row blocks"}


def over_tolerance(ratios, axes) -> str:
    """Where a table ends over its tolerance: ``ratios`` per texel (estimate / target, the worst channel; row-major,
    the slowest axis first), ``axes`` the table's (lutbake.axes.Axis, slowest first). One line: "143 of 4096 texels
    over tolerance: perceptual_roughness rows 0..16 (0.0078..0.27), NoV columns 0..12 (0.0078..0.2); worst
    estimate / tolerance 3.65e+03" (the bounding box of those texels, indices and axis values); "" when none."""
    import numpy as np

    r = np.asarray(ratios, np.float64).ravel()
    over = np.flatnonzero(~(r <= 1.0 + OVER_SLACK))  # NaN counts as over
    if len(over) == 0:
        return ""
    shape = tuple(a.count for a in axes)
    where = f"texels {over.min()}..{over.max()}"
    if int(np.prod(shape)) == len(r):
        parts = []
        for a, idx in zip(axes, np.unravel_index(over, shape)):
            lo, hi = int(idx.min()), int(idx.max())
            values = a.values()
            parts.append(
                f"{a.name} {AXIS_WORDS.get(a.dim, a.dim)} {lo}..{hi} ({float(values[lo]):.3g}..{float(values[hi]):.3g})"
            )
        where = ", ".join(parts)
    worst = float(np.max(np.where(np.isnan(r), np.inf, r)))
    return f"{len(over)} of {len(r)} texels over tolerance: {where}; worst estimate / tolerance {worst:.3g}"
