"""Integrands of the anisotropic split-sum tables (kind specular_aniso): one record per lobe.

Tangent T = +x, bitangent B = +y, n = +z. Anisotropy -> (alpha_x, alpha_y): Burley 2012 ("Physically based shading
at Disney", SIGGRAPH course notes, Addenda B.2): aspect = sqrt(1 - 0.9 |a|), alpha_x = alpha / aspect,
alpha_y = alpha * aspect for a >= 0 (a < 0 swaps the two: the lobe stretches along B) (``alpha_xy``).

Lobes (key ``model``), each as ``sample(v, ax, ay, nu, nv, u1, u2) -> h`` (its own half-vector sampler),
``weight(v, l, ax, ay) -> float`` (g / p: the per-sample weight under that sampler, F excluded) and
``f_cos(v, l, h, ax, ay, nu, nv) -> float`` (f (n.l) / F at any l, for estimators that sample l themselves):
- ``microfacet``: anisotropic GGX (Heitz 2014, Eq. 85) with height-correlated Smith G2 and the anisotropic
  Lambda (Heitz 2014, Eq. 86); f = D G2 F / (4 (n.l)(n.v)). Sampled by the anisotropic VNDF (Heitz 2018, JCGT
  7(4); spherical caps, Dupuy & Benyoub 2023): pdf = G1(v) max(0, v.h) D(h) / (n.v), so g / p = F G2 / G1(v)
  = F (1 + Lambda_v) / (1 + Lambda_v + Lambda_l), bounded by F. alpha -> 0 (max(alpha_x, alpha_y) < ALPHA_MIN):
  the mirror, E = channels(n.v) (lutbake.edge).
- ``ashikhmin_shirley``: Ashikhmin & Shirley 2000 with exponents nu = 2 / alpha_x^2 - 2 along T and
  nv = 2 / alpha_y^2 - 2 along B (clamped to >= 0), f = F p_h / (4 (v.h) max(n.l, n.v)), p_h their half-vector
  density; sampled by the paper's Eq. 9, weight = F (n.l) / max(n.l, n.v). alpha clamped to >= ALPHA_MIN.
The channels are those of the dfg layouts scale_bias / multiscatter (lutbake.integrands.specular.channels_for).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import warp as wp

from ..edge import ALPHA_MIN
from ..terms import masking, ndf
from .specular import channels_for


def alpha_xy(alpha: np.ndarray, aniso: np.ndarray, mirror: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Burley 2012 (Addenda B.2): (alpha_x, alpha_y) (float32) for NDF alpha and anisotropy a in [-1, 1], each
    >= ALPHA_MIN; with ``mirror``, texels whose alpha_x and alpha_y are both below ALPHA_MIN get (0, 0): the
    mirror branch (lutbake.edge)."""
    alpha = np.asarray(alpha, np.float64)
    aniso = np.asarray(aniso, np.float64)
    aspect = np.sqrt(1.0 - 0.9 * np.abs(aniso))
    ax, ay = alpha / aspect, alpha * aspect
    ax, ay = np.where(aniso >= 0, ax, ay), np.where(aniso >= 0, ay, ax)
    smooth = mirror & (np.maximum(ax, ay) < ALPHA_MIN)
    ax, ay = np.maximum(ax, ALPHA_MIN), np.maximum(ay, ALPHA_MIN)
    return np.where(smooth, 0.0, ax).astype(np.float32), np.where(smooth, 0.0, ay).astype(np.float32)


@wp.func
def sample_microfacet(v: wp.vec3, ax: float, ay: float, nu: float, nv: float, u1: float, u2: float):
    return ndf.sample_vndf_ggx_aniso(v, ax, ay, u1, u2)


@wp.func
def weight_microfacet(v: wp.vec3, l: wp.vec3, ax: float, ay: float):
    lam_v = masking.Lambda_ggx_aniso(v, ax, ay)
    return (1.0 + lam_v) / (1.0 + lam_v + masking.Lambda_ggx_aniso(l, ax, ay))


@wp.func
def f_cos_microfacet(v: wp.vec3, l: wp.vec3, h: wp.vec3, ax: float, ay: float, nu: float, nv: float):
    g2 = masking.G2_smith_height_correlated(masking.Lambda_ggx_aniso(v, ax, ay), masking.Lambda_ggx_aniso(l, ax, ay))
    return ndf.D_ggx_aniso(h, ax, ay) * g2 / (4.0 * v[2])


@wp.func
def sample_ashikhmin_shirley(v: wp.vec3, ax: float, ay: float, nu: float, nv: float, u1: float, u2: float):
    return ndf.sample_ashikhmin_shirley(nu, nv, u1, u2)


@wp.func
def weight_ashikhmin_shirley(v: wp.vec3, l: wp.vec3, ax: float, ay: float):
    return l[2] / wp.max(l[2], v[2])


@wp.func
def f_cos_ashikhmin_shirley(v: wp.vec3, l: wp.vec3, h: wp.vec3, ax: float, ay: float, nu: float, nv: float):
    return ndf.D_ashikhmin_shirley(h, nu, nv) * l[2] / (4.0 * wp.dot(v, h) * wp.max(l[2], v[2]))


LOBES = {
    "microfacet": (sample_microfacet, weight_microfacet, f_cos_microfacet),
    "ashikhmin_shirley": (sample_ashikhmin_shirley, weight_ashikhmin_shirley, f_cos_ashikhmin_shirley),
}


@dataclass(frozen=True)
class AnisoIntegrand:
    model: str
    layout: str
    channels: object  # channels(VoH, param) -> vec2 (Schlick split-sum weights)
    sample: object
    weight: object
    f_cos: object
    mirror: bool  # alpha -> 0 has the closed-form mirror limit channels(n.v)
    nch: int = 2


@functools.lru_cache(maxsize=None)
def aniso_integrand(model: str, layout: str) -> AnisoIntegrand:
    sample, weight, f_cos = LOBES[model]
    return AnisoIntegrand(model, layout, channels_for(layout)[0], sample, weight, f_cos, model == "microfacet")
