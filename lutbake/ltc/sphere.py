"""The sphere / disk integral table of LTC area lights: the projected solid angle of a spherical cap clipped
to the horizon, divided by the unclipped one (Hill & Heitz 2017, "Real-Time Area Lighting: a Journey from
Research to Production", SIGGRAPH course; ltc_code fit/fitLTC.cpp genSphereTab, texture 2's .w; Blender EEVEE's
ltc_disk_integral).

A polygon's LTC integral without clipping is the length |F| of its vector form factor F = Σ edge vectors
(1/(2 pi) Σ acos(v_i.v_j) normalize(v_i x v_j)); the clipped integral is approximated by that of the sphere cap
with the same form factor: a cap about the direction of F, of half-angle sigma, sin^2 sigma = |F| (the unclipped
form factor of a cap is sin^2 sigma). The table holds, at z = F.z / |F| = cos omega and len = |F|,
    S(z, len) = I(omega, sigma) / (pi len),  I = ∫_cap max(0, cos theta) dω      (so len * S = clipped value)
x = z * 0.5 + 0.5 and y = len, both at endpoint texels i / (N - 1) (ltc_code; shaders sample
uv = (z * 0.5 + 0.5, len) * (N - 1)/N + 0.5/N).

Baked by integration, not by the closed form: in the cap's own frame (polar angle b from its axis, azimuth p),
cos theta = a + c cos p with a = cos omega cos b, c = sin omega sin b, and the azimuthal integral of the
clamped cosine is exact,
    ∫_0^2pi max(0, a + c cos p) dp = 2 pi a (a >= c),  0 (a <= -c),  2 (a p0 + c sin p0), p0 = acos(-a/c) otherwise,
leaving I = ∫_0^sigma J(b) sin b db, done with Gauss-Legendre panels split where the horizon enters and leaves
the cap's rings (b = |pi/2 - omega|). ``snyder_cap`` is Snyder's closed form (ltc_code's ihemi) for the tests.
"""

from __future__ import annotations

import numpy as np

CAP_ORDER = 48  # Gauss-Legendre nodes per panel in the cap's polar angle


def ring_integral(a: np.ndarray, c: np.ndarray) -> np.ndarray:
    """∫_0^2pi max(0, a + c cos p) dp for c >= 0 (exact)."""
    a, c = np.broadcast_arrays(np.asarray(a, np.float64), np.asarray(c, np.float64))
    out = np.where(a >= c, 2.0 * np.pi * a, 0.0)
    mid = (a < c) & (a > -c)
    p0 = np.arccos(np.clip(-a[mid] / c[mid], -1.0, 1.0))
    out[mid] = 2.0 * (a[mid] * p0 + c[mid] * np.sin(p0))
    return out


def cap_projected_solid_angle(omega: np.ndarray, sigma: np.ndarray, order: int = CAP_ORDER) -> np.ndarray:
    """I(omega, sigma) = ∫ over the cap (axis at polar angle omega, half-angle sigma) of max(0, cos theta) dω."""
    omega, sigma = np.broadcast_arrays(np.asarray(omega, np.float64), np.asarray(sigma, np.float64))
    x, w = np.polynomial.legendre.leggauss(order)
    kink = np.abs(np.pi / 2 - omega)
    edges = np.stack([np.zeros_like(sigma), np.minimum(kink, sigma), sigma], axis=-1)
    total = np.zeros(omega.shape)
    for k in range(2):
        lo, hi = edges[..., k], edges[..., k + 1]
        b = 0.5 * (hi - lo)[..., None] * (x + 1.0) + lo[..., None]
        j = ring_integral(np.cos(omega)[..., None] * np.cos(b), np.sin(omega)[..., None] * np.sin(b))
        total += 0.5 * (hi - lo) * np.sum(w * j * np.sin(b), axis=-1)
    return total


def sphere_table(n: int, order: int = CAP_ORDER) -> np.ndarray:
    """S[j, i] at z = 2 i/(n - 1) - 1 (x), len = j/(n - 1) (y); S = max(z, 0) at len = 0 (the limit)."""
    t = np.arange(n) / max(n - 1, 1)
    z, ln = np.meshgrid(2.0 * t - 1.0, t)
    omega = np.arccos(np.clip(z, -1.0, 1.0))
    sigma = np.arcsin(np.sqrt(ln))
    out = np.maximum(z, 0.0).copy()
    pos = ln > 0.0
    out[pos] = cap_projected_solid_angle(omega[pos], sigma[pos], order) / (np.pi * ln[pos])
    return out


def snyder_cap(omega: float, sigma: float) -> float:
    """Snyder 1996's closed form of I(omega, sigma) as ltc_code's ihemi (fitLTC.cpp), for omega in [0, pi]."""
    s2 = np.sin(sigma) ** 2
    if omega <= np.pi / 2 - sigma:
        return np.pi * np.cos(omega) * s2
    if omega >= np.pi / 2 + sigma:
        return 0.0
    g = np.arcsin(np.clip(np.cos(sigma) / np.sin(omega), -1.0, 1.0))
    G = -2.0 * np.sin(omega) * np.cos(sigma) * np.cos(g) + np.pi / 2 - g + np.sin(g) * np.cos(g)
    H = np.cos(omega) * (
        np.cos(g) * np.sqrt(max(s2 - np.cos(g) ** 2, 0.0)) + s2 * np.arcsin(np.clip(np.cos(g) / np.sin(sigma), -1, 1))
    )
    if omega < np.pi / 2:
        return np.pi * np.cos(omega) * s2 + G - H
    return G + H
