"""Integrands of microfacet specular tables and the estimator plumbing they share.

Cook-Torrance microfacet BRDF (Gotanda 2014 course notes, Eq. 1):
    f(l, v) = D(h) F(v.h) G2(l, v, h) / (4 (n.l)(n.v))
In the half-vector measure (see lutbake.sampling.estimators) the integrand is
    g(h) = f (n.l) 4 (v.h) = D G2 F (v.h) / (n.v).
A *channel function* replaces F by the weights that make the table's channels; for the split sum
with Schlick F = f0 (1 - Fc) + Fc, Fc = (1 - v.h)^5 (Karis 2013):
    scale_bias:   (1 - Fc, Fc)   -> E = f0 * scale + bias
    multiscatter: (Fc, 1)        -> E = mix(R, G, f0) = (1 - f0) R + f0 G,  E(F = 1) = G
    scale_bias_f82: (1 - Fc, Fc, (v.h)(1 - v.h)^6)   (Blender EEVEE's F82-tint term)
The cloth layout adds a channel with its own BRDF, D_charlie V_ashikhmin (no Fresnel), whose integrand
in the same measure is D_charlie V_ashikhmin (n.l) 4 (v.h) (Filament's DFV_Charlie_Uniform).
"""
from __future__ import annotations

import functools

import numpy as np
import warp as wp

from ..edge import COS_EPS
from ..sampling import points
from ..sampling.estimators import make_gauss_legendre, make_qmc
from ..terms import fresnel, masking, ndf, sets
from ..terms.frame import reflect


@wp.func
def channels_scale_bias(VoH: float):
    Fc = fresnel.Fc_schlick(VoH)
    return wp.vec2(1.0 - Fc, Fc)


@wp.func
def channels_multiscatter(VoH: float):
    return wp.vec2(fresnel.Fc_schlick(VoH), 1.0)


@wp.func
def channels_albedo(VoH: float):
    return wp.vec2(1.0, 0.0)


@wp.func
def channels_scale_bias_f82(VoH: float):
    Fc = fresnel.Fc_schlick(VoH)
    return wp.vec3(1.0 - Fc, Fc, VoH * Fc * wp.clamp(1.0 - VoH, 0.0, 1.0))


@wp.func
def channels_multiscatter3(VoH: float):
    return wp.vec3(fresnel.Fc_schlick(VoH), 1.0, 0.0)


CHANNEL_FUNCS = {"scale_bias": channels_scale_bias, "multiscatter": channels_multiscatter,
                 "albedo": channels_albedo, "scale_bias_f82": channels_scale_bias_f82}
N_CHANNELS = {"scale_bias": 2, "multiscatter": 2, "albedo": 2, "scale_bias_f82": 3, "multiscatter_cloth": 3}


@functools.lru_cache(maxsize=None)
def integrand_for(ndf_name: str, masking_name: str, channels_name: str):
    """g(h) = D G2 (v.h)/(n.v) * channels(v.h), 0 where n.l or v.h <= COS_EPS (back-facing)."""
    if channels_name == "multiscatter_cloth":
        return cloth_integrand_for(ndf_name, masking_name)
    D = sets.NDFS[ndf_name].D
    G2 = sets.G2_for(ndf_name, masking_name)
    ch = CHANNEL_FUNCS[channels_name]
    vec = wp.vec3 if N_CHANNELS[channels_name] == 3 else wp.vec2

    @wp.func
    def integrand(v: wp.vec3, h: wp.vec3, alpha: float):
        l = reflect(v, h)
        NoL = l[2]
        NoV = v[2]
        VoH = wp.dot(v, h)
        if NoL <= COS_EPS or VoH <= COS_EPS or NoV <= COS_EPS:
            return vec()
        NoH = h[2]
        return ch(VoH) * (D(h, alpha) * G2(NoV, NoL, NoH, VoH, alpha) * VoH / NoV)

    return integrand


@functools.lru_cache(maxsize=None)
def cloth_integrand_for(ndf_name: str, masking_name: str):
    """(Fc s, s, D_charlie V_ashikhmin (n.l) 4 (v.h)) with s = D G2 (v.h)/(n.v): the multiscatter
    channels plus Filament's cloth DV, 0 where n.l or v.h <= COS_EPS (back-facing)."""
    D = sets.NDFS[ndf_name].D
    G2 = sets.G2_for(ndf_name, masking_name)

    @wp.func
    def integrand(v: wp.vec3, h: wp.vec3, alpha: float):
        l = reflect(v, h)
        NoL = l[2]
        NoV = v[2]
        VoH = wp.dot(v, h)
        if NoL <= COS_EPS or VoH <= COS_EPS or NoV <= COS_EPS:
            return wp.vec3()
        spec = D(h, alpha) * G2(NoV, NoL, h[2], VoH, alpha) * VoH / NoV
        cloth = ndf.D_charlie(h, alpha) * masking.V_ashikhmin(NoV, NoL) * NoL * 4.0 * VoH
        return channels_multiscatter3(VoH) * spec + wp.vec3(0.0, 0.0, cloth)

    return integrand


ESTIMATORS = {
    "gauss_legendre": "deterministic product Gauss-Legendre over panels in theta_h (or CDF(theta_h)) and phi, "
                      "split exactly at the horizon (default; converges exponentially)",
    "sobol_vndf": "scrambled Sobol' points, GGX visible-normal sampling (Dupuy & Benyoub 2023)",
    "sobol_ndf": "scrambled Sobol' points, NDF importance sampling of D(h)(n.h)",
    "hammersley_ndf": "Hammersley points, NDF importance sampling (Filament cmgen's estimator)",
}
DEFAULT_SAMPLES = {"gauss_legendre": 432, "sobol_vndf": 4096, "sobol_ndf": 4096, "hammersley_ndf": 1024}


@functools.lru_cache(maxsize=None)
def kernel_for(ndf_name: str, masking_name: str, channels_name: str, estimator: str):
    """The table kernel for a (terms, channels, estimator) key; compiled once per Warp cache."""
    nd = sets.NDFS[ndf_name]
    g = integrand_for(ndf_name, masking_name, channels_name)
    vec, acc = (wp.vec3, wp.vec3d) if N_CHANNELS[channels_name] == 3 else (wp.vec2, wp.vec2d)
    if estimator == "gauss_legendre":
        return make_gauss_legendre(g, sets.pdf_ndf_for(ndf_name), nd.tan2_from_u, nd.u_from_tan2, vec, acc)
    if estimator == "sobol_vndf":
        return make_qmc(g, sets.pdf_vndf_for(ndf_name), nd.vndf, vec, acc)
    return make_qmc(g, sets.pdf_ndf_for(ndf_name), sets.sample_ndf_for(ndf_name), vec, acc)


def gl_order(samples: int) -> int:
    """GL points per dimension n for a nominal budget of ``samples`` evaluations per texel: 3 regions x n x n
    (A and B's two halves; grazing texels get more panels, up to 2 log4(pi / (4 theta_a)) + 1)."""
    return max(2, int(round(np.sqrt(samples / 3.0))))


def effective_samples(estimator: str, samples: int) -> int:
    if estimator == "gauss_legendre":
        return 3 * gl_order(samples) ** 2
    if estimator.startswith("sobol"):
        return 1 << int(np.ceil(np.log2(max(samples, 1))))
    return samples


def point_arrays(estimator: str, samples: int, seed: int, device: str) -> list:
    """The estimator's point-set arrays, as kernel inputs after (nov, alpha)."""
    if estimator == "gauss_legendre":
        x, w = points.gauss_legendre(gl_order(samples))
        arr = [wp.array(a, dtype=wp.float64, device=device) for a in (x, w)]
        return arr + arr
    if estimator.startswith("sobol"):
        pts = points.sobol(samples, seed)
    else:
        pts = points.hammersley(samples)
    pts = np.clip(pts, 0.0, np.nextafter(np.float32(1.0), np.float32(0.0))).astype(np.float32)
    w = np.full(len(pts), 1.0 / len(pts))
    return [wp.array(pts, dtype=float, device=device), wp.array(w, dtype=wp.float64, device=device)]


def integrate(kernel, nov: np.ndarray, alpha: np.ndarray, estimator: str, samples: int, seed: int,
              nch: int, device: str = "cpu") -> np.ndarray:
    """Run one launch over texels (nov[i], alpha[i]) -> float64 array (len, nch)."""
    n = len(nov)
    out = wp.zeros((n, nch), dtype=wp.float64, device=device)
    inputs = [wp.array(np.ascontiguousarray(nov, dtype=np.float32), dtype=float, device=device),
              wp.array(np.ascontiguousarray(alpha, dtype=np.float32), dtype=float, device=device)]
    inputs += point_arrays(estimator, samples, seed, device)
    wp.launch(kernel, dim=n, inputs=inputs + [out], device=device)
    return out.numpy()


def load(kernel, device: str = "cpu") -> None:
    """Compile (or load from Warp's cache) a kernel's module before worker threads launch it."""
    wp.load_module(kernel.module, device=device)
