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

from dataclasses import dataclass

import numpy as np
import warp as wp

from ..edge import ALPHA_MIN
from ..runtime.warp_runtime import kernel_factory
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


@kernel_factory
def aniso_integrand(model: str, layout: str) -> AnisoIntegrand:
    sample, weight, f_cos = LOBES[model]
    return AnisoIntegrand(model, layout, channels_for(layout)[0], sample, weight, f_cos, model == "microfacet")


# --------------------------------------------------------------- the view-azimuth average for the panelled rule
# The kind's default table averages E over the view azimuth phi_v. Rotating v and h together leaves the panelled
# Gauss-Legendre rule's geometry (horizon, v.h, n.l: lutbake.sampling.hemisphere) unchanged, so the average moves
# inside the integrand: at each node h (kernel frame, v in the x-z plane) it averages the lobe over the orientation
# beta of the tangent frame, g(h) = (1/pi) ∫_0^pi g_beta(h) dbeta (D and Lambda are pi-periodic in the azimuth), by the
# periodic trapezoid rule at beta_j = j pi / M, nested with its even nodes (M / 2) for an estimate of its own error.
# The average of a node set symmetric under beta -> -beta is even in phi, as the rule needs. Its integrand varies in
# beta on a scale ~alpha_y / alpha_x (D's azimuthal peak in the lobe's tail; Lambda(v) at grazing view), so M grows
# with the aspect r = alpha_max / alpha_min: M = AZIMUTH_NODES_PER_ASPECT r rounded up to a power of two (at most
# AZIMUTH_NODES_MAX); r = 1 (isotropic) takes one node, exactly.
AZIMUTH_NODES_PER_ASPECT = 16.0
AZIMUTH_NODES_MAX = 256
AVERAGED_CHANNELS = 4  # (scale, bias) over the M nodes, then over the M / 2 even ones (the nested estimate)


@wp.func
def azimuth_nodes(alpha_max: float, alpha_min: float):
    """M for the aspect alpha_max / alpha_min (comment above)."""
    r = alpha_max / wp.max(alpha_min, 1.0e-30)
    if r <= 1.000001:
        return 1
    m = int(2)  # noqa: UP018 (Warp: a dynamic variable, mutated in the loop)
    while float(m) < AZIMUTH_NODES_PER_ASPECT * r and m < AZIMUTH_NODES_MAX:
        m = m * 2
    return m


def azimuth_nodes_np(alpha_max: np.ndarray, alpha_min: np.ndarray) -> np.ndarray:
    """azimuth_nodes in numpy (the nominal cost of a texel)."""
    r = np.asarray(alpha_max, np.float64) / np.maximum(np.asarray(alpha_min, np.float64), 1e-30)
    m = 2.0 ** np.ceil(np.log2(np.maximum(AZIMUTH_NODES_PER_ASPECT * r, 2.0)))
    return np.where(r <= 1.000001, 1, np.minimum(m, AZIMUTH_NODES_MAX)).astype(np.int64)


def frame_average_for(term):
    """``frame_average(v, h, l, alpha_min, alpha_max) -> vec2``: (mean over the M orientations beta_j = j pi / M,
    mean over the even ones) of ``term(v, h, l, alpha_min, alpha_max, cos beta_j, sin beta_j)``, float64 sums. The
    frame's cos, sin of beta_j by a float64 rotation recurrence (its rounding ~1e-16 j)."""

    @wp.func
    def frame_average(v: wp.vec3, h: wp.vec3, l: wp.vec3, alpha_min: float, alpha_max: float):
        m = azimuth_nodes(alpha_max, alpha_min)
        step = wp.float64(wp.pi) / wp.float64(m)
        c1 = wp.cos(step)
        s1 = wp.sin(step)
        c = wp.float64(1.0) + wp.float64(0.0)
        s = wp.float64(0.0)
        all_ = wp.float64(0.0)
        even = wp.float64(0.0)
        for j in range(m):
            w = term(v, h, l, alpha_min, alpha_max, float(c), float(s))
            all_ = all_ + w
            if j % 2 == 0:
                even = even + w
            c_next = c * c1 - s * s1
            s = s * c1 + c * s1
            c = c_next
        mean = float(all_ / wp.float64(m))
        if m == 1:
            return wp.vec2(mean, mean)
        return wp.vec2(mean, float(even / wp.float64(m / 2)))

    return frame_average


@wp.func
def ggx_in_frame(v: wp.vec3, h: wp.vec3, l: wp.vec3, alpha_min: float, alpha_max: float, cf: float, sf: float):
    """D G2 with the tangent frame at (cos, sin) = (cf, sf): anisotropic GGX (Heitz 2014, Eq. 85) with alpha_max along
    the frame's T, alpha_min along B, height-correlated Smith G2 = 1 / (1 + Lambda(v) + Lambda(l)) with the
    anisotropic Lambda (Heitz 2014, Eq. 86)."""
    ax2 = alpha_max * alpha_max
    ay2 = alpha_min * alpha_min
    hx = h[0] * cf + h[1] * sf  # h in the frame
    hy = h[1] * cf - h[0] * sf
    d = hx * hx / ax2 + hy * hy / ay2 + h[2] * h[2]
    lx = l[0] * cf + l[1] * sf
    ly = l[1] * cf - l[0] * sf
    lam_l = 0.5 * (wp.sqrt(l[2] * l[2] + ax2 * lx * lx + ay2 * ly * ly) / l[2] - 1.0)
    lam_v = 0.5 * (wp.sqrt(v[2] * v[2] + v[0] * v[0] * (ax2 * cf * cf + ay2 * sf * sf)) / v[2] - 1.0)
    return wp.float64(1.0 / (wp.pi * alpha_max * alpha_min) / (d * d * (1.0 + lam_v + lam_l)))


ggx_frame_average = frame_average_for(ggx_in_frame)


@wp.func
def averaged_weight(v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha_min: float, alpha_max: float):
    """(mean over the M orientations, over the even ones) of D G2 (v.h) / (n.v) (ggx_in_frame)."""
    return ggx_frame_average(v, h, l, alpha_min, alpha_max) * (VoH / v[2])


@wp.func
def averaged_weight_ashikhmin_shirley(
    v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha_min: float, alpha_max: float
):
    """As averaged_weight for Ashikhmin & Shirley 2000: p_h (n.l) / max(n.l, n.v) (the lobe's g / F) averaged over the
    frame's orientation beta in closed form. p_h = sqrt((nu + 1)(nv + 1)) / (2 pi) (n.h)^((nu h_T^2 + nv h_B^2) /
    (1 - (n.h)^2)) (ndf.D_ashikhmin_shirley), nu (of alpha_max) along the frame's T, nv (of alpha_min) along B. With
    L = log(n.h) (ndf.log_cos64: float64, the exponents reach 2e8) and psi the azimuth of h, the exponent is
    L ((nu + nv) / 2 + (nu - nv) / 2 cos 2(psi - beta)), and (1 / pi) ∫_0^pi exp(c cos 2 beta) dbeta = I0(c)
    (Abramowitz & Stegun 1964, Eq. 9.6.16), so the mean is
        exp(L (nu + nv) / 2) I0(L (nu - nv) / 2) = exp(L min(nu, nv)) i0e(|L| |nu - nv| / 2)     (L <= 0)
    (ndf.bessel_i0e: no overflow for nu ~ 2e8). Exact: both kernel channels (the M- and M/2-node means of the GGX lobe)
    hold it, so the azimuth rule's estimate is 0 (it replaced a periodic trapezoid of up to 256 orientations)."""
    nu = ndf.as_exponent(wp.min(alpha_max, 1.0))
    nv = ndf.as_exponent(wp.min(alpha_min, 1.0))
    lg = ndf.log_cos64(h)
    mean = wp.exp(lg * wp.float64(wp.min(nu, nv))) * ndf.bessel_i0e(lg * wp.float64(0.5) * wp.float64(wp.abs(nu - nv)))
    scale = wp.sqrt((nu + 1.0) * (nv + 1.0)) / (2.0 * wp.pi) * l[2] / wp.max(l[2], v[2])
    return wp.vec2(float(mean), float(mean)) * scale


AVERAGED = {"microfacet": averaged_weight, "ashikhmin_shirley": averaged_weight_ashikhmin_shirley}


def one_node(alpha_max: np.ndarray, alpha_min: np.ndarray) -> np.ndarray:
    """The closed-form mean's node count (averaged_weight_ashikhmin_shirley): one evaluation a node."""
    return np.ones(np.shape(alpha_max), np.int64)


AVERAGED_NODES = {"microfacet": azimuth_nodes_np, "ashikhmin_shirley": one_node}  # per texel, for the nominal cost


@kernel_factory
def averaged_integrand(model: str, layout: str):
    """The integrand record of a view-azimuth-averaged anisotropic table for the panelled Gauss-Legendre kernel
    (lutbake.sampling.hemisphere_kernels.make_gauss_legendre): per texel (n.v, alpha = alpha_min, param = alpha_max),
    g(h) = channels(v.h) x the lobe's averaged weight (AVERAGED) over AVERAGED_CHANNELS = 4 kernel channels (the
    M-node and the M/2-node averages), the first 2 kept; the panels, the horizon map and the u = CDF(theta_h)
    variable of the NDF-peak panel are those of the isotropic lobe at alpha_min (its sharpest scale): GGX, with the
    mirror limit at alpha -> 0; for Ashikhmin-Shirley the Blinn-Phong CDF its isotropic tables use, and panels split
    along its max(n.l, n.v) kink."""
    from ..edge import COS_EPS
    from ..terms.distributions import NDFS
    from .specular import SpecularIntegrand, half_vector_integrand

    ch, _ = channels_for(layout)
    weight = AVERAGED[model]
    microfacet = model == "microfacet"

    @wp.func
    def lobe(v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha: float, param: float):
        c = ch(VoH, 0.0)
        w = weight(v, h, l, VoH, alpha, param)
        return wp.vec4(c[0] * w[0], c[1] * w[0], c[0] * w[1], c[1] * w[1])

    @wp.func
    def mirror(v: wp.vec3, param: float):
        if v[2] <= COS_EPS:
            return wp.vec4()
        c = ch(v[2], 0.0)
        return wp.vec4(c[0], c[1], c[0], c[1])

    return SpecularIntegrand(
        (f"{model}_aniso_averaged", "smith_height_correlated" if microfacet else "none", layout, model),
        half_vector_integrand(lobe, wp.vec4, True),
        wp.vec4,
        wp.vec4d,
        AVERAGED_CHANNELS,
        2,
        NDFS["ggx" if microfacet else "blinn_phong"],
        mirror if microfacet else None,
        kink_at_nov=not microfacet,
    )
