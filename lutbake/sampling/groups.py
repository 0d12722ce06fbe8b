"""Texels that share every node of their quadrature and differ only in one parameter, evaluated together.

A kernel that takes such a group's nodes once and only the parameter's part per member (lutbake.sampling.dielectric:
the glass tables' eta >= 1 at one (n.v, alpha); lutbake.sampling.swapped: the diffuse_3d table's f0 slices at one
(n.v, sigma)) gives each member the bits of its own evaluation, so the grouping is free to cut anywhere: a texel's
value never depends on its company. ``key_of`` names the texels that share their nodes, ``group_rows`` cuts a call's
texels into groups, ``siblings_by_key`` gives lutbake.sampling.plan.per_texel_plan the texels to evaluate with a
tile where the plan's CPU tiles cut the shared axis (a parameter slowest, as IOR and f0 slices are stored).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def key_of(*columns) -> np.ndarray:
    """One integer per texel, equal where every column's value is (bit for bit, in float64)."""
    a = np.ascontiguousarray(np.column_stack([np.asarray(c, np.float64) for c in columns]))
    rows = a.view(np.dtype((np.void, a.dtype.itemsize * a.shape[1]))).ravel()
    return np.unique(rows, return_inverse=True)[1].ravel().astype(np.int64)


def group_rows(key: np.ndarray, shareable: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """(groups, singles): rows of up to ``size`` indices (-1 padded) of the ``shareable`` texels of one key (two or
    more), by key then index; the other texels' indices, ascending."""
    idx = np.flatnonzero(shareable)
    order = idx[np.argsort(key[idx], kind="stable")]
    keys = key[order]
    starts = np.flatnonzero(np.r_[True, keys[1:] != keys[:-1]]) if len(order) else np.zeros(0, int)
    rows, singles = [], [np.flatnonzero(~shareable)]
    for a, b in zip(starts, np.r_[starts[1:], len(order)]):
        run = order[a:b]
        if len(run) < 2:
            singles.append(run)
            continue
        for c in range(0, len(run), size):
            rows.append(np.pad(run[c : c + size], (0, size - len(run[c : c + size])), constant_values=-1))
    groups = np.array(rows, dtype=np.int32).reshape(-1, size)
    return groups, np.sort(np.concatenate(singles).astype(np.int64))


def siblings_by_key(key: np.ndarray, shareable: np.ndarray) -> Callable[[int, int], np.ndarray | None]:
    """``siblings(start, stop)`` of per_texel_plan: where each shareable texel of tile [start, stop) is the only one
    of its key in the tile (a tile within one slice of the shared parameter), the tile with every shareable texel of
    those keys, so that they form groups; else None (the tile's texels group among themselves, or none can)."""
    pool = np.flatnonzero(shareable)
    pool = pool[np.argsort(key[pool], kind="stable")]
    pool_keys = key[pool]

    def siblings(start: int, stop: int) -> np.ndarray | None:
        own = np.arange(start, stop)[shareable[start:stop]]
        if len(own) == 0 or len(np.unique(key[own])) < len(own):
            return None
        lo, hi = np.searchsorted(pool_keys, key[own], "left"), np.searchsorted(pool_keys, key[own], "right")
        if np.all(hi - lo < 2):
            return None
        return np.union1d(np.arange(start, stop), np.concatenate([pool[a:b] for a, b in zip(lo, hi)]))

    return siblings
