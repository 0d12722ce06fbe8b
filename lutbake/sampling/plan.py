"""One texel plan for every kind: ``per_texel_plan(integrand, estimator, grid)``, a lutbake.runtime.plan.TexelPlan
(everything the executor needs; its ``run_tile(start, stop, device)`` is a pure function of the spec and the tile
bounds, so tiles can be handed to any worker, thread or cluster, and the result is bit-identical however they are
cut).

The three parts it composes stay apart, as in ``warp.fem.integrate(integrand, domain, quadrature)``:
- the **integrand** (lutbake.integrands): what is integrated per texel, a record holding its ``@wp.func``s;
- the **estimator** (this package): how, an object with ``name``, ``prepare(integrand, device)``,
  ``evaluate(integrand, inputs, device) -> (n, nch) float64``, ``samples(inputs)`` (evaluations per texel) and
  ``refined() -> (estimator, how)``: the same estimator at a higher budget (or another scrambling), for the
  error estimate;
- the **grid** (``Grid``): the axes and the per-texel inputs (lutbake.axes gives the values).
The error estimate re-evaluates one set of probe texels (``probe_indices``) with ``refined()``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..axes import Axis
from ..runtime.plan import TexelPlan
from ..tolerance import over_tolerance

PROBE_STRIDED = 256  # strided probe texels of the error estimate
PROBE_EXTREME = 64  # ... plus at most this many of the most grazing and of the smallest-alpha texels


@dataclass(frozen=True)
class Grid:
    """The texels of a table: ``axes`` and the per-texel ``inputs`` of the integrand (name -> array, row-major,
    slowest axis first). ``grazing`` and ``alpha`` (optional, per texel) pick the probe texels of the error
    estimate. (An average over a texel's sub-directions, as kind albedo_avg's over mu, is a plan of its own:
    lutbake.sampling.mu_average.)"""

    axes: list[Axis]
    inputs: dict[str, np.ndarray]
    grazing: np.ndarray | None = None
    alpha: np.ndarray | None = None
    # per texel: its inputs are an analytic function of its texel coordinates (no edge policy cut them): the texels
    # lutbake.sampling.interpolation may interpolate between; None: that kind's plan never interpolates
    smooth: np.ndarray | None = None

    @property
    def n_texels(self) -> int:
        return len(next(iter(self.inputs.values())))

    def rows(self, idx) -> dict[str, Any]:
        """The inputs of texels ``idx`` (a slice or an index array)."""
        return {k: v[idx] for k, v in self.inputs.items()}


@dataclass(frozen=True)
class StoredMap:
    """What a table stores of its integrand's channels where that is not the integrals themselves: a layout's map
    (lutbake.layouts.base.Layout.to_stored / from_stored, ``StoredMap.of_values``) or an engine's added channel
    (lutbake.integrands.engine_diffuse.diffuse_channel). ``to_stored(values, texels, device)``: the integrals (or the
    previous map's values) of the texels ``texels`` (a slice), (n, C), -> the stored values, (n, C + added);
    ``from_stored(stored)``: back to what it was given, (n, C), for the error estimate; ``prepare(device)``: the
    kernels ``to_stored`` launches, loaded with the estimator's."""

    to_stored: Callable[[np.ndarray, slice, str], np.ndarray]
    from_stored: Callable[[np.ndarray], np.ndarray] | None
    added: int = 0
    prepare: Callable[[str], None] | None = None

    @classmethod
    def of_values(cls, to_stored: Callable, from_stored: Callable | None) -> StoredMap:
        """The map of each texel's values alone: ``to_stored(values)``, ``from_stored(stored)``."""
        return cls(lambda values, texels, device: to_stored(values), from_stored)


def stored_through(stored: tuple[StoredMap, ...], nch: int, run_tile: Callable, error_estimate: Callable | None):
    """(run_tile, error_estimate) of a plan whose table holds the ``nch`` integrals passed through ``stored`` (in
    order), the tiles' aux columns untouched; the error estimate sees the integrals again (each map's from_stored, in
    reverse order), as the estimator produced them."""
    width = nch + sum(m.added for m in stored)

    def run(start: int, stop: int, device: str) -> np.ndarray:
        tile = run_tile(start, stop, device)
        values = tile[:, :nch]
        for m in stored:
            values = m.to_stored(values, slice(start, stop), device)
        return np.concatenate([values, tile[:, nch:]], axis=1)

    def estimate(data: np.ndarray, device: str):
        values = data[:, :width]
        for m in reversed(stored):
            values = m.from_stored(values)
        return error_estimate(np.concatenate([values, data[:, width:]], axis=1), device)

    return run, estimate if error_estimate is not None else None


def probe_indices(grid: Grid) -> np.ndarray:
    """The probe texels of every error estimate: PROBE_STRIDED strided texels, plus (at most PROBE_EXTREME each)
    the most grazing ones (``grid.grazing`` at its minimum) and the smallest alphas at grazing view, where
    every quadrature converges slowest."""
    n = grid.n_texels
    parts = [np.arange(0, n, max(1, n // PROBE_STRIDED))]
    if grid.grazing is not None:
        grazing = np.flatnonzero(grid.grazing <= grid.grazing.min())
        parts.append(grazing[:: max(1, len(grazing) // PROBE_EXTREME)])
        if grid.alpha is not None:
            parts.append(np.lexsort((grid.alpha, grid.grazing))[:PROBE_EXTREME])
    return np.unique(np.concatenate(parts))


def per_texel_plan(
    integrand,
    estimator,
    grid: Grid,
    *,
    channels: dict[str, str],
    reconstruction: str,
    terms: dict[str, str],
    extra: dict[str, str] | None = None,
    relative_error: bool = False,
    error_estimate: bool = True,
    tile_texels: int | None = None,
    interpolate: bool = False,
    siblings: Callable[[int, int], np.ndarray | None] | None = None,
    stored: tuple[StoredMap, ...] = (),
) -> TexelPlan:
    """The texel plan of ``grid``'s texels integrated by ``estimator``: texel i = estimator.evaluate(integrand,
    grid inputs of i), the first ``integrand.nch`` channels kept.
    ``relative_error``: the error estimate is max |a - b| / |b| over probe texels with |b| > 1e-6.
    ``interpolate``: an adaptive estimator's texels come from lutbake.sampling.interpolation where the grid allows
    (interpolation.applies: a ``grid.smooth`` mask, both image axes long enough), each within the tolerance.
    ``siblings(start, stop)``: the texels (sorted, a superset of the tile's) to evaluate in one call with tile
    [start, stop), or None for the tile alone: an estimator that shares work between texels of one call
    (lutbake.sampling.dielectric.sibling_tiles) gets them together; each texel is evaluated once per plan (a memo:
    the tiles of its siblings take its row), and its value does not depend on its company.
    ``stored``: what the table holds of the integrals where it is not them (StoredMap: a layout's map, an engine's
    added channel), applied in order to each tile's channels; the error estimate sees the integrals."""
    from ..runtime.memo import RowMemo
    from . import interpolation

    def run(idx, est, device):
        return est.evaluate(integrand, grid.rows(idx), device)[:, : integrand.nch]

    adaptive = hasattr(estimator, "evaluate_with_error")
    tolerance_record = (
        {"tolerance": f"max({estimator.absolute:.3g}, {estimator.relative:.3g} |v|) per value"} if adaptive else {}
    )

    def integrate(est, idx, device: str) -> tuple[np.ndarray, np.ndarray]:
        """Values and estimates of texels ``idx`` (a slice or indices) by the adaptive estimator ``est``."""
        values, err = est.evaluate_with_error(integrand, grid.rows(idx), device)
        return values[:, : integrand.nch], err[:, : integrand.nch]

    memo = RowMemo(capacity=grid.n_texels) if siblings else None

    def tile_rows(s: int, e: int, rows_of: Callable[[Any], np.ndarray]) -> np.ndarray:
        """rows_of(texels) of tile [s, e), evaluated with the tile's siblings where it has them."""
        idx = siblings(s, e) if siblings else None
        if idx is None:
            return rows_of(slice(s, e))
        keys = [int(i).to_bytes(8, "little") for i in idx]
        (rows,) = memo.run(keys, lambda j: (rows_of(idx[j]),))
        return rows[np.searchsorted(idx, np.arange(s, e))]

    def run_adaptive(s: int, e: int, device: str) -> np.ndarray:
        """Values of texels [s, e), then their error estimates (aux columns)."""
        return tile_rows(s, e, lambda idx: np.concatenate(integrate(estimator, idx, device), 1))

    verified = None
    if adaptive and interpolate and interpolation.applies(grid):
        verified = interpolation.VerifiedInterpolation(grid, estimator, integrate, integrand.nch)
        tolerance_record["interpolation"] = interpolation.METHOD

    def adaptive_estimate(data: np.ndarray, device: str) -> tuple[float, str, str]:
        """The max over texels of the kernel's own per-texel estimate (the tiles' aux columns); the method names
        the worst ratio to the tolerance (<= 1: every texel met it); the third part, where texels end over it
        (lutbake.tolerance.over_tolerance, "" when none)."""
        full = data.reshape(grid.n_texels, -1)
        nch = integrand.nch
        values, texel_error = full[:, :nch], full[:, nch : 2 * nch]
        target = np.maximum(estimator.absolute, estimator.relative * np.abs(values))
        with np.errstate(divide="ignore", invalid="ignore"):  # tolerance = 0 (allowed): a zero target
            ratios = np.where(target > 0, texel_error / target, np.where(texel_error > 0, np.inf, 0.0))
        ratio = float(np.max(ratios))
        # texels whose panels all reached the last order short of the target (the kernel's comparison, with rounding)
        over = int(np.count_nonzero(np.any(texel_error > target * (1.0 + 1e-9), axis=1)))
        err = float(np.max(texel_error))
        if relative_error:
            ok = np.abs(values) > 1e-6
            err = float(np.max(texel_error[ok] / np.abs(values[ok]))) if ok.any() else 0.0
        met = "every texel" if over == 0 else f"all but {over} of {grid.n_texels} texels, which ended at the last order"
        how = (
            f"per {'integrated (and coarse) ' if verified else ''}texel: sum over panels of |Q(order k) - "
            f"Q(order k-1)| at the order that met the tolerance{getattr(estimator, 'estimate_note', '')}"
        )
        if verified:
            how += "; per interpolated texel: " + interpolation.describe(full[:, 2 * nch])
        how += f" ({met}); max error / tolerance = {ratio:.3g}"
        if relative_error:
            how = "relative (|f| > 1e-6), " + how + f"; max abs {float(np.max(texel_error)):.3e}"
        return err, how, over_tolerance(np.max(ratios, axis=1), grid.axes)

    def estimate(data: np.ndarray, device: str) -> tuple[float, str]:
        idx = probe_indices(grid)
        refined, how = estimator.refined()
        ref = run(idx, refined, device)
        got = data.reshape(grid.n_texels, -1)[idx]
        err = np.abs(got - ref)
        where = f"over {len(idx)} probe texels (strided + most grazing + smallest alpha)"
        if not relative_error:
            return float(np.max(err)), f"max |{how}| {where}"
        ok = np.abs(ref) > 1e-6
        rel = float(np.max(err[ok] / np.abs(ref[ok]))) if ok.any() else 0.0
        return rel, f"max relative |{how}| {where} with |f| > 1e-6; max abs {float(np.max(err)):.3e}"

    def run_fixed(s: int, e: int, device: str) -> np.ndarray:
        return tile_rows(s, e, lambda idx: run(idx, estimator, device))

    run_tile = verified.run_tile if verified else run_adaptive if adaptive else run_fixed
    error = (adaptive_estimate if adaptive else estimate) if error_estimate else None
    if stored:
        run_tile, error = stored_through(stored, integrand.nch, run_tile, error)

    def prepare(device: str) -> None:
        estimator.prepare(integrand, device)
        for m in stored:
            if m.prepare is not None:
                m.prepare(device)

    samples = estimator.samples(grid.inputs)  # evaluations per texel
    return TexelPlan(
        axes=grid.axes,
        channels=channels,
        reconstruction=reconstruction,
        n_texels=grid.n_texels,
        n_channels=integrand.nch + sum(m.added for m in stored),
        run_tile=run_tile,
        prepare=prepare,
        samples=int(round(np.mean(samples))),
        estimator=estimator.name,
        terms=terms,
        cost=float(np.sum(samples)),
        extra={**(extra or {}), **tolerance_record},
        error_estimate=error,
        aux_channels=(integrand.nch + (1 if verified else 0)) if adaptive else 0,
        tile_texels=interpolation.tile_texels(grid.axes) if verified else tile_texels,
    )
