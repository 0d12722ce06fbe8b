"""The validation checks' own host quadratures (lutbake.validate.checks): deliberately NOT the estimators of
:mod:`lutbake.sampling`, so that a check does not share an estimator's mistakes. Composite Gauss-Legendre rules
(lutbake.sampling.points' nodes) in plain spherical coordinates (no importance sampling, no change of variables), with
panels graded geometrically towards every point where the integrand changes scale (the NDF peak) or loses smoothness
(a cut where v.m = 0)."""

from __future__ import annotations

import numpy as np

from ..sampling import points

GL_NODES = 16  # Gauss-Legendre nodes per panel
PANEL_RATIO = 2.0  # geometric panel growth away from an anchor
CUT_FIRST_PANEL = 1.0e-6  # first panel width next to a cut (rad)


def graded_edges(lo: float, hi: float, anchors: list[tuple[float, float]]) -> np.ndarray:
    """Panel edges on [lo, hi]: the ends, every anchor a, and a +- first * PANEL_RATIO^j inside [lo, hi]
    for each (a, first) in ``anchors``."""
    pts = [lo, hi]
    for a, first in anchors:
        if not lo <= a <= hi:
            continue
        pts.append(a)
        d = first
        while d < hi - lo:
            pts += [a - d, a + d]
            d *= PANEL_RATIO
    return np.unique(np.clip(np.asarray(pts, dtype=np.float64), lo, hi))


def composite_gl(edges: np.ndarray, n: int = GL_NODES) -> tuple[np.ndarray, np.ndarray]:
    """Composite n-point Gauss-Legendre on the panels between ``edges`` -> (nodes, weights)."""
    x, w = points.gauss_legendre(n)
    a, b = edges[:-1], edges[1:]
    return (a[:, None] + (b - a)[:, None] * x).ravel(), ((b - a)[:, None] * w).ravel()


def direction(theta: np.ndarray, phi: np.ndarray | float = 0.0) -> np.ndarray:
    """The unit vectors (sin theta cos phi, sin theta sin phi, cos theta), shape broadcast(theta, phi) + (3,)."""
    st = np.sin(theta)
    xyz = st * np.cos(phi), st * np.sin(phi), np.cos(theta)
    h = np.empty(np.broadcast_shapes(*(np.shape(c) for c in xyz)) + (3,), np.result_type(*xyz))
    h[..., 0], h[..., 1], h[..., 2] = xyz
    return h


def sphere_quadrature(scale: float, theta_cut: float | None = None, horizon: bool = False):
    """Composite GL nodes in theta on [0, pi/2] graded from the pole at ``scale``, about a cut start if given,
    and towards the horizon if ``horizon`` (where (n.h)^e with a non-integer e is not analytic)."""
    anchors = [(0.0, np.arctan(scale) / 16.0)] + ([(np.pi / 2, CUT_FIRST_PANEL)] if horizon else [])
    if theta_cut is not None:
        anchors.append((theta_cut, CUT_FIRST_PANEL))
    return composite_gl(graded_edges(0.0, np.pi / 2, anchors))
