"""The weights an output texel integrates the source against, as ``@wp.func``s of (r, l, alpha): r the texel's
direction (n = v = r, the split-sum assumption), l a unit direction with r . l >= 0 (the quadrature clips the
horizon), in float64 with the NDF from lutbake.terms.

Prefiltered radiance P(r) = ∫ L(l) w(r, l) dω / ∫ w(r, l) dω (Karis 2013, "Real Shading in Unreal Engine 4", the
split-sum's first sum, Eq. 2 as the converged limit of its estimator): with n = v = r the GGX sampling pdf of l is
D(h)(n.h) / (4 v.h) = D(h) / 4, so Karis' sum of L (n.l) over l drawn from it converges to ∫ L D/4 (n.l) dω /
∫ D/4 (n.l) dω. ``ggx_nl`` is that weight, ``ggx`` the unweighted one (Filament's cmgen without n.l, glTF-IBL-Sampler
with its n.l weighting off), ``cosine`` the irradiance lobe (E(r)/pi = ∫ L (n.l) dω / pi), ``footprint`` the
indicator of a texel's own footprint (the area average, the alpha -> 0 mip). With n = v = r, h = (r + l)/|r + l|,
n.h = |r + l| / 2 and |n x h| = |r - l| / 2, both exact near the peak.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from ..terms.ndf import D_charlie_sin2, D_ggx


@wp.func
def w_ggx_nl(r: wp.vec3d, l: wp.vec3d, alpha: wp.float64):
    """D_ggx(h; alpha) / 4 * (n.l), n = v = r (Karis 2013's n.l-weighted prefilter)."""
    c = wp.length(r + l) * wp.float64(0.5)
    s = wp.length(r - l) * wp.float64(0.5)
    d = D_ggx(wp.vec3(float(s), 0.0, float(c)), float(alpha))
    return wp.float64(d) * wp.float64(0.25) * wp.dot(r, l)


@wp.func
def w_ggx(r: wp.vec3d, l: wp.vec3d, alpha: wp.float64):
    """D_ggx(h; alpha) / 4 over the hemisphere r . l >= 0 (the unweighted prefilter)."""
    c = wp.length(r + l) * wp.float64(0.5)
    s = wp.length(r - l) * wp.float64(0.5)
    return wp.float64(D_ggx(wp.vec3(float(s), 0.0, float(c)), float(alpha))) * wp.float64(0.25)


@wp.func
def w_charlie(r: wp.vec3d, l: wp.vec3d, alpha: wp.float64):
    """D_charlie(h; alpha) / 4 * (n.l), n = v = r: the sheen prefilter (glTF-IBL-Sampler's Charlie distribution, its
    n.l-weighted sum; Estevez & Kulla 2017, Eq. 2), sin^2 theta_h = |r - l|^2 / 4."""
    s = wp.length(r - l) * wp.float64(0.5)
    return wp.float64(D_charlie_sin2(s * s, float(alpha))) * wp.float64(0.25) * wp.dot(r, l)


@wp.func
def w_cosine(r: wp.vec3d, l: wp.vec3d, alpha: wp.float64):
    """n.l (the irradiance lobe; alpha unused)."""
    return wp.dot(r, l)


@wp.func
def w_footprint(r: wp.vec3d, l: wp.vec3d, alpha: wp.float64):
    """1 (the texel's footprint: the quadrature clips it to its four planes)."""
    return wp.float64(1.0)


# name -> (weight, relative slope S of the weight across a cell of radius rho at distance d from the peak:
# |dw/w| ~ S rho / (d + lambda), lambda per texel from ``lobe_width``)
LOBES = {
    "ggx_nl": (w_ggx_nl, 4.0),
    "ggx": (w_ggx, 4.0),
    "charlie": (w_charlie, 8.0),
    "cosine": (w_cosine, 2.0),
    "footprint": (w_footprint, 0.0),
}


def lobe_width(lobe: str, alpha: float) -> float:
    """lambda: the angular scale (radians, in l) over which the weight falls by about half from its peak: GGX
    2 atan(alpha) (the h lobe's half width alpha, doubled by the reflection), cosine pi/3, Charlie (rising from 0 at
    l = r to the horizon, its log-slope 1 / (alpha tan theta_h)) pi/3 with the slope 8 in LOBES, footprint 0."""
    if lobe in ("ggx_nl", "ggx"):
        return 2.0 * math.atan(alpha)
    return math.pi / 3 if lobe in ("cosine", "charlie") else 0.0


def alpha_of(lobe: str, r: float) -> float:
    """The NDF's alpha at perceptual roughness r: r^2 (GGX: Burley 2012), r for Charlie (glTF-IBL-Sampler passes the
    mip's roughness to D_Charlie as its sheenRoughness, and the viewer reads lod = sheenRoughness (M - 1))."""
    return float(r) if lobe == "charlie" else float(r) ** 2


def _charlie_profile(t: np.ndarray, alpha: float) -> np.ndarray:
    """D_charlie(h) / 4 as a function of t = r.l: sin^2 theta_h = (1 - t) / 2 (Estevez & Kulla 2017, Eq. 2)."""
    return (2 + 1 / alpha) * np.maximum((1 - t) / 2, 0.0) ** (0.5 / alpha) / (2 * math.pi) / 4


def _ggx_profile(t: np.ndarray, alpha: float) -> np.ndarray:
    """D_ggx(h) / 4 as a function of t = r.l (n = v = r: cos^2 theta_h = (1 + t) / 2), Walter et al. 2007 Eq. 33."""
    a2 = alpha * alpha
    return a2 / (math.pi * ((1 + t) / 2 * (a2 - 1) + 1) ** 2) / 4


# name -> the zonal weight k(t, alpha), t = r.l, zero behind the horizon: the same weights as LOBES, in numpy, for
# the spherical-harmonic prefilter (lutbake.environment.harmonic)
PROFILES = {
    "ggx_nl": lambda t, alpha: np.where(t > 0, _ggx_profile(t, alpha) * t, 0.0),
    "ggx": lambda t, alpha: np.where(t > 0, _ggx_profile(t, alpha), 0.0),
    "charlie": lambda t, alpha: np.where(t > 0, _charlie_profile(t, alpha) * t, 0.0),
    "cosine": lambda t, alpha: np.maximum(t, 0.0),
}
# the same weights without the horizon's cut (smooth on [-1, 1]): how fast their coefficients fall says how wide
# the lobe is; the cut's kink adds a tail that falls like l^-5/2 (lutbake.environment.harmonic.LMAX_FLOOR)
SMOOTH_PROFILES = {
    "ggx_nl": lambda t, alpha: _ggx_profile(t, alpha) * t,
    "ggx": _ggx_profile,
    "charlie": lambda t, alpha: _charlie_profile(t, alpha) * t,
    "cosine": lambda t, alpha: t,
}
