"""A texel's integral over panels, each up a ladder of Gauss-Legendre orders, refined greedily to a tolerance.

The orders are ``levels`` (offset, order) into ``rules`` (the concatenated GL rules of
lutbake.sampling.hemisphere.gl_levels). Every panel is integrated at the first two orders; a panel's value is its
finer one, Q_(k), and its error estimate d = |Q_(k) - Q_(k-1)| is the error of the coarser one: with exponential
convergence a bound of Q_(k)'s (the argument of lutbake.sampling.hemisphere.make_gauss_legendre). Then, while the
texel's estimate sum_p d_p exceeds its target, the panel with the largest d goes one order up (a panel at the last
order stays). Against a fixed per-panel share of the tolerance (make_gauss_legendre), the texel's error budget goes
where the error is: panels far below the tolerance stop at the second order.

``greedy_ladder_for(panel_sum, max_panels)`` closes over the panel rule ``panel_sum(ctx, j, rules, offset, order)
-> float64`` (``ctx``: the texel's constants, a Warp struct; ``j``: the panel's index, 0 .. n_panels - 1; an empty
panel returns 0 at every order).
"""

from __future__ import annotations

import functools
from typing import Any

import warp as wp

from .arrays import Levels, Rule


@functools.lru_cache(maxsize=None)
def greedy_ladder_for(panel_sum, max_panels: int):
    """``(integrate, climb, Values)``: ``integrate(ctx, n_panels, rules, levels, target_abs, target_rel) ->
    vec2d(sum_p Q_p, sum_p d_p)``: every panel at the first two levels, then refined until
    sum_p d_p <= max(target_abs, target_rel |sum_p Q_p|) or every panel is at the last order (module docstring);
    n_panels <= max_panels. ``climb(ctx, n_panels, rules, levels, vec2d(target_abs, target_rel), fine0, coarse0)``:
    the same from the first two levels' panel values given (``Values``: float64 vectors of max_panels; fine0 at
    levels[1], coarse0 at levels[0]), e.g. computed for several texels that share per-node work: the same float
    operations, so the same result."""
    Values = wp.types.vector(length=max_panels, dtype=wp.float64)
    Orders = wp.types.vector(length=max_panels, dtype=wp.int32)  # a panel's level

    @wp.func
    def climb(ctx: Any, n_panels: int, rules: Rule, levels: Levels, targets: wp.vec2d, fine0: Values, coarse0: Values):
        # every panel at the first two levels: fine0 (levels[top]), coarse0 (levels[0]); targets: (abs, rel)
        q = Values()
        d = Values()
        lev = Orders()
        total = wp.float64(0.0)
        err = wp.float64(0.0)
        last = levels.shape[0] - 1
        top = wp.min(1, last)
        for j in range(n_panels):
            q[j] = fine0[j]
            d[j] = wp.abs(fine0[j] - coarse0[j])
            lev[j] = top
            total = total + q[j]
            err = err + d[j]
        while err > wp.max(targets[0], targets[1] * wp.abs(total)):
            worst = wp.int32(-1)  # the panel with the largest d that can still go up
            for j in range(n_panels):
                if lev[j] < last:
                    if worst < 0:
                        worst = j
                    elif d[j] > d[worst]:
                        worst = j
            if worst < 0:
                break
            k = lev[worst] + 1
            fine = panel_sum(ctx, worst, rules, levels[k][0], levels[k][1])
            d[worst] = wp.abs(fine - q[worst])
            q[worst] = fine
            lev[worst] = k
            total = wp.float64(0.0)
            err = wp.float64(0.0)
            for j in range(n_panels):
                total = total + q[j]
                err = err + d[j]
        return wp.vec2d(total, err)

    @wp.func
    def integrate(
        ctx: Any,
        n_panels: int,
        rules: Rule,
        levels: Levels,
        target_abs: wp.float64,
        target_rel: wp.float64,
    ):
        fine0 = Values()
        coarse0 = Values()
        top = wp.min(1, levels.shape[0] - 1)
        for j in range(n_panels):
            fine0[j] = panel_sum(ctx, j, rules, levels[top][0], levels[top][1])
            coarse0[j] = fine0[j]  # one order: the fixed rule, no estimate
            if top > 0:
                coarse0[j] = panel_sum(ctx, j, rules, levels[0][0], levels[0][1])
        return climb(ctx, n_panels, rules, levels, wp.vec2d(target_abs, target_rel), fine0, coarse0)

    return integrate, climb, Values


@functools.lru_cache(maxsize=None)
def greedy_ladder_channels_for(panel_sum, max_panels: int, nch: int):
    """``integrate(ctx, n_panels, rules, levels, target_abs, target_rel) -> (sum_p Q_p, sum_p d_p)``: the greedy
    ladder of ``greedy_ladder_for`` for a ``panel_sum`` that returns ``nch`` channels (a float64 vector), per channel
    c until sum_p d_pc <= max(target_abs[c], target_rel[c] |sum_p Q_pc|) (targets: float64 vectors of nch; a channel
    with an unreachable target, e.g. 1e300, never refines). Each step takes the channel furthest over its target
    (largest sum_p d_pc / target_c) and raises its panel with the largest d_pc."""
    Vec = wp.types.vector(length=nch, dtype=wp.float64)
    Table = wp.types.matrix(shape=(max_panels, nch), dtype=wp.float64)
    Orders = wp.types.vector(length=max_panels, dtype=wp.int32)  # a panel's level

    @wp.func
    def integrate(ctx: Any, n_panels: int, rules: Rule, levels: Levels, target_abs: Vec, target_rel: Vec):
        q = Table()
        d = Table()
        lev = Orders()
        last = levels.shape[0] - 1
        top = wp.min(1, last)
        for j in range(n_panels):
            fine = panel_sum(ctx, j, rules, levels[top][0], levels[top][1])
            coarse = fine  # one order: the fixed rule, no estimate
            if top > 0:
                coarse = panel_sum(ctx, j, rules, levels[0][0], levels[0][1])
            for c in range(nch):
                q[j, c] = fine[c]
                d[j, c] = wp.abs(fine[c] - coarse[c])
            lev[j] = top
        total = Vec()
        err = Vec()
        going = wp.int32(1)
        while going == 1:
            total = Vec()
            err = Vec()
            for j in range(n_panels):
                for c in range(nch):
                    total[c] = total[c] + q[j, c]
                    err[c] = err[c] + d[j, c]
            worst_c = wp.int32(-1)  # the channel furthest over its target
            over = wp.float64(1.0)
            for c in range(nch):
                r = err[c] / wp.max(wp.max(target_abs[c], target_rel[c] * wp.abs(total[c])), wp.float64(1.0e-300))
                if r > over:
                    over = r
                    worst_c = c
            worst = wp.int32(-1)  # its panel with the largest d that can still go up
            if worst_c >= 0:
                for j in range(n_panels):
                    if lev[j] < last:
                        if worst < 0:
                            worst = j
                        elif d[j, worst_c] > d[worst, worst_c]:
                            worst = j
            if worst < 0:
                going = 0
            else:
                k = lev[worst] + 1
                fine = panel_sum(ctx, worst, rules, levels[k][0], levels[k][1])
                for c in range(nch):
                    d[worst, c] = wp.abs(fine[c] - q[worst, c])
                    q[worst, c] = fine[c]
                lev[worst] = k
        return total, err

    return integrate, Vec
