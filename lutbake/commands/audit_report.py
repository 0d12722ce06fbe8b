"""What the audits share (lutbake.commands.audit: the split-sum family; lutbake.commands.audit_tables: LTC and
OpenPBR): the strided subset of texels re-integrated, the error statistics, the metric held against the tolerance,
and the error map."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..axes import Axis

MISMATCH_RATIO = 0.5  # an alternative convention is the diagnosis when its RMS is below this x the nominal RMS
PERCENTILES = (50, 95, 99)
METRICS = ("max", "p99", "mean")


def subset(n: int, max_side: int) -> np.ndarray:
    """At most ``max_side`` evenly strided indices of 0..n-1, the last one always included."""
    stride = max(1, math.ceil(n / max_side))
    return np.unique(np.r_[np.arange(0, n, stride), n - 1])


def stats(err: np.ndarray) -> dict:
    a = np.abs(err)
    d = {"max": float(a.max()), "mean": float(a.mean())}
    d.update({f"p{p}": float(np.percentile(a, p)) for p in PERCENTILES})
    return d


def metric_value(abs_err: np.ndarray, metric: str) -> float:
    """The statistic of |error| held against --tolerance (METRICS)."""
    return {"max": float(abs_err.max()), "p99": float(np.percentile(abs_err, 99)), "mean": float(abs_err.mean())}[
        metric
    ]


def verdict(metric: str, tolerance: float, value: float, passed: bool | None = None) -> dict:
    """The verdict fields of every audit report: the metric, the tolerance, the value held against it and whether it
    passed (default: value <= tolerance)."""
    return {
        "metric": metric,
        "tolerance": tolerance,
        "value": value,
        "passed": bool(value <= tolerance) if passed is None else passed,
    }


def write_error_map(out: Path, err: np.ndarray, names: list[str], axes: list[Axis], iy, ix, title: str) -> Path:
    """PNG: |file - reference| per channel, image row 0 at the bottom, ticks = the declared axis values."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..io.atomic import atomic_write

    n = err.shape[-1]
    fig, axs = plt.subplots(1, n, figsize=(4.2 * n, 3.8), dpi=100, squeeze=False)
    for c in range(n):
        ax = axs[0, c]
        im = ax.imshow(np.abs(err[..., c]), origin="lower", cmap="magma", interpolation="nearest", aspect="auto")
        ax.set_title(f"|file - converged|  {'RGBA'[c]} = {names[c]}", fontsize=9)
        for axis, idx, setter, ticker in (
            (axes[1], ix, ax.set_xlabel, ax.set_xticks),
            (axes[0], iy, ax.set_ylabel, ax.set_yticks),
        ):
            vals = axis.values()
            pos = np.unique(np.linspace(0, len(idx) - 1, 5).round().astype(int))
            ticker(pos, [f"{vals[idx[p]]:.3g}" for p in pos], fontsize=7)
            setter(f"{axis.name} ({axis.texel}, {axis.mapping}, {axis.order}); index 0 at origin", fontsize=8)
        fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04).ax.tick_params(labelsize=7)
    fig.suptitle(f"lutbake audit: {title}", fontsize=10)
    fig.tight_layout()
    out = Path(out)
    atomic_write(out, lambda tmp: fig.savefig(tmp, format="png"))
    plt.close(fig)
    return out
