"""The lat-long (equirectangular) source: its direction convention, its texels' exact solid angles, and the
box-filtered pyramid the prefilter's quadrature descends.

**Convention** (y up, the convention of glTF-IBL-Sampler's ``dirToUV`` and of most HDR panoramas): column j of a
W-wide image spans u in [j/W, (j+1)/W], row i of an H-high image spans v in [i/H, (i+1)/H], row 0 at the top, and

    theta = pi v (polar angle from +Y),  phi = 2 pi u - pi,  d = (sin theta cos phi, cos theta, sin theta sin phi)

so u = 0.5 + atan2(z, x) / (2 pi), v = acos(y) / pi; the image centre looks down +X, the left and right edges -X.
The radiance is **texel-constant**: each texel holds the average radiance over its cell (what a box-filtered
capture holds), and every integral lutbake computes is of that piecewise-constant function.

A texel's solid angle is exact: Omega = (phi1 - phi0) (cos theta0 - cos theta1) = 2 sin(theta_c) sin(dtheta / 2) dphi,
not its centre's sin(theta_c) dtheta dphi (short by the factor sinc(dtheta / 2) in every row).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def directions(theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Unit directions (..., 3) of polar angle theta (from +Y) and azimuth phi (the convention above)."""
    st = np.sin(theta)
    return np.stack(np.broadcast_arrays(st * np.cos(phi), np.cos(theta), st * np.sin(phi)), axis=-1)


def angles(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(theta, phi) of directions ``d`` (..., 3): theta = acos(y / |d|), phi = atan2(z, x)."""
    d = np.asarray(d, np.float64)
    r = np.linalg.norm(d, axis=-1)
    return np.arccos(np.clip(d[..., 1] / r, -1.0, 1.0)), np.arctan2(d[..., 2], d[..., 0])


def row_edges(h: int) -> np.ndarray:
    """theta at the h + 1 row edges."""
    return np.pi * np.arange(h + 1) / h


def column_edges(w: int) -> np.ndarray:
    """phi at the w + 1 column edges."""
    return 2.0 * np.pi * np.arange(w + 1) / w - np.pi


def solid_angles(h: int, w: int) -> np.ndarray:
    """(h, w) exact texel solid angles: (2 pi / w)(cos theta0 - cos theta1), summing to 4 pi."""
    t = row_edges(h)
    band = np.cos(t[:-1]) - np.cos(t[1:])
    return np.repeat((2.0 * np.pi / w) * band[:, None], w, axis=1)


def lookup(image: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The texel-constant radiance of ``image`` (h, w, C) in directions ``d`` (..., 3): the texel that holds each."""
    h, w = image.shape[:2]
    theta, phi = angles(d)
    i = np.clip((theta / np.pi * h).astype(np.int64), 0, h - 1)
    j = np.clip(((phi + np.pi) / (2 * np.pi) * w).astype(np.int64), 0, w - 1)
    return image[i, j]


@dataclass(frozen=True, eq=False)  # hashed by identity: its device copies are cached per pyramid
class Pyramid:
    """Levels 0 (the source) to L - 1 of a lat-long image, each halving both dimensions, flattened level after
    level (row-major). Per cell:

    - ``mean``: the exact solid-angle-weighted average of the source over the cell (sum of L Omega over its source
      texels / its Omega), so that mean x Omega is the integral of the source over the cell at every level;
    - ``slope_theta``, ``slope_phi``: the least-squares linear model of the source over the cell in L2(dω),
      L(theta, phi) ~ c0 + c_theta u + c_phi v, u = (theta - theta_c) / dtheta, v = (phi - phi_c) / dphi in
      [-1/2, 1/2] (theta_c, phi_c the cell's middle): c0, c_theta, c_phi solve the normal equations with the cell's
      exact moments (∫ L, ∫ L u, ∫ L v and the Gram matrix of 1, u, v under dω, in closed form per source texel). The
      model keeps ∫ L dω and the first moments ∫ L u dω, ∫ L v dω exact, so a smooth weight's linear part is
      integrated exactly against it; level 0 has zero slopes (the source is texel-constant). ``c0`` is stored as
      ``offset`` (it differs from the mean where sin theta tilts the cell's measure);
    - ``low``, ``high``: the per-channel minimum and maximum of the source texels in the cell.
    ``heights``/``widths``/``offsets`` per level."""

    mean: np.ndarray  # (N, 3) float64
    offset: np.ndarray
    slope_theta: np.ndarray
    slope_phi: np.ndarray
    low: np.ndarray
    high: np.ndarray
    heights: np.ndarray  # (L,) int32
    widths: np.ndarray
    offsets: np.ndarray

    @property
    def levels(self) -> int:
        return len(self.heights)

    def level(self, k: int, which: str = "mean") -> np.ndarray:
        """Level k of ``which`` as (h, w, 3)."""
        a = getattr(self, which)
        h, w, o = int(self.heights[k]), int(self.widths[k]), int(self.offsets[k])
        return a[o : o + h * w].reshape(h, w, 3)


def _block_sum(a: np.ndarray, k: int) -> np.ndarray:
    """Sums of a (h, w, ...) array over 2^k x 2^k blocks."""
    f = 1 << k
    h, w = a.shape[:2]
    return a.reshape(h // f, f, w // f, f, *a.shape[2:]).sum(axis=(1, 3))


def _linear_models(img: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(c0, c_theta, c_phi) of every cell of level k (Pyramid): each (h_k, w_k, 3)."""
    h, w = img.shape[:2]
    t, p = row_edges(h), column_edges(w)
    band = np.cos(t[:-1]) - np.cos(t[1:])  # ∫ sin
    t_moment = np.diff(np.sin(t) - t * np.cos(t))  # ∫ theta sin dtheta
    dphi = 2 * np.pi / w
    omega = (dphi * band)[:, None] * np.ones((1, w))
    L_omega = img * omega[..., None]
    L_theta = img * (dphi * t_moment)[:, None, None]  # ∫ L theta dω per texel
    L_phi = L_omega * ((p[:-1] + p[1:]) / 2)[None, :, None]  # ∫ L phi dω
    b0, bt, bp = (_block_sum(a, k) for a in (L_omega, L_theta, L_phi))
    hk, wk = h >> k, w >> k
    T, P = row_edges(hk), column_edges(wk)
    Dt, Dp = np.pi / hk, 2 * np.pi / wk
    tc, pc = (T[:-1] + T[1:]) / 2, (P[:-1] + P[1:]) / 2
    # the Gram matrix of (1, u, v) over a cell; the v-row decouples (sin theta does not depend on phi)
    s0 = np.cos(T[:-1]) - np.cos(T[1:])
    s1 = np.diff(np.sin(T) - T * np.cos(T))
    s2 = np.diff(2 * T * np.sin(T) - (T * T - 2) * np.cos(T))
    g11 = Dp * s0
    g1u = Dp * (s1 - tc * s0) / Dt
    guu = Dp * (s2 - 2 * tc * s1 + tc * tc * s0) / (Dt * Dt)
    gvv = s0 * Dp / 12
    bu = (bt - tc[:, None, None] * b0) / Dt
    bv = (bp - pc[None, :, None] * b0) / Dp
    det = (g11 * guu - g1u * g1u)[:, None, None]
    c0 = (guu[:, None, None] * b0 - g1u[:, None, None] * bu) / det
    cu = (g11[:, None, None] * bu - g1u[:, None, None] * b0) / det
    cv = bv / gvv[:, None, None]
    return c0, cu, cv


def pyramid(image: np.ndarray) -> Pyramid:
    """The Pyramid of a lat-long image (h, w, 3), w = 2 h: levels halve while the height is even (a power-of-two
    height reaches 1 x 2). Raises ValueError for another aspect or a negative or non-finite value."""
    img = np.asarray(image, np.float64)
    if img.ndim != 3 or img.shape[2] != 3 or img.shape[1] != 2 * img.shape[0]:
        raise ValueError(f"a lat-long source is (h, 2h, 3), got {img.shape}")
    if not np.all(np.isfinite(img)) or np.any(img < 0):
        raise ValueError("a lat-long source holds finite radiance >= 0")
    h = img.shape[0]
    levels = 1 + next(k for k in range(64) if (h >> k) % 2 or (h >> k) == 1)
    omega = solid_angles(*img.shape[:2])[..., None]
    means, models, lows, highs = [], [], [], []
    for k in range(levels):
        means.append(_block_sum(img * omega, k) / _block_sum(omega, k))
        zero = np.zeros_like(means[-1])
        models.append((means[-1], zero, zero) if k == 0 else _linear_models(img, k))
        f = 1 << k
        blocks = img.reshape(h >> k, f, img.shape[1] >> k, f, 3)
        lows.append(blocks.min(axis=(1, 3)))
        highs.append(blocks.max(axis=(1, 3)))
    heights = np.array([m.shape[0] for m in means], np.int32)
    widths = 2 * heights
    offsets = np.concatenate([[0], np.cumsum(heights.astype(np.int64) * widths)[:-1]]).astype(np.int32)

    def flat(levels):
        return np.ascontiguousarray(np.concatenate([a.reshape(-1, 3) for a in levels]))

    return Pyramid(
        flat(means),
        *(flat([m[i] for m in models]) for i in range(3)),
        flat(lows),
        flat(highs),
        heights,
        widths,
        offsets,
    )
