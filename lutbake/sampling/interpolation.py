"""Verified interpolation between texels: most texels of a large adaptive table from its every STRIDE-th row and
column, each one kept only where its own error estimate meets the table's tolerance; every other texel integrated.

A table is a smooth function of its texel coordinates wherever no edge policy cuts it (lutbake.edge: the mirror limit
or clamps at alpha -> 0, clamped cosines; ``Grid.smooth``), and at 1024^2 it is sampled far more densely than its
features need: the glTF table's values change by ~1e-3 per texel. Per 2D slice (the last two axes, y and x):

1. The *coarse* texels, every STRIDE-th index of each axis plus the last, are integrated by the table's adaptive
   estimator at COARSE_SHARE of its tolerance (``lutbake.runtime.memo.RowMemo``: once per process, whichever tile asks).
2. Every other texel of a *smooth* stencil is the tensor product of degree-5 Lagrange interpolants in the texel index
   (6 coarse nodes per axis: 3 on each side). Its error is estimated from the same coarse data interpolated by the
   degree-5 stencil shifted one node to either side, along x, then along y. Where the function is resolved, a
   shifted stencil's error has the opposite sign and 1.2-1.7x the size of the centred one's (its node polynomial
   trades the factor (t - 3) for (t + 3) or (t + 2) for (t - 4), t in (0, 1) the texel's place between its two
   nearest nodes, in coarse steps), so their difference is at least 2.2x the centred error along that axis. Where a
   feature sits under the stencil (alpha ~ NoV / 4 near grazing), a shifted stencil sees it from another side and
   disagrees. (A centred degree-5 against degree-3 test was passed by texels whose error was 2-4x that difference,
   next to such features; measured on the 1024^2 glTF table against a bake to 2e-7: with the shifts, error /
   estimate <= 0.31 over every accepted texel.)
       estimate = SAFETY max_shifts |V_shifted - V| + sum_ab |w_a w_b| e_ab + TERMS_ROUNDING |V|
   where e_ab are the coarse texels' own estimates (the Lagrange weights w propagate them exactly) and TERMS_ROUNDING
   the float32 terms' rounding (lutbake.sampling.hemisphere). A texel is kept where this is within max(tolerance,
   relative_tolerance |V|) in every channel.
3. The rest, texels near the table's edges (the shifted stencils need 4 coarse nodes on one side), next to an edge
   policy, or whose estimate missed, are integrated as without interpolation, to the tolerance.

Every value is a pure function of the coarse texels and its own inputs (element-wise numpy, a fixed order of
operations), so the table is bit-identical however the tiles are cut and whichever worker computes a coarse texel.
A tile's per-texel aux columns carry each texel's estimate and how it was obtained (``INTEGRATED``, ``COARSE``,
``INTERPOLATED``), for lutbake:error_estimate_method.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

import numpy as np

from ..runtime.memo import RowMemo
from ..tolerance import TERMS_ROUNDING

STRIDE = 4  # coarse texels: every STRIDE-th index of each image axis, and the last
COARSE_SHARE = 0.25  # their tolerance: this share of the table's (their errors reach interpolated texels x Lebesgue)
SAFETY = 2.0  # the estimate: SAFETY x the largest difference between the interpolants
# both image axes at least this long, else every texel integrated: at 64^2 the edges (3 coarse gaps on each side) leave
# 3-15 % of the texels to interpolate, less than the coarse texels' tighter tolerance costs (make luts's 64^2 tables:
# 0.8-1.0x the time without); at 128^2, 45-55 % and 1.4-1.8x less CPU (benchmarks/bench_interpolation.py)
MIN_AXIS = 128
TILE_TARGET = 16384  # texels per tile: whole rows, at most about this many
MIN_TILES = 8  # ... and at least this many tiles per slice (a 128^2 table in one tile kept one core busy)
INTEGRATED, COARSE, INTERPOLATED = 0.0, 1.0, 2.0  # a texel's flag in the tile's last aux column
# interpolants along one axis, as (first node, node count) relative to k, the first coarse node above the texel
VARIANTS = {"c": (-3, 6), "l": (-4, 6), "r": (-2, 6)}
COMBOS = (("l", "c"), ("r", "c"), ("c", "l"), ("c", "r"))  # (x, y) variants compared with ("c", "c")
SPAN = (-4, 8)  # every node any variant uses: k - 4 .. k + 3


@dataclass(frozen=True)
class AxisStencils:
    """One axis of n texels: its coarse indices, and per variant (VARIANTS) the coarse ordinals ``idx`` (n, 6) and
    Lagrange weights ``w`` (n, 6) of every index (a coarse index: itself, weight 1; ``valid`` False where a variant
    would leave the axis: those texels are integrated)."""

    n: int
    coarse: np.ndarray
    is_coarse: np.ndarray
    idx: dict
    w: dict
    span: np.ndarray  # (n, 8) ordinals of SPAN (a coarse index: itself)
    valid: np.ndarray


@functools.lru_cache(maxsize=64)
def axis_stencils(n: int, stride: int = STRIDE) -> AxisStencils:
    coarse = np.unique(np.r_[np.arange(0, n, stride), n - 1])
    nc = len(coarse)
    is_coarse = np.zeros(n, bool)
    is_coarse[coarse] = True
    ordinal = np.searchsorted(coarse, np.arange(n))  # a coarse index's ordinal; else k: coarse[k - 1] < i < coarse[k]
    valid = is_coarse | ((ordinal + SPAN[0] >= 0) & (ordinal + SPAN[0] + SPAN[1] - 1 <= nc - 1))
    idx, w = {}, {}
    for name, (first, count) in VARIANTS.items():
        ii = np.zeros((n, 6), np.int64)
        ww = np.zeros((n, 6))
        for i in range(n):
            if is_coarse[i]:
                ii[i, :] = ordinal[i]
                ww[i, 0] = 1.0
            elif valid[i]:
                o = ordinal[i] + first + np.arange(count)
                x = coarse[o].astype(np.float64)
                ii[i, :count] = o
                ii[i, count:] = o[0]
                for a in range(count):  # Lagrange basis polynomial a at i
                    others = np.delete(x, a)
                    ww[i, a] = np.prod((i - others) / (x[a] - others))
        idx[name], w[name] = ii, ww
    span = np.where(
        is_coarse[:, None], ordinal[:, None], np.clip(ordinal[:, None] + SPAN[0] + np.arange(SPAN[1]), 0, nc - 1)
    )
    return AxisStencils(n, coarse, is_coarse, idx, w, span, valid)


def along(a: np.ndarray, idx: np.ndarray, w: np.ndarray, axis: int) -> np.ndarray:
    """sum_m w[:, m] a[idx[:, m]] along ``axis`` (0: rows of a (R, X, C), 1: its columns), term by term in m (a fixed
    order: the same bits for any array shape)."""
    acc = None
    for m in range(w.shape[1]):
        if axis == 1:
            term = w[None, :, m, None] * a[:, idx[:, m]]
        else:
            term = w[:, m, None, None] * a[idx[:, m]]
        acc = term if acc is None else acc + term
    return acc


def applies(grid) -> bool:
    """Whether a plan of ``grid`` interpolates: a smoothness mask and both image axes at least MIN_AXIS long."""
    axes = grid.axes
    return grid.smooth is not None and len(axes) >= 2 and min(axes[-1].count, axes[-2].count) >= MIN_AXIS


def tile_texels(axes) -> int:
    """Whole rows per tile, a multiple of STRIDE: at most about TILE_TARGET texels, at least MIN_TILES tiles a slice
    (the coarse texels two tiles share are computed once: VerifiedInterpolation.memo)."""
    nx, ny = axes[-1].count, axes[-2].count
    rows = min(TILE_TARGET // nx, -(-ny // MIN_TILES))
    return nx * min(ny, STRIDE * max(1, -(-rows // STRIDE)))


METHOD = (
    f"texels between every {STRIDE}th row and column (integrated to {COARSE_SHARE:g} x the tolerance) interpolated by "
    "tensor degree-5 Lagrange in the texel index where the stencils lie on smooth texels and the estimate "
    f"{SAFETY:g} max |stencil shifted by one node - it| + sum |w_a w_b| e_ab + 1e-7 |v| meets the tolerance; "
    "every other texel integrated (lutbake.sampling.interpolation)"
)


def describe(flags: np.ndarray) -> str:
    """How many texels of a table were integrated, coarse, interpolated (the tiles' flag column)."""
    n = len(flags)
    k = int(np.count_nonzero(flags == INTERPOLATED))
    c = int(np.count_nonzero(flags == COARSE))
    return (
        f"{SAFETY:g} max |V(stencil shifted by one node) - V| + sum |w_a w_b| e_ab + 1e-7 |V| "
        f"(lutbake.sampling.interpolation): {k} of {n} texels ({100.0 * k / max(n, 1):.1f} %) interpolated from {c} "
        f"coarse ones, {n - k - c} integrated"
    )


class VerifiedInterpolation:
    """The tiles of an adaptive estimator's plan over ``grid`` (module docstring): ``run_tile(start, stop, device)``
    -> (values, estimates, flag) columns of texels [start, stop). ``integrate(estimator, texel indices, device)`` ->
    (values, estimates) of those texels by an adaptive estimator (``estimator`` or its COARSE_SHARE copy)."""

    def __init__(self, grid, estimator, integrate, nch: int):
        self.grid, self.estimator, self.integrate, self.nch = grid, estimator, integrate, nch
        self.nx, self.ny = grid.axes[-1].count, grid.axes[-2].count
        self.x, self.y = axis_stencils(self.nx), axis_stencils(self.ny)
        self.coarse_estimator = replace(
            estimator, absolute=estimator.absolute * COARSE_SHARE, relative=estimator.relative * COARSE_SHARE
        )
        n_coarse = len(self.x.coarse) * len(self.y.coarse) * (grid.n_texels // (self.nx * self.ny))
        self.memo = RowMemo(capacity=n_coarse)

    def coarse_rows(self, z: int, rows: np.ndarray, device: str):
        """Values, estimates and smoothness of the coarse texels of coarse-row ordinals ``rows`` (every coarse
        column): (R, ncx, nch) twice, (R, ncx)."""
        cols = self.x.coarse
        flat = (z * self.ny + self.y.coarse[rows])[:, None] * self.nx + cols[None, :]
        keys = [int(i).to_bytes(8, "little") for i in flat.ravel()]

        v, e = self.memo.run(keys, lambda which: self.integrate(self.coarse_estimator, flat.ravel()[which], device))
        shape = (len(rows), len(cols), self.nch)
        return v.reshape(shape), e.reshape(shape), self.grid.smooth[flat]

    def rows(self, z: int, r0: int, r1: int, device: str) -> np.ndarray:
        """(values, estimates, flag) of every texel of rows [r0, r1) of slice z: (r1 - r0) * nx rows."""
        xs, ys, nch = self.x, self.y, self.nch
        rr = np.arange(r0, r1)
        flat = (z * self.ny + rr)[:, None] * self.nx + np.arange(self.nx)[None, :]
        need = np.unique(ys.span[rr][ys.valid[rr]])
        if need.size == 0:  # rows next to an end of the y axis, none coarse: every texel integrated
            v, e = self.integrate(self.estimator, flat.ravel(), device)
            return np.concatenate([v, e, np.full((len(v), 1), INTEGRATED)], axis=1)
        f, fe, fs = self.coarse_rows(z, need, device)
        # along x: every variant, the coarse estimates (|w|), smoothness over the stencils' span
        xv = {v: along(f, xs.idx[v], xs.w[v], 1) for v in VARIANTS}
        xe = along(fe, xs.idx["c"], np.abs(xs.w["c"]), 1)
        xbad = ~fs[:, xs.span].all(axis=2) | ~xs.valid[None, :]
        # along y, rows rr: positions of their stencils' ordinals among the fetched rows
        ok_y = ys.valid[rr]
        pos = {v: np.searchsorted(need, np.where(ok_y[:, None], ys.idx[v][rr], need[0])) for v in VARIANTS}
        wy = {v: np.where(ok_y[:, None], ys.w[v][rr], 0.0) for v in VARIANTS}
        value = along(xv["c"], pos["c"], wy["c"], 0)
        diff = np.zeros_like(value)
        for vx, vy in COMBOS:
            diff = np.maximum(diff, np.abs(along(xv[vx], pos[vy], wy[vy], 0) - value))
        propagated = along(xe, pos["c"], np.abs(wy["c"]), 0)
        span_pos = np.searchsorted(need, np.where(ok_y[:, None], ys.span[rr], need[0]))
        bad = xbad[span_pos].any(axis=1) | ~ok_y[:, None]
        estimate = SAFETY * diff + propagated + TERMS_ROUNDING * np.abs(value)
        target = np.maximum(self.estimator.absolute, self.estimator.relative * np.abs(value))
        coarse = ys.is_coarse[rr][:, None] & xs.is_coarse[None, :]
        keep = (estimate <= target).all(axis=2) & ~bad & self.grid.smooth[flat] & ~coarse
        flag = np.where(coarse, COARSE, np.where(keep, INTERPOLATED, INTEGRATED))
        # coarse texels: their own values and estimates (value and propagated reproduce them: weight 1, others 0)
        estimate[coarse] = propagated[coarse]
        todo = ~(keep | coarse)
        if todo.any():
            v, e = self.integrate(self.estimator, flat[todo], device)
            value[todo], estimate[todo] = v, e
        n = len(rr) * self.nx
        return np.concatenate([value.reshape(n, nch), estimate.reshape(n, nch), flag.reshape(n, 1)], axis=1)

    def run_tile(self, start: int, stop: int, device: str) -> np.ndarray:
        """Texels [start, stop): the whole rows they touch, per slice, cut to the range."""
        per_slice = self.nx * self.ny
        parts, first = [], start
        while first < stop:
            z, in_slice = divmod(first, per_slice)
            last = min(stop, (z + 1) * per_slice)  # exclusive, within slice z
            r0, r1 = in_slice // self.nx, -(-(last - z * per_slice) // self.nx)
            block = self.rows(z, r0, r1, device)
            off = z * per_slice + r0 * self.nx
            parts.append(block[first - off : last - off])
            first = last
        return np.concatenate(parts, axis=0)
