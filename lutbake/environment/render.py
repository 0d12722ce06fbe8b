"""Spheres shaded under an environment, in numpy (Warp-free: ``lutbake preview`` of a cube file imports it): an
orthographic camera's sphere, a cube map looked up as a GPU samples it, the L2 SH irradiance, the split sum, and the
display curve of the pictures.

- **Camera** (``sphere_view``): a unit sphere seen along -w (w the world direction toward the camera); pixel (row i,
  column j) of a size x size image is at x = (j + 1/2)/size 2 - 1 (right), y = 1 - (i + 1/2)/size 2 (up); inside the
  disc its normal is n = x right + y up + sqrt(1 - x^2 - y^2) w and its view direction v = w for every pixel.
- **Cube lookup** (``CubeSampler``): bilinear between the four texel centres around the lookup vector's (s, t) on
  its face (lutbake.environment.cube's table), **seamless**: a face is padded by one texel taken from its
  neighbours (each border texel's centre direction, extended past the face, looked up on the face it lands on, as
  GL_TEXTURE_CUBE_MAP_SEAMLESS, OpenGL 4.6 §8.13.1, samples across an edge); a padded corner is the mean of its
  three neighbours (the corner's value is implementation-defined in GL). **Trilinear** across mips at a
  fractional lod (textureLod), the lod from the engine's curve (``lod``).
- **Split sum** (``split_sum_specular``, Karis 2013): L_spec = prefiltered(R, lod(r)) (f0 scale(n.v, r) +
  bias(n.v, r)), R = 2 (n.v) n - v; L_diffuse = albedo x irradiance_over_pi(n) (the irradiance cube holds E / pi).
- **SH** (``sh_irradiance_over_pi``): E / pi of an L2 SH in any form of lutbake.environment.sh.
- **Display** (``tone_map``): exposure k, Reinhard x / (1 + x) per channel, then the sRGB transfer function
  (IEC 61966-2-1): what the pictures' titles state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import cube, sh
from .curves import MipCurve
from .latlong import directions

# ------------------------------------------------------------------------------------------------ camera


@dataclass(frozen=True)
class SphereView:
    """The pixels of an orthographic sphere: ``inside`` (size, size) bool, and per inside pixel (row-major order)
    its unit normal ``n`` and view direction ``v`` (N, 3), world directions (lutbake.environment.latlong's y-up
    frame)."""

    size: int
    inside: np.ndarray
    n: np.ndarray
    v: np.ndarray

    def image(self, values: np.ndarray, background: float = 0.0) -> np.ndarray:
        """(size, size, C): ``values`` (N, C) at the inside pixels, ``background`` elsewhere."""
        values = np.asarray(values)
        out = np.full((self.size, self.size) + values.shape[1:], background, dtype=np.float64)
        out[self.inside] = values
        return out


def camera_direction(azimuth: float, elevation: float) -> np.ndarray:
    """The world direction toward the camera at ``azimuth`` phi (radians, lutbake.environment.latlong's
    phi = atan2(z, x): 0 looks from +X) and ``elevation`` (radians above the horizon)."""
    return directions(np.array(math.pi / 2 - elevation), np.array(azimuth))


def sphere_view(size: int, w: np.ndarray, up=(0.0, 1.0, 0.0)) -> SphereView:
    """The orthographic sphere of ``size``^2 pixels seen from the unit direction ``w`` (module docstring); ``up`` is
    the world direction drawn upward (projected off w)."""
    w = np.asarray(w, np.float64) / np.linalg.norm(w)
    right = np.cross(np.asarray(up, np.float64), w)
    if np.linalg.norm(right) < 1e-9:  # looking straight up or down: any right angle will do
        right = np.cross((1.0, 0.0, 0.0), w)
    right /= np.linalg.norm(right)
    upward = np.cross(w, right)
    c = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(c, -c)
    inside = x * x + y * y < 1
    z = np.sqrt(1 - x[inside] ** 2 - y[inside] ** 2)
    n = x[inside, None] * right + y[inside, None] * upward + z[:, None] * w
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return SphereView(size, inside, n, np.broadcast_to(w, n.shape).copy())


def reflect(n: np.ndarray, v: np.ndarray) -> np.ndarray:
    """R = 2 (n.v) n - v (the mirror direction of v about n), (N, 3)."""
    return 2 * np.sum(n * v, axis=-1, keepdims=True) * n - v


# ------------------------------------------------------------------------------------------------ cube lookup


def padded_faces(mip: np.ndarray) -> np.ndarray:
    """(6, n + 2, n + 2, C): each face of ``mip`` (6, n, n, C) with a one-texel border from its neighbours (module
    docstring): the border texel's centre, (u, v) one texel past the face's edge, is a direction whose major axis
    names the face it lies on; it takes that face's texel under it (clamped to the face). Corners: the mean of
    their three neighbours."""
    mip = np.asarray(mip, np.float64)
    n = mip.shape[1]
    c = (np.arange(-1, n + 1) + 0.5) / n * 2 - 1  # padded texel centres in u (or v)
    v, u = np.meshgrid(c, c, indexing="ij")
    d = cube.face_directions(np.arange(6)[:, None, None], u[None], v[None])
    face, s, t = cube.face_st(d)
    col = np.clip((s * n).astype(np.int64), 0, n - 1)
    row = np.clip((t * n).astype(np.int64), 0, n - 1)
    out = mip[face, row, col]
    for r, cc, dr, dc in ((0, 0, 1, 1), (0, n + 1, 1, -1), (n + 1, 0, -1, 1), (n + 1, n + 1, -1, -1)):
        out[:, r, cc] = (out[:, r + dr, cc] + out[:, r, cc + dc] + out[:, r + dr, cc + dc]) / 3
    return out


@dataclass
class CubeSampler:
    """A cube map with mips (each (6, n, n, C), lutbake's face table) sampled as a GPU does (module docstring);
    ``orientation``: how a world direction becomes the lookup vector (lutbake.environment.cube.ORIENTATIONS, the
    record's ``face_convention``)."""

    mips: list[np.ndarray]
    orientation: str = "gl"
    _padded: dict[int, np.ndarray] = field(default_factory=dict, repr=False)

    def padded(self, m: int) -> np.ndarray:
        if m not in self._padded:
            self._padded[m] = padded_faces(self.mips[m])
        return self._padded[m]

    def bilinear(self, m: int, world: np.ndarray) -> np.ndarray:
        """(N, C): mip ``m`` at world directions ``world`` (N, 3), bilinear between texel centres, seamless."""
        face, s, t = cube.face_st(cube.lookup_vectors(world, self.orientation))
        p = self.padded(m)
        n = p.shape[1] - 2
        x, y = s * n - 0.5, t * n - 0.5  # texel coordinates, centres at integers
        i0, j0 = np.floor(x), np.floor(y)
        fx, fy = (x - i0)[:, None], (y - j0)[:, None]
        i0 = np.clip(i0.astype(np.int64) + 1, 0, n)  # + 1: the padding
        j0 = np.clip(j0.astype(np.int64) + 1, 0, n)
        top = p[face, j0, i0] * (1 - fx) + p[face, j0, i0 + 1] * fx
        bottom = p[face, j0 + 1, i0] * (1 - fx) + p[face, j0 + 1, i0 + 1] * fx
        return top * (1 - fy) + bottom * fy

    def sample(self, world: np.ndarray, lod: float) -> np.ndarray:
        """(N, C): trilinear at ``lod`` (clamped to [0, mips - 1]), textureLod's result."""
        lod = min(max(float(lod), 0.0), len(self.mips) - 1.0)
        m0 = int(math.floor(lod))
        frac = lod - m0
        out = self.bilinear(m0, world)
        if frac > 0:
            out = out * (1 - frac) + self.bilinear(m0 + 1, world) * frac
        return out


def lod(curve: MipCurve, roughness: float, mips: int) -> float:
    """The fractional mip the engine's shader reads at perceptual ``roughness``: the inverse of the curve's
    roughness(mip, mips) (lutbake.environment.curves), by bisection on [0, mips - 1] (the curves are
    non-decreasing; on a flat part the smallest such mip)."""
    if mips < 2:
        return 0.0
    r = min(max(float(roughness), 0.0), 1.0)
    lo, hi = 0.0, mips - 1.0
    if curve.roughness(lo, mips) >= r:
        return lo
    if curve.roughness(hi, mips) <= r:
        return hi
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if curve.roughness(mid, mips) < r else (lo, mid)
    return hi


# ------------------------------------------------------------------------------------------------ shading


def split_sum_specular(
    prefiltered: CubeSampler, curve: MipCurve, dfg, n: np.ndarray, v: np.ndarray, roughness: float, f0
) -> np.ndarray:
    """(N, 3): prefiltered(R, lod(r)) (f0 scale + bias), ``dfg(nov, r) -> (scale, bias)`` each (N,) (the DFG
    table's lookup, scale_bias layout: E = f0 scale + f90 bias, f90 = 1)."""
    R = reflect(n, v)
    nov = np.clip(np.sum(n * v, axis=-1), 0.0, 1.0)
    scale, bias = dfg(nov, np.full_like(nov, roughness))
    E = np.asarray(f0, np.float64) * scale[:, None] + bias[:, None]
    return prefiltered.sample(R, lod(curve, roughness, len(prefiltered.mips))) * E


def sh_irradiance_over_pi(coefficients: np.ndarray, form: str, d: np.ndarray) -> np.ndarray:
    """(N, C): E / pi at unit directions ``d`` of L2 SH ``coefficients`` (9, C) in ``form`` (lutbake.environment.sh
    FORMS): back to radiance coefficients (each form is the radiance ones times a constant per index), then
    Â_l L_k / pi summed over Y_k (Ramamoorthi & Hanrahan 2001, Eq. 8)."""
    c = np.asarray(coefficients, np.float64)
    per_index = sh.convolve(np.ones((9, 1)), form)  # the form's factor per index
    radiance = c / per_index
    return sh.evaluate(sh.convolve(radiance, "irradiance_over_pi"), d)


# ------------------------------------------------------------------------------------------------ display

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # Rec. 709 / sRGB primaries


def srgb_encode(x: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1) of linear x in [0, 1]."""
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def tone_map(rgb: np.ndarray, exposure: float) -> np.ndarray:
    """Display values in [0, 1]: y = k x / (1 + k x) per channel (Reinhard et al. 2002, Eq. 3), k = ``exposure``,
    sRGB-encoded."""
    x = np.maximum(np.asarray(rgb, np.float64), 0.0) * exposure
    return srgb_encode(x / (1 + x))


def exposure_for(values: np.ndarray) -> float:
    """k = 1 / the mean luminance of ``values`` (..., 3): the scene's mean maps to 1/2 after Reinhard (1 when the
    mean is 0)."""
    mean = float(np.mean(np.asarray(values, np.float64) @ LUMINANCE))
    return 1.0 / mean if mean > 0 else 1.0


DISPLAY = "display: Reinhard k x / (1 + k x), k = {k:.3g} (1 / mean luminance), sRGB"
