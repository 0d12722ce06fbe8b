"""Hemispherical averages over the view cosine mu = n.v, to a tolerance, by adaptive Gauss-Kronrod panels.

    E_avg = 2 ∫_0^1 E(mu) mu dmu          (Kulla & Conty 2017, slide 18: the average of a directional albedo)

per texel of an averaged table (kinds albedo_avg, dielectric_avg), E(mu) the kind's per-texel integral. Each
texel's mu axis starts as the panels between its breakpoints (``starts``: where E(mu) is not analytic, e.g. 0, 0.2,
1); every panel takes the Gauss-Kronrod pair (n, 2n + 1) of lutbake.sampling.points.gauss_kronrod, and
d = |Q_kronrod - Q_gauss| is its estimate (the Gauss rule's error: pessimistic for the Kronrod value, which is
exact to degree 3n + 1 against 2n - 1). While a texel's sum of d exceeds its target (``share`` of max(absolute,
relative |v|) at the first pass's v, the worst channel), its panel with the largest d is bisected (greedy, as
lutbake.sampling.ladder), up to ``max_panels`` panels. A texel's panels are its own: its values do not depend on
which texels share the call (bit-identical for any tiling).

Where E(mu) comes with an error bound per node (an adaptive inner estimator), the inner part of the estimate is
2 ∑ W mu e(mu) over the final panels' Kronrod nodes (the Kronrod weights W are positive): an error e at every node
moves the average by at most its mu-weighted mean.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .points import gauss_kronrod


@dataclass(frozen=True)
class MuAverages:
    """The result for texels t: ``values`` and the mu rule's estimates ``mu_error`` (len(t), C), the inner estimates
    ``inner_error`` (len(t), C; zeros where E came without bounds), ``first_e``: E at each texel's first-panel
    Kronrod nodes (a list per texel, (panels x (2n + 1), C)), and ``panels``: each texel's final panel count."""

    values: np.ndarray
    mu_error: np.ndarray
    inner_error: np.ndarray
    first_e: list[np.ndarray]
    panels: np.ndarray


def mu_target(tol, share: float) -> Callable[[np.ndarray], np.ndarray]:
    """mu_averages' ``target``: ``share`` of max(tol.absolute, tol.relative |v|) at the first pass's values, the
    worst (smallest) channel of each texel."""
    return lambda total: share * np.maximum(tol.absolute, tol.relative * np.min(np.abs(total), axis=1))


def mu_averages(
    e_at: Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray | None]],
    t: np.ndarray,
    starts: list[np.ndarray],
    order: int,
    target: Callable[[np.ndarray], np.ndarray],
    max_panels: int,
) -> MuAverages:
    """2 ∫ E mu dmu at texels ``t`` (module docstring). ``e_at(texels, mu) -> (E (len, C), bounds or None)``: one
    evaluation per (texel, mu) pair; ``starts[j]``: texel t[j]'s first panel ends (ascending, from 0 to 1);
    ``target(first-pass values (len(t), C)) -> (len(t),)``: the mu rule's target per texel."""
    x_mu, w_kronrod, w_gauss = gauss_kronrod(order)
    owner = np.concatenate([[j] * (len(e) - 1) for j, e in enumerate(starts)]).astype(int)
    lo = np.concatenate([e[:-1] for e in starts])
    hi = np.concatenate([e[1:] for e in starts])

    def panel_sums(tt, lo, hi):
        """(kronrod, gauss, inner bound) (len(tt), C) each over the panels [lo, hi] of texels tt (the Gauss nodes are
        Kronrod nodes: 2n + 1 evaluations a panel), and E at the nodes (len(tt), 2n + 1, C)."""
        mu = lo[:, None] + (hi - lo)[:, None] * x_mu
        raw, bound = e_at(np.repeat(tt, len(x_mu)), mu.ravel())
        raw = raw.reshape(len(tt), len(x_mu), -1)
        jac = 2.0 * (hi - lo)[:, None] * mu
        e = raw * jac[:, :, None]
        inner = np.zeros((len(tt), raw.shape[2]))
        if bound is not None:
            inner = np.einsum("tkc,k->tc", bound.reshape(raw.shape) * jac[:, :, None], w_kronrod)
        return np.einsum("tkc,k->tc", e, w_kronrod), np.einsum("tkc,k->tc", e, w_gauss), inner, raw

    panels = [list(zip(lo[owner == j], hi[owner == j])) for j in range(len(t))]
    q, d, b, raw = panel_sums(t[owner], lo, hi)
    first_e = [raw[owner == j] for j in range(len(t))]
    d = np.abs(q - d)
    fine = [list(q[owner == j]) for j in range(len(t))]
    diff = [list(d[owner == j]) for j in range(len(t))]
    inner = [list(b[owner == j]) for j in range(len(t))]
    goal = target(np.array([np.sum(f, axis=0) for f in fine]))
    while True:
        pick = [j for j in range(len(t)) if np.max(np.sum(diff[j], axis=0)) > goal[j] and len(panels[j]) < max_panels]
        if not pick:
            break
        worst = [int(np.argmax(np.max(diff[j], axis=1))) for j in pick]
        a_, b_ = (
            np.array([panels[j][w][0] for j, w in zip(pick, worst)]),
            np.array([panels[j][w][1] for j, w in zip(pick, worst)]),
        )
        m_ = 0.5 * (a_ + b_)
        q, c, b, _ = panel_sums(np.concatenate([t[pick], t[pick]]), np.concatenate([a_, m_]), np.concatenate([m_, b_]))
        c = np.abs(q - c)
        n = len(pick)
        for i, (j, w) in enumerate(zip(pick, worst)):
            panels[j][w : w + 1] = [(a_[i], m_[i]), (m_[i], b_[i])]
            fine[j][w : w + 1] = [q[i], q[n + i]]
            diff[j][w : w + 1] = [c[i], c[n + i]]
            inner[j][w : w + 1] = [b[i], b[n + i]]
    return MuAverages(
        np.array([np.sum(f, axis=0) for f in fine]),
        np.array([np.sum(e, axis=0) for e in diff]),
        np.array([np.sum(e, axis=0) for e in inner]),
        first_e,
        np.array([len(p) for p in panels]),
    )
