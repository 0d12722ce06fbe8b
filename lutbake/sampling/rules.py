"""The host side of the hemisphere's Gauss-Legendre rules: the adaptive orders, the rules of a ladder concatenated on
[0, 1] (gl_levels), region A's inner rule tabulated once (phi_rule_a) and their device arrays (gl_rule_arrays)."""

from __future__ import annotations

import functools

import numpy as np
import warp as wp

from . import points

# the successive product-rule orders of a panel: a ratio of ~1.5 (each level costs ~2.25x the last). Starting lower
# (4, 6, ...) let coincidental agreements of two coarse rules pass (measured: error 1.9e-6 at an estimate 8e-7 on
# the 128^2 dfg; GGX's region-A NDF-peak panel from (4, 6): albedo's inner 4- and 6-point rules erred by 2.6e-7 and
# 3.7e-7, an estimate of 1.1e-7). Gentler climbs (9 -> 11 -> 14 -> 20) replayed 4-7 % cheaper on GGX but let
# Blinn-Phong's 64^2 table pass an error of 2.7e-6 under an estimate of 2.2e-7: orders 9 and 11 agree by chance.
# The outer and the inner rule climb on their own (lutbake.sampling.ladder.product_ladder_for)
ADAPTIVE_ORDERS = (6, 9, 12, 16, 24, 32, 48, 64)
CHECK_ORDER = 8  # the outer check rule of the first pair (lutbake.sampling.ladder.outer_bound: orders 6, 8, 9)
assert (ADAPTIVE_ORDERS[0], CHECK_ORDER, ADAPTIVE_ORDERS[1]) == (6, 8, 9)  # outer_bound's geometric tail assumes them


@functools.lru_cache(maxsize=None)
def gl_levels(orders: tuple[int, ...], kronrod: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """The GL rules of ``orders`` on [0, 1], concatenated ((node, weight) rows), and (offset, order) per order.
    ``kronrod``: the second rule is the Kronrod extension of the first (orders[1] = 2 orders[0] + 1 nodes, the first's
    among them; lutbake.sampling.points.gauss_kronrod), so the first two levels are a Gauss-Kronrod pair."""
    rule = [np.stack(points.gauss_legendre(n), axis=1) for n in orders]
    if kronrod:
        if len(orders) < 2 or orders[1] != 2 * orders[0] + 1:
            raise ValueError(f"a Gauss-Kronrod pair is (n, 2n + 1) nodes, not {orders[:2]}")
        rule[1] = np.stack(points.gauss_kronrod(orders[0])[:2], axis=1)
    rules = np.concatenate(rule)
    offsets = np.cumsum([0] + list(orders[:-1]))
    return rules, np.stack([offsets, orders], axis=1).astype(np.int32)


def phi_rule_a(rules: np.ndarray) -> np.ndarray:
    """Region A's inner rule: phimax = pi and the sinh map's scale eps = pi (make_gauss_legendre) for every texel, so
    its nodes phi_j = pi - pi sinh(A (1 - x_j)), A = asinh(1), and weights w_j pi A cosh(A (1 - x_j)) are computed
    once, here: rows (cos phi_j, sin phi_j, weight), float64."""
    x, w = rules[:, 0], rules[:, 1]
    big_a = np.arcsinh(1.0)
    ex = np.exp(big_a * (1.0 - x))
    phi = np.pi - np.pi * 0.5 * (ex - 1.0 / ex)
    return np.stack([np.cos(phi), np.sin(phi), w * np.pi * 0.5 * (ex + 1.0 / ex) * big_a], axis=1)


@functools.lru_cache(maxsize=None)
def gl_rule_arrays(orders: tuple[int, ...], device: str) -> tuple:
    """(rules, phi_rule_a, levels) of ``orders`` as the kernel's device arrays: made once per (orders, device), not
    per tile (read-only, shared by every launch)."""
    rules, levels = gl_levels(orders)
    return (
        wp.array(rules, dtype=wp.vec2d, device=device),
        wp.array(phi_rule_a(rules), dtype=wp.vec3d, device=device),
        wp.array(levels, dtype=wp.vec2i, device=device),
    )
