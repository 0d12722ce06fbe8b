"""Random polygon lights in the shading frame (n = +z, v = (sin theta_v, 0, cos theta_v)): the area-light benchmark's
lights (lutbake.validate.ltc_bench) and the shaded fit's training lights (lutbake.ltc.shaded) are drawn by this one
generator from different seeds.

A light is a planar quad or triangle at distance 1 from the shading point, stored as 4 vertices (a triangle repeats
its last vertex: a zero-length edge adds nothing to an edge integral and passes every inside test), oriented
counter-clockwise seen from the shading point (p0 . (p1 x p2) > 0). Its centre direction is, with probability
``P_MIRROR``, the mirror direction reflect(v, n) turned by a random angle of the order of the lobe's width, else
uniform in solid angle over the sphere above ``ELEVATION_MIN``; its angular radius is log-uniform in
[``RADIUS_MIN``, ``RADIUS_MAX``] (a small light to one covering most of the hemisphere); quads have a random aspect
ratio and roll, and every light's normal is tilted away from the shading point by up to ``TILT_MAX``. Lights whose
every vertex lies below the horizon are drawn again; lights partly below it are kept (the shader clips them).
"""

from __future__ import annotations

import numpy as np

P_MIRROR = 0.5
P_QUAD = 0.6
ELEVATION_MIN = np.radians(-20.0)  # centre directions down to 20 degrees below the horizon
RADIUS_MIN, RADIUS_MAX = 0.03, 1.3  # angular radius, radians
TILT_MAX = np.radians(50.0)
ASPECT_MIN = 0.3


UNIFORMS = 10  # uniform numbers per light


def _frame(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents orthogonal to the unit vectors n (..., 3)."""
    a = np.where(np.abs(n[..., :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1, axis=-1, keepdims=True)
    return t1, np.cross(n, t1)


def _rot(c, s, a, b):
    return c[..., None] * a + s[..., None] * b


def from_uniforms(u: np.ndarray, v: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """Lights (..., 4, 3) from uniform numbers u (..., UNIFORMS) in [0, 1) for views v (..., 3) and NDF alphas
    (...,) (broadcast): a deterministic map, so a texel's lights depend only on its inputs and the numbers."""
    shape = np.broadcast_shapes(u.shape[:-1], np.shape(v)[:-1], np.shape(alpha))
    u = np.broadcast_to(u, shape + u.shape[-1:])
    v = np.broadcast_to(v, shape + (3,))
    alpha = np.broadcast_to(alpha, shape)
    r = v * np.array([-1.0, -1.0, 1.0])  # reflect(v, n)
    mirror = u[..., 0] < P_MIRROR
    # around the mirror direction: an exponentially distributed angle of mean ~ the lobe's width, up to 80 degrees
    spread = np.minimum(-np.log1p(-u[..., 1]) * (2.0 * alpha + 0.05), 1.4)
    t1, t2 = _frame(r)
    phi = 2 * np.pi * u[..., 2]
    c_m = _rot(np.cos(spread), np.sin(spread), r, _rot(np.cos(phi), np.sin(phi), t1, t2))
    z = np.sin(ELEVATION_MIN) + (1.0 - np.sin(ELEVATION_MIN)) * u[..., 3]  # (phi as above: one of c_m, c_u is kept)
    s = np.sqrt(1 - z * z)
    c_u = np.stack([s * np.cos(phi), s * np.sin(phi), z], -1)
    c = np.where(mirror[..., None], c_m, c_u)
    c /= np.linalg.norm(c, axis=-1, keepdims=True)
    rho = np.exp(np.log(RADIUS_MIN) + (np.log(RADIUS_MAX) - np.log(RADIUS_MIN)) * u[..., 4])
    half = np.tan(rho)  # half-size of the light at distance 1
    # the light's normal: towards the shading point, tilted
    a1, a2 = _frame(-c)
    tilt, tphi = TILT_MAX * u[..., 5], 2 * np.pi * u[..., 6]
    nl = _rot(np.cos(tilt), np.sin(tilt), -c, _rot(np.cos(tphi), np.sin(tphi), a1, a2))
    nl /= np.linalg.norm(nl, axis=-1, keepdims=True)
    e1, e2 = _frame(nl)
    roll = 2 * np.pi * u[..., 7]
    e1, e2 = _rot(np.cos(roll), np.sin(roll), e1, e2), _rot(np.cos(roll), -np.sin(roll), e2, e1)
    quad = u[..., 8] < P_QUAD
    aspect = ASPECT_MIN + (1.0 - ASPECT_MIN) * u[..., 9]
    # quads: corners (+-1, +-aspect); triangles: 3 points on the unit circle, the third repeated
    qx, qy = np.array([1.0, -1.0, -1.0, 1.0]), np.array([1.0, 1.0, -1.0, -1.0])
    ang = np.radians([90.0, 210.0, 330.0, 330.0])
    x = np.where(quad[..., None], qx, np.cos(ang))
    y = np.where(quad[..., None], qy * aspect[..., None], np.sin(ang))
    p = c[..., None, :] + half[..., None, None] * (x[..., None] * e1[..., None, :] + y[..., None] * e2[..., None, :])
    # counter-clockwise seen from the origin
    flip = np.einsum("...i,...i->...", p[..., 0, :], np.cross(p[..., 1, :], p[..., 2, :])) < 0
    order = np.where(quad[..., None], [0, 3, 2, 1], [0, 2, 1, 1])
    order = np.where(flip[..., None], order, [0, 1, 2, 3])
    return np.take_along_axis(p, order[..., None], axis=-2)


def first_lit(p: np.ndarray, count: int) -> np.ndarray:
    """The first ``count`` lights along axis -3 of p (..., n, 4, 3) with a vertex above the horizon (kept order)."""
    lit = np.any(p[..., 2] > 0.0, axis=-1)
    if np.any(lit.sum(axis=-1) < count):
        raise ValueError("too few lights above the horizon: draw more")
    idx = np.argsort(~lit, axis=-1, kind="stable")[..., :count]
    return np.take_along_axis(p, idx[..., None, None], axis=-3)


def random_lights(rng: np.random.Generator, v: np.ndarray, alpha: float, count: int) -> np.ndarray:
    """``count`` lights (count, 4, 3) for the view ``v`` (unit, shading frame) and NDF ``alpha`` (sets how far from
    the mirror direction the mirror-centred lights fall), each with at least one vertex above the horizon."""
    u = rng.random((2 * count + 8, UNIFORMS))
    return first_lit(from_uniforms(u, np.asarray(v, np.float64), float(alpha)), count)


def is_triangle(p: np.ndarray) -> np.ndarray:
    """True where a light (k, 4, 3) repeats a vertex."""
    return np.any(np.all(p == np.roll(p, -1, axis=1), axis=2), axis=1)


def inside(l: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(s, k) booleans: the unit directions l (s, 3) that cross the lights p (k, 4, 3) (counter-clockwise cones)."""
    e = np.cross(p, np.roll(p, -1, axis=1))  # (k, 4, 3) edge normals
    d = np.einsum("sj,kej->ske", l, e)
    return np.all(d >= 0.0, axis=2)
