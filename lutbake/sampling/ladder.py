"""A texel's integral over panels, each up a ladder of Gauss-Legendre orders, refined greedily to a tolerance.

The orders are ``levels`` (offset, order) into ``rules`` (the concatenated GL rules of
lutbake.sampling.rules.gl_levels). Every panel is integrated at the first two orders; a panel's value is its
finer one, Q_(k), and its error estimate d = |Q_(k) - Q_(k-1)| is the error of the coarser one: with exponential
convergence a bound of Q_(k)'s (the argument of lutbake.sampling.hemisphere_kernels.make_gauss_legendre). Then, while a
channel's estimate sum_p d_p exceeds its target, that channel's panel with the largest d goes one order up (a panel at
the last order stays; of several channels over their targets, the one furthest over). Against a fixed per-panel share
of the tolerance, the texel's error budget goes where the error is: panels far below the tolerance stop at the second
order.

A panel rule that is a product of two one-dimensional rules (the hemisphere's outer theta_h and inner phi rules) climbs
by ``product_ladder_for`` instead: each rule on its own level with its own estimate, so that the two rules' errors,
which can cancel in one product rule's difference, are bounded separately.

``greedy_ladder_for(panel_sum, max_panels, nch)`` closes over the panel rule ``panel_sum(ctx, j, rules, offset, order)
-> value`` (``ctx``: the texel's constants, a Warp struct; ``j``: the panel's index, 0 .. n_panels - 1; an empty
panel returns 0 at every order); the value is a float64 (nch = 1) or a float64 vector of nch channels (vec2d, vec3d),
every channel refined to its own target. (No ``from __future__ import annotations``: Warp reads the kernels' argument
types, local to the factory, from the annotations.)
"""

from typing import Any

import warp as wp

from ..runtime.warp_runtime import kernel_factory
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


# the floor (a relative error the caller adds to the estimate, e.g. float32 terms' rounding, 1e-7 |I|) against the
# tolerance: where the tolerance less the floor is over FLOOR_REACH floors, the quadrature's target is that rest (the
# texel meets its tolerance); below, no affordable order helps, and the quadrature stops at half the floor (the texel
# ends over its tolerance, and says so). A half for both let HDRP's Charlie texel (G = 6.69: floor 6.7e-7 against
# 1e-6) stop at 1.0007 x its tolerance; a tenth for both cost 6x the time of tight bakes (tolerance 1e-8, where the
# floor alone is over it: the 256^2 interpolation test 7.8 -> 48 s)
FLOOR_REACH = wp.constant(wp.float64(0.1))
FLOOR_GIVE_UP = wp.constant(wp.float64(0.5))


@kernel_factory
def furthest_over_for(nch: int):
    """``furthest_over(total, err, target_abs, target_rel, floor)``: the channel c whose estimate err_c is furthest
    over its target max(target_abs_c, target_rel_c |total_c|) - floor |total_c| (where that is FLOOR_REACH floors
    |total_c| or less: FLOOR_GIVE_UP floor |total_c|), -1 when every channel meets its target (float64 vectors of
    nch)."""

    @wp.func
    def furthest_over(total: Any, err: Any, target_abs: Any, target_rel: Any, floor: wp.float64):
        worst_c = wp.int32(-1)
        over = wp.float64(1.0)
        for c in range(wp.static(nch)):
            noise = floor * wp.abs(total[c])
            target = wp.max(target_abs[c], target_rel[c] * wp.abs(total[c])) - noise
            if target <= FLOOR_REACH * noise:  # the floor eats the tolerance: no order helps
                target = FLOOR_GIVE_UP * noise
            if err[c] > target * over:
                worst_c = c
                over = err[c] / wp.max(target, wp.float64(1.0e-300))
        return worst_c

    return furthest_over


@kernel_factory
def totals_for(Sums, nch: int):
    """``totals(q, d, d2, w2, n_panels) -> (total, err)``: per channel, the sum of the panels' values q and of their
    estimates d + w2 d2 (float64 matrices max_panels x nch; w2 = 0: d alone)."""

    @wp.func
    def totals(q: Any, d: Any, d2: Any, w2: wp.float64, n_panels: int):
        total = Sums()
        err = Sums()
        for j in range(n_panels):
            for c in range(wp.static(nch)):
                total[c] = total[c] + q[j, c]
                err[c] = err[c] + d[j, c] + w2 * d2[j, c]
        return total, err

    return totals


@kernel_factory
def greedy_ladder_for(panel_sum, max_panels: int, nch: int = 1, first_level=None):
    """``(integrate, climb, Panels, Sums, Orders)``: ``integrate(ctx, n_panels, rules, levels, target_abs, target_rel,
    floor) -> (total, err)`` (``Sums``: float64 vectors of nch, the targets per channel too): every panel at the
    first two levels, then refined until err_c = sum_p d_(p,c) <= max(target_abs_c, target_rel_c |total_c|) - floor
    |total_c| (furthest_over_for's target) for every channel c (floor: a relative error the caller
    adds to the estimate, e.g. the terms' rounding; an unreachable target, e.g. 1e300, never refines) or every panel
    is at the last order (module docstring); n_panels <= max_panels. ``climb(ctx, n_panels, rules, levels,
    target_abs, target_rel, floor, fine0, coarse0, lev)``: the same from each panel's first two levels' values given
    (``Panels``: float64 matrices max_panels x nch; fine0 at levels[lev[j]], coarse0 at levels[lev[j] - 1];
    ``Orders``: int32 vectors of max_panels), e.g. computed for several texels that share per-node work: the same
    float operations, so the same result. ``first_level(ctx, j) -> k`` (optional): panel j starts at levels k and k
    + 1 instead of the first two (a panel class known to converge fast; clamped to the ladder)."""
    Panels = wp.types.matrix(shape=(max_panels, nch), dtype=wp.float64)
    Sums = wp.types.vector(length=nch, dtype=wp.float64)
    Orders = wp.types.vector(length=max_panels, dtype=wp.int32)  # a panel's level
    furthest_over = furthest_over_for(nch)
    totals = totals_for(Sums, nch)

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
            total, err = totals(q, d, d, wp.float64(0.0), n_panels)
            worst_c = furthest_over(total, err, target_abs, target_rel, floor)
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


@wp.func
def outer_bound(d_coarse: wp.float64, d_check: wp.float64):
    """The error estimate of the outer rule Q_n1 from d_coarse = |Q_n1 - Q_n0| and d_check = |Q_n1 - Q_nc| (n0 < nc
    < n1 = nc + 1: the check rule one order below; 6, 8, 9 in lutbake.sampling.hemisphere): their maximum (two null
    rules: both vanish only if two coarse rules agree with Q_n1 by chance, Berntsen & Espelid 1991; Gonnet 2012,
    "A review of error estimation in adaptive quadrature", Sec. 2.5), and at least the geometric tail of Q_n1's own
    error. A Gauss-Legendre rule on an integrand analytic in a Bernstein ellipse errs by e_n ~ C s^n, s < 1
    (Trefethen 2008, "Is Gauss quadrature better than Clenshaw-Curtis?", Thm. 4.5), so d_check / d_coarse = R =
    s^2 / (1 + s + s^2) at (6, 8, 9), which gives s, and e_9 = d_coarse s^3 / (1 - s^3): more than d_coarse where
    s^3 > 1/2 (a slow convergence, a singularity near the panel: measured 5.5e-10, 3.7e-10, 3.0e-10 at orders 6, 8,
    9, d_coarse 2.5e-10). R >= 1/3 is no geometric convergence yet: the two differences' maximum, and the panel, at
    that size, climbs."""
    d = wp.max(d_coarse, d_check)
    if d_coarse > wp.float64(0.0):
        r = d_check / d_coarse
        if r < wp.float64(1.0) / wp.float64(3.0):
            s = (r + wp.sqrt(r * r + wp.float64(4.0) * r * (wp.float64(1.0) - r))) / (
                wp.float64(2.0) * (wp.float64(1.0) - r)
            )
            s3 = s * s * s
            d = wp.max(d, d_coarse * s3 / (wp.float64(1.0) - s3))
    return d


@kernel_factory
def product_ladder_for(panel_sum, max_panels: int, nch: int = 1, check: bool = False):
    """``integrate(ctx, n_panels, rules, levels, target_abs, target_rel, floor) -> (total, err)`` as
    greedy_ladder_for's, for a panel rule that is a product of two one-dimensional rules (an outer variable and an
    inner one), each on its own level: ``panel_sum(ctx, j, rules, offset_outer, order_outer, offset_inner,
    order_inner) -> value``.

    A product rule's error is the sum of its two rules' errors (Q_o x Q_i - I x I = (Q_o - I) x Q_i + I x (Q_i - I)),
    and the two can cancel: measured on make luts' tables, a panel's 6 x 6 rule erred by 5e-7 where its outer rule
    alone erred by -3.0e-6 and its inner one by +3.5e-6, while the 9 x 9 rule erred by 7e-7; |Q(9, 9) - Q(6, 6)| =
    2e-7 passed an error of 7e-7. So each rule's error is estimated on its own, by the difference of two of its
    levels at the other's level fixed, and the panel's estimate is their sum (the triangle inequality: no
    cancellation between them): every panel at Q(k, k), Q(k+1, k), Q(k+1, k+1) (the first two levels; outer, inner),
    d_o = |Q(k+1, k) - Q(k, k)|, d_i = |Q(k+1, k+1) - Q(k+1, k)|, the panel's value the last. While a channel's
    estimate sum_p (d_o + d_i) exceeds its target (greedy_ladder_for's), the panel and variable with the largest d in
    that channel goes one level up (its d: the difference of that step); a variable at the last level stays."""
    Panels = wp.types.matrix(shape=(max_panels, nch), dtype=wp.float64)
    Sums = wp.types.vector(length=nch, dtype=wp.float64)
    Orders = wp.types.vector(length=max_panels, dtype=wp.int32)
    furthest_over = furthest_over_for(nch)
    totals = totals_for(Sums, nch)

    @wp.func
    def integrate(
        ctx: Any, n_panels: int, rules: Rule, levels: Levels, target_abs: Sums, target_rel: Sums, floor: wp.float64
    ):
        q = Panels()
        d_o = Panels()  # the outer rule's error estimate
        d_i = Panels()  # the inner rule's
        lev_o = Orders()
        lev_i = Orders()
        last = levels.shape[0] - 1
        chk = last  # the check rule (``check``: the last of several levels)
        if wp.static(check) and last > 0:
            last = last - 1
        top = wp.min(1, last)
        for j in range(n_panels):
            coarse = panel_sum(ctx, j, rules, levels[0][0], levels[0][1], levels[0][0], levels[0][1])
            mixed = coarse  # one level: the fixed rule, no estimate
            fine = coarse
            other = coarse  # the outer check rule's (none: the coarse one, adding nothing)
            if top > 0:
                mixed = panel_sum(ctx, j, rules, levels[top][0], levels[top][1], levels[0][0], levels[0][1])
                fine = panel_sum(ctx, j, rules, levels[top][0], levels[top][1], levels[top][0], levels[top][1])
                if wp.static(check):
                    other = panel_sum(ctx, j, rules, levels[chk][0], levels[chk][1], levels[0][0], levels[0][1])
            for c in range(wp.static(nch)):
                q[j, c] = channel(fine, c)
                d_o[j, c] = wp.abs(channel(mixed, c) - channel(coarse, c))
                if wp.static(check):
                    d_o[j, c] = outer_bound(d_o[j, c], wp.abs(channel(mixed, c) - channel(other, c)))
                d_i[j, c] = wp.abs(channel(fine, c) - channel(mixed, c))
            lev_o[j] = top
            lev_i[j] = top
        total, err = totals(q, d_o, d_i, wp.float64(1.0), n_panels)
        worst_c = furthest_over(total, err, target_abs, target_rel, floor)
        while worst_c >= 0:
            worst = wp.int32(-1)  # its panel and variable (outer: True) with the largest d that can still go up
            outer = wp.bool(False)
            best = wp.float64(-1.0)
            for j in range(n_panels):
                if lev_o[j] < last and d_o[j, worst_c] > best:
                    worst = j
                    outer = True
                    best = d_o[j, worst_c]
                if lev_i[j] < last and d_i[j, worst_c] > best:
                    worst = j
                    outer = False
                    best = d_i[j, worst_c]
            if worst < 0:
                worst_c = wp.int32(-1)
            else:
                ko = lev_o[worst]
                ki = lev_i[worst]
                if outer:
                    ko = ko + 1
                else:
                    ki = ki + 1
                fine = panel_sum(ctx, worst, rules, levels[ko][0], levels[ko][1], levels[ki][0], levels[ki][1])
                for c in range(wp.static(nch)):
                    step = wp.abs(channel(fine, c) - q[worst, c])
                    if outer:
                        d_o[worst, c] = step
                    else:
                        d_i[worst, c] = step
                    q[worst, c] = channel(fine, c)
                lev_o[worst] = ko
                lev_i[worst] = ki
                total, err = totals(q, d_o, d_i, wp.float64(1.0), n_panels)
                worst_c = furthest_over(total, err, target_abs, target_rel, floor)
        return total, err

    return integrate
