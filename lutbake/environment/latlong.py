"""The lat-long (equirectangular) source: its direction convention, its texels' exact solid angles, and the
box-filtered pyramid the prefilter's quadrature descends.

**Convention** (y up, the convention of glTF-IBL-Sampler's ``dirToUV`` and of most HDR panoramas): column j of a
W-wide image spans u in [j/W, (j+1)/W], row i of an H-high image spans v in [i/H, (i+1)/H], row 0 at the top, and

    theta = pi v (polar angle from +Y),  phi = 2 pi u - pi,  d = (sin theta cos phi, cos theta, sin theta sin phi)

so u = 0.5 + atan2(z, x) / (2 pi), v = acos(y) / pi; the image centre looks down +X, the left and right edges -X.
The radiance is **texel-constant**: each texel holds the average radiance over its cell (what a box-filtered
capture holds), and every integral lutbake computes is of that piecewise-constant function.

A texel's solid angle is exact: Omega = (phi1 - phi0) (cos theta0 - cos theta1), not its centre's sin theta times
the cell (which is wrong by up to a factor 2 in the polar rows: the polar texel of an H-row image holds
2 sin^2(pi / 4H) x 2 pi / W).
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
    level (row-major). Per texel: ``mean`` (the exact solid-angle-weighted average of the source over the texel's
    cell: sum of L Omega over its source texels / its Omega, so that mean x Omega is the integral of the source
    over the cell at every level), ``low`` and ``high`` (the per-channel minimum and maximum of the source texels in
    the cell). ``heights``/``widths``/``offsets`` per level."""

    mean: np.ndarray  # (N, 3) float64
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


def pyramid(image: np.ndarray) -> Pyramid:
    """The Pyramid of a lat-long image (h, w, 3), w = 2 h: levels halve while the height is even (a power-of-two
    height reaches 1 x 2). Raises ValueError for another aspect or a negative or non-finite value."""
    img = np.asarray(image, np.float64)
    if img.ndim != 3 or img.shape[2] != 3 or img.shape[1] != 2 * img.shape[0]:
        raise ValueError(f"a lat-long source is (h, 2h, 3), got {img.shape}")
    if not np.all(np.isfinite(img)) or np.any(img < 0):
        raise ValueError("a lat-long source holds finite radiance >= 0")
    means, lows, highs = [img], [img], [img]
    while means[-1].shape[0] % 2 == 0:
        m, lo, hi = means[-1], lows[-1], highs[-1]
        h, w = m.shape[:2]
        omega = solid_angles(h, w)[..., None]
        wm = (m * omega).reshape(h // 2, 2, w // 2, 2, 3).sum(axis=(1, 3))
        om = omega.reshape(h // 2, 2, w // 2, 2, 1).sum(axis=(1, 3))
        means.append(wm / om)
        lows.append(lo.reshape(h // 2, 2, w // 2, 2, 3).min(axis=(1, 3)))
        highs.append(hi.reshape(h // 2, 2, w // 2, 2, 3).max(axis=(1, 3)))
    heights = np.array([m.shape[0] for m in means], np.int32)
    widths = 2 * heights
    offsets = np.concatenate([[0], np.cumsum(heights.astype(np.int64) * widths)[:-1]]).astype(np.int32)

    def flat(levels):
        return np.ascontiguousarray(np.concatenate([a.reshape(-1, 3) for a in levels]))

    return Pyramid(flat(means), flat(lows), flat(highs), heights, widths, offsets)
