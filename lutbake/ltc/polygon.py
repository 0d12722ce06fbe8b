"""Polygon-light integrals of an LTC table on the CPU (numpy): what a shader computes, in float64.

In the shading frame (n = +z, v = (sin theta_v, 0, cos theta_v), i.e. ltc_code's (T1, T2, N) with
T1 = normalize(v - n (n.v))), a polygon with vertices p_i (relative to the shading point) is transformed by M^-1,
clipped to the horizon z >= 0 and projected to the unit sphere; the clamped-cosine integral over it is
    I = 1/(2 pi) Σ_edges acos(u_i.u_j) (u_i x u_j).z / |u_i x u_j|          (Heitz et al. 2016, Eq. 11;
                                                                            Lambert's formula, Arvo 1995)
so the fitted lobe's integral over the polygon is magnitude * I (F = 1), and with Schlick Fresnel
(f0 * magnitude + (1 - f0) * fresnel) * I. ``edge_fitted`` is the rational fit of theta / sin theta that
ltc_code's shaders use (IntegrateEdgeVec; Hill & Heitz 2017), for comparing with a GPU.
"""

from __future__ import annotations

import numpy as np


def clip_horizon(poly: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman clip of a polygon (k, 3) to the half-space z >= 0 (0 to k + 1 vertices)."""
    out = []
    k = len(poly)
    for i in range(k):
        a, b = poly[i], poly[(i + 1) % k]
        ina, inb = a[2] >= 0.0, b[2] >= 0.0
        if ina:
            out.append(a)
        if ina != inb:
            t = a[2] / (a[2] - b[2])
            p = a + t * (b - a)
            p[2] = 0.0
            out.append(p)
    return np.array(out).reshape(-1, 3)


def edge_exact(u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """acos(u1.u2) (u1 x u2) / (2 pi |u1 x u2|) for unit vectors (rows): the edge's vector form factor."""
    c = np.cross(u1, u2)
    s = np.linalg.norm(c, axis=-1)
    theta = np.arctan2(s, np.sum(u1 * u2, axis=-1))
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(s > 0.0, theta / np.where(s > 0.0, s, 1.0), 1.0)
    return c * (w / (2.0 * np.pi))[..., None]


def edge_fitted(u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """ltc_code / Hill & Heitz 2017 IntegrateEdgeVec: (u1 x u2) * theta_sintheta, a rational fit of
    theta / (2 pi sin theta) (the 1/(2 pi) is inside the fit: 0.8543985 + ... at u1.u2 = 1 gives 1/(2 pi))."""
    x = np.sum(u1 * u2, axis=-1)
    y = np.abs(x)
    a = 0.8543985 + (0.4965155 + 0.0145206 * y) * y
    b = 3.4175940 + (4.1616724 + y) * y
    v = a / b
    ts = np.where(x > 0.0, v, 0.5 / np.sqrt(np.maximum(1.0 - x * x, 1e-7)) - v)
    return np.cross(u1, u2) * ts[..., None]


def form_factor(poly: np.ndarray, edge=edge_exact) -> float:
    """I = Σ edge(u_i, u_{i+1}).z of the clipped polygon (0 if nothing is above the horizon);
    positive for vertices counter-clockwise seen from the origin."""
    c = clip_horizon(np.asarray(poly, np.float64))
    if len(c) < 3:
        return 0.0
    u = c / np.linalg.norm(c, axis=1, keepdims=True)
    return float(np.sum(edge(u, np.roll(u, -1, axis=0))[:, 2]))


def inverse_matrix(t1: np.ndarray) -> np.ndarray:
    """M^-1 (3, 3) from an ltc_1 texel (x, y, z, w): mat3(vec3(x, 0, y), vec3(0, 1, 0), vec3(z, 0, w)) (GLSL
    columns), i.e. rows (x, 0, z), (0, 1, 0), (y, 0, w)."""
    x, y, z, w = (float(c) for c in t1)
    return np.array([[x, 0.0, z], [0.0, 1.0, 0.0], [y, 0.0, w]])


def bilinear(tex: np.ndarray, u: float, v: float) -> np.ndarray:
    """A GPU's bilinear fetch (clamp to edge) of tex (H, W, C) at normalised (u, v), texel centres at (i + 0.5)/W."""
    h, w = tex.shape[:2]
    x = np.clip(u * w - 0.5, 0.0, w - 1.0)
    y = np.clip(v * h - 0.5, 0.0, h - 1.0)
    x0, y0 = int(np.floor(x)), int(np.floor(y))
    x1, y1 = min(x0 + 1, w - 1), min(y0 + 1, h - 1)
    fx, fy = x - x0, y - y0
    return (1 - fy) * ((1 - fx) * tex[y0, x0] + fx * tex[y0, x1]) + fy * ((1 - fx) * tex[y1, x0] + fx * tex[y1, x1])


def lookup_uv(n: int, roughness: float, nov: float) -> tuple[float, float]:
    """ltc_code's uv = vec2(roughness, sqrt(1 - NoV)) * (N - 1)/N + 0.5/N."""
    s = (n - 1.0) / n
    return roughness * s + 0.5 / n, np.sqrt(max(1.0 - nov, 0.0)) * s + 0.5 / n


def shade(
    ltc_1: np.ndarray,
    ltc_2: np.ndarray,
    roughness: float,
    nov: float,
    poly: np.ndarray,
    f0: float = 1.0,
    edge=edge_exact,
    two_sided: bool = True,
) -> float:
    """(f0 * magnitude + (1 - f0) * fresnel) * I for a polygon in the shading frame, texels fetched bilinearly
    as a GPU does (f0 = 1: the lobe itself, F = 1)."""
    u, v = lookup_uv(ltc_1.shape[1], roughness, nov)
    t1, t2 = bilinear(ltc_1, u, v), bilinear(ltc_2, u, v)
    i = form_factor(np.asarray(poly, np.float64) @ inverse_matrix(t1).T, edge)
    i = abs(i) if two_sided else max(i, 0.0)
    return (f0 * t2[0] + (1.0 - f0) * t2[1]) * i
