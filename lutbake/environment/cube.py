"""Cube-map geometry: the face table, direction <-> (face, s, t), exact texel solid angles and footprints.

**The face convention (OpenGL / KTX / Vulkan)**, OpenGL 4.6 §8.13 Table 8.19 (Vulkan 1.3 §16.5.4, Table 17 is the
same; KTX 1 and KTX 2 store the six faces in this order and orientation). A direction (x, y, z) picks its major
axis ma; the face's (sc, tc) give s = (sc / |ma| + 1) / 2, t = (tc / |ma| + 1) / 2:

    face  index  ma   sc   tc        direction of (u, v) = (2s - 1, 2t - 1)
    +X    0      +x   -z   -y        ( 1, -v, -u)
    -X    1      -x   +z   -y        (-1, -v,  u)
    +Y    2      +y   +x   +z        ( u,  1,  v)
    -Y    3      -y   +x   -z        ( u, -1, -v)
    +Z    4      +z   +x   -y        ( u, -v,  1)
    -Z    5      -z   -x   -y        (-u, -v, -1)

Texel (row j, column i) of an n x n face covers s in [i/n, (i+1)/n], t in [j/n, (j+1)/n]: column along s, row 0 at
t = 0, the image's first row (KTX 2: "the first texel of each image is the top-left"; no flip is applied).

**D3D**: Direct3D addresses a cube with the same major-axis table and the same face order, so one set of six images
samples the same for the same lookup vector. What differs is the world: a left-handed engine (D3D's samples, Unity)
looks a cube up with its own (x, y, z), which is the right-handed world's (x, y, -z). Orientation ``d3d_left_handed``
names that: a world direction d is looked up as (d.x, d.y, -d.z), which swaps the +Z and -Z faces and mirrors the
others. It is recorded in every file lutbake writes (``face_convention``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

FACE_NAMES = ("+X", "-X", "+Y", "-Y", "+Z", "-Z")


@dataclass(frozen=True)
class Orientation:
    """How a world direction is turned into the lookup vector of the face table: lookup = world * ``flip``."""

    name: str
    flip: tuple[float, float, float]
    doc: str


ORIENTATIONS = {
    "gl": Orientation(
        "gl",
        (1.0, 1.0, 1.0),
        "OpenGL / Vulkan / KTX: right-handed world, lookup vector = world direction (GL 4.6 Table 8.19)",
    ),
    "d3d_left_handed": Orientation(
        "d3d_left_handed",
        (1.0, 1.0, -1.0),
        "Direct3D's face table (the same as GL's) in a left-handed world: lookup vector = (x, y, -z) of the "
        "right-handed world direction",
    ),
}


def face_directions(face: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The (unnormalised) lookup vectors of face ``face`` at (u, v) = (2s - 1, 2t - 1) in [-1, 1]: the table above.
    Shapes broadcast; the result has a last axis of 3, float64."""
    face, u, v = np.broadcast_arrays(np.asarray(face), np.asarray(u, np.float64), np.asarray(v, np.float64))
    one = np.ones_like(u)
    table = (
        (one, -v, -u),
        (-one, -v, u),
        (u, one, v),
        (u, -one, -v),
        (u, -v, one),
        (-u, -v, -one),
    )
    out = np.zeros(u.shape + (3,))
    for f, comps in enumerate(table):
        m = face == f
        for c in range(3):
            out[..., c][m] = comps[c][m]
    return out


def face_st(d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(face, s, t) of lookup vectors ``d`` (..., 3): the major axis picks the face (ties: x before y before z, as
    the GL table's order), then s = (sc/|ma| + 1)/2, t = (tc/|ma| + 1)/2. The inverse of ``face_directions``."""
    d = np.asarray(d, np.float64)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    ax, ay, az = np.abs(x), np.abs(y), np.abs(z)
    major = np.where((ax >= ay) & (ax >= az), 0, np.where(ay >= az, 1, 2))
    neg = np.choose(major, (x, y, z)) < 0
    face = 2 * major + neg
    sc = np.choose(face, (-z, z, x, x, x, -x))
    tc = np.choose(face, (-y, -y, z, -z, -y, -y))
    ma = np.choose(major, (ax, ay, az))
    return face, (sc / ma + 1) / 2, (tc / ma + 1) / 2


def lookup_vectors(world: np.ndarray, orientation: str = "gl") -> np.ndarray:
    """The lookup vectors of world directions under an orientation (ORIENTATIONS)."""
    return np.asarray(world, np.float64) * np.asarray(ORIENTATIONS[orientation].flip)


def texel_edges(n: int) -> np.ndarray:
    """u (or v) at the n + 1 texel edges of an n-texel face: -1 + 2 i / n."""
    return -1.0 + 2.0 * np.arange(n + 1) / n


def _area_corner(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """F(u, v) = atan2(u v, sqrt(u^2 + v^2 + 1)): the solid angle of the face rectangle [0, u] x [0, v] at unit
    distance, signed; ∫∫ du dv / (1 + u^2 + v^2)^(3/2) = F(u1, v1) - F(u0, v1) - F(u1, v0) + F(u0, v0)."""
    return np.arctan2(u * v, np.sqrt(u * u + v * v + 1.0))


def texel_solid_angles(n: int) -> np.ndarray:
    """(n, n) exact solid angles of one face's texels (row j = t, column i = s); the same on every face; the six
    faces sum to 4 pi. The area element of the plane at unit distance, integrated in closed form."""
    e = texel_edges(n)
    F = _area_corner(e[None, :], e[:, None])  # [j (v), i (u)]
    return F[1:, 1:] - F[:-1, 1:] - F[1:, :-1] + F[:-1, :-1]


def texel_centres(n: int) -> np.ndarray:
    """(6, n, n, 3) unit lookup vectors of every texel centre (face, row t, column s)."""
    c = (np.arange(n) + 0.5) / n * 2 - 1
    v, u = np.meshgrid(c, c, indexing="ij")
    d = face_directions(np.arange(6)[:, None, None], u[None], v[None])
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


@functools.lru_cache(maxsize=4)
def texel_planes(n: int) -> np.ndarray:
    """(6, n, n, 4, 3) the inward unit normals of the four great circles that bound each texel: its footprint is the
    set of directions l with p . l >= 0 for all four (a convex spherical quadrilateral). Cached per n (every tile of
    a mip reads it), read-only."""
    e = texel_edges(n)
    v0, u0 = np.meshgrid(e[:-1], e[:-1], indexing="ij")
    v1, u1 = v0 + 2.0 / n, u0 + 2.0 / n
    faces = np.arange(6)[:, None, None]
    corners = [face_directions(faces, uu[None], vv[None]) for uu, vv in ((u0, v0), (u1, v0), (u1, v1), (u0, v1))]
    centre = texel_centres(n)
    planes = []
    for k in range(4):
        p = np.cross(corners[k], corners[(k + 1) % 4])
        p /= np.linalg.norm(p, axis=-1, keepdims=True)
        p *= np.sign(np.sum(p * centre, axis=-1, keepdims=True))  # inward: the centre lies on the positive side
        planes.append(p)
    out = np.stack(planes, axis=-2)
    out.flags.writeable = False
    return out
