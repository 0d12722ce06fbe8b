"""A texel's integral over panels, each up a ladder of Gauss-Legendre orders, refined greedily to a tolerance.

The orders are ``levels`` (offset, order) into ``rules`` (the concatenated GL rules of
lutbake.sampling.hemisphere.gl_levels). Every panel is integrated at the first two orders; a panel's value is its
finer one, Q_(k), and its error estimate d = |Q_(k) - Q_(k-1)| is the error of the coarser one: with exponential
convergence a bound of Q_(k)'s (the argument of lutbake.sampling.hemisphere.make_gauss_legendre). Then, while a
channel's estimate sum_p d_p exceeds its target, that channel's panel with the largest d goes one order up (a panel at
the last order stays; of several channels over their targets, the one furthest over). Against a fixed per-panel share
of the tolerance, the texel's error budget goes where the error is: panels far below the tolerance stop at the second
order.

``greedy_ladder_for(panel_sum, max_panels, nch)`` closes over the panel rule ``panel_sum(ctx, j, rules, offset, order)
-> value`` (``ctx``: the texel's constants, a Warp struct; ``j``: the panel's index, 0 .. n_panels - 1; an empty
panel returns 0 at every order); the value is a float64 (nch = 1) or a float64 vector of nch channels (vec2d, vec3d),
every channel refined to its own target. (No ``from __future__ import annotations``: Warp reads the kernels' argument
types, local to the factory, from the annotations.)
"""

import functools
from typing import Any

import warp as wp

from .arrays import Levels, Rule


@wp.func
def channel(x: wp.float64, c: int):
    """Channel c of a panel value: the value itself for a scalar."""
    return x


@wp.func
def channel(x: wp.vec2d, c: int):  # noqa: F811 (a Warp overload)
    return x[c]


@wp.func
def channel(x: wp.vec3d, c: int):  # noqa: F811 (a Warp overload)
    return x[c]


@wp.func
def channel(x: wp.vec4d, c: int):  # noqa: F811 (a Warp overload)
    return x[c]


@functools.lru_cache(maxsize=None)
def greedy_ladder_for(panel_sum, max_panels: int, nch: int = 1, first_level=None):
    """``(integrate, climb, Panels, Sums, Orders)``: ``integrate(ctx, n_panels, rules, levels, target_abs, target_rel,
    floor) -> (total, err)`` (``Sums``: float64 vectors of nch, the targets per channel too): every panel at the first
    two levels, then refined until err_c = sum_p d_(p,c) <= max(target_abs_c, target_rel_c |total_c|) - floor
    |total_c| (but at least floor |total_c| / 2) for every channel c (floor: a relative error the caller adds to the
    estimate, e.g. the terms' rounding;
    an unreachable target, e.g. 1e300, never refines) or every panel is at the last order (module docstring);
    n_panels <= max_panels. ``climb(ctx, n_panels, rules, levels, target_abs, target_rel, floor, fine0, coarse0,
    lev)``: the same from each panel's first two levels' values given (``Panels``: float64 matrices max_panels x nch;
    fine0 at levels[lev[j]], coarse0 at levels[lev[j] - 1]; ``Orders``: int32 vectors of max_panels), e.g. computed
    for several texels that share per-node work: the same float operations, so the same result.
    ``first_level(ctx, j) -> k`` (optional): panel j starts at levels k and k + 1 instead of the first two (a panel
    class known to converge fast; clamped to the ladder)."""
    Panels = wp.types.matrix(shape=(max_panels, nch), dtype=wp.float64)
    Sums = wp.types.vector(length=nch, dtype=wp.float64)
    Orders = wp.types.vector(length=max_panels, dtype=wp.int32)  # a panel's level

    @wp.func
    def climb(
        ctx: Any,
        n_panels: int,
        rules: Rule,
        levels: Levels,
        target_abs: Sums,
        target_rel: Sums,
        floor: wp.float64,
        fine0: Panels,
        coarse0: Panels,
        lev: Orders,
    ):
        q = Panels()
        d = Panels()
        last = levels.shape[0] - 1
        for j in range(n_panels):
            for c in range(wp.static(nch)):
                q[j, c] = fine0[j, c]
                d[j, c] = wp.abs(fine0[j, c] - coarse0[j, c])
        total = Sums()
        err = Sums()
        climbing = wp.bool(True)  # a dynamic variable (Warp: a bare literal is a constant)
        while climbing:
            total = Sums()
            err = Sums()
            for j in range(n_panels):
                for c in range(wp.static(nch)):
                    total[c] = total[c] + q[j, c]
                    err[c] = err[c] + d[j, c]
            worst_c = wp.int32(-1)  # the channel furthest over its target
            over = wp.float64(1.0)
            for c in range(wp.static(nch)):
                # a floor over the tolerance (float32 noise) leaves the quadrature half of it: beyond, no order helps
                target = wp.max(
                    wp.max(target_abs[c], target_rel[c] * wp.abs(total[c])) - floor * wp.abs(total[c]),
                    wp.float64(0.5) * floor * wp.abs(total[c]),
                )
                if err[c] > target * over:
                    worst_c = c
                    over = err[c] / wp.max(target, wp.float64(1.0e-300))
            worst = wp.int32(-1)  # its panel with the largest d that can still go up
            if worst_c >= 0:
                for j in range(n_panels):
                    if lev[j] < last:
                        if worst < 0:
                            worst = j
                        elif d[j, worst_c] > d[worst, worst_c]:
                            worst = j
            if worst < 0:
                climbing = False
            else:
                k = lev[worst] + 1
                fine = panel_sum(ctx, worst, rules, levels[k][0], levels[k][1])
                for c in range(wp.static(nch)):
                    d[worst, c] = wp.abs(channel(fine, c) - q[worst, c])
                    q[worst, c] = channel(fine, c)
                lev[worst] = k
        return total, err

    @wp.func
    def integrate(
        ctx: Any, n_panels: int, rules: Rule, levels: Levels, target_abs: Sums, target_rel: Sums, floor: wp.float64
    ):
        fine0 = Panels()
        coarse0 = Panels()
        lev = Orders()
        last = levels.shape[0] - 1
        for j in range(n_panels):
            k = wp.int32(0)  # the panel's coarse level
            if wp.static(first_level is not None):
                k = wp.clamp(first_level(ctx, j), 0, wp.max(last - 1, 0))
            top = wp.min(k + 1, last)
            coarse = panel_sum(ctx, j, rules, levels[k][0], levels[k][1])
            fine = coarse  # one order: the fixed rule, no estimate
            if top > k:
                fine = panel_sum(ctx, j, rules, levels[top][0], levels[top][1])
            for c in range(wp.static(nch)):
                fine0[j, c] = channel(fine, c)
                coarse0[j, c] = channel(coarse, c)
            lev[j] = top
        return climb(ctx, n_panels, rules, levels, target_abs, target_rel, floor, fine0, coarse0, lev)

    return integrate, climb, Panels, Sums, Orders
