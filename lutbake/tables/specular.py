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
from ..terms import fresnel, masking, metals, ndf, sets
from ..terms.frame import reflect
from .base import Plan


@wp.func
def channels_scale_bias(VoH: float, f0: float):
    Fc = fresnel.Fc_schlick(VoH)
    return wp.vec2(1.0 - Fc, Fc)


@wp.func
def channels_multiscatter(VoH: float, f0: float):
    return wp.vec2(fresnel.Fc_schlick(VoH), 1.0)


@wp.func
def channels_albedo(VoH: float, f0: float):
    return wp.vec2(1.0, 0.0)


# specular_3d: R = F(f0, v.h) for the texel's f0 (the kernel's per-texel param); G unused (0)
@wp.func
def channels_F_schlick(VoH: float, f0: float):
    return wp.vec2(fresnel.F_schlick(f0, VoH), 0.0)


@wp.func
def channels_F_schlick_sg(VoH: float, f0: float):
    return wp.vec2(fresnel.F_schlick_sg(f0, VoH), 0.0)


@wp.func
def channels_F_improved_sg(VoH: float, f0: float):
    return wp.vec2(fresnel.F_improved_sg(f0, VoH), 0.0)


@wp.func
def channels_F_dielectric_f0(VoH: float, f0: float):
    return wp.vec2(fresnel.F_dielectric_f0(f0, VoH), 0.0)


# Blender EEVEE's F82-tint layout: (1 - Fc, Fc, (v.h)(1 - v.h)^6)
@wp.func
def channels_scale_bias_f82(VoH: float, f0: float):
    Fc = fresnel.Fc_schlick(VoH)
    return wp.vec3(1.0 - Fc, Fc, VoH * Fc * wp.clamp(1.0 - VoH, 0.0, 1.0))


@wp.func
def channels_multiscatter3(VoH: float, f0: float):
    return wp.vec3(fresnel.Fc_schlick(VoH), 1.0, 0.0)


CHANNEL_FUNCS = {
    "scale_bias": channels_scale_bias,
    "multiscatter": channels_multiscatter,
    "albedo": channels_albedo,
    "F:schlick": channels_F_schlick,
    "F:schlick_sg": channels_F_schlick_sg,
    "F:improved_sg": channels_F_improved_sg,
    "F:dielectric_f0": channels_F_dielectric_f0,
    "scale_bias_f82": channels_scale_bias_f82,
}
THREE_CHANNELS = {"scale_bias_f82", "multiscatter_cloth", "charlie", "charlie_clamped"}
N_CHANNELS = {
    "scale_bias": 2,
    "multiscatter": 2,
    "albedo": 2,
    "scale_bias_f82": 3,
    "multiscatter_cloth": 3,
    "charlie": 3,
    "sheen_albedo": 2,
    "charlie_clamped": 3,
    "sheen_albedo_clamped": 2,
}
# the sheen lobe alone: no GGX term (sheen_integrand_for); *_clamped: V clamped to [0, 1] (the viewer's shaders)
SHEEN_LAYOUTS = ("charlie", "sheen_albedo", "charlie_clamped", "sheen_albedo_clamped")


@functools.lru_cache(maxsize=None)
def channels_for(channels_name: str):
    """(channel wp.func (VoH, param) -> vec, vec type): a name of CHANNEL_FUNCS, or "metal:<name>"
    for RGB = F_conductor(n_c, k_c, v.h) of a metal of lutbake.terms.metals (constants closed over)."""
    if channels_name in CHANNEL_FUNCS:
        return CHANNEL_FUNCS[channels_name], (wp.vec3 if channels_name in THREE_CHANNELS else wp.vec2)
    if channels_name.startswith("metal:"):
        m = metals.lookup_metal(channels_name[len("metal:") :])
        nr, ng, nb = (float(x) for x in m.n)
        kr, kg, kb = (float(x) for x in m.k)

        @wp.func
        def channels_metal(VoH: float, f0: float):
            return wp.vec3(
                fresnel.F_conductor(nr, kr, VoH), fresnel.F_conductor(ng, kg, VoH), fresnel.F_conductor(nb, kb, VoH)
            )

        return channels_metal, wp.vec3
    raise KeyError(channels_name)


@functools.lru_cache(maxsize=None)
def integrand_for(ndf_name: str, masking_name: str, channels_name: str, form: str = "microfacet"):
    """g(h) = f(l, v) (n.l) 4 (v.h) * channels(v.h, param), 0 where n.l, v.h or n.v <= COS_EPS (back-facing).
    ``form`` (lutbake.terms.sets.model_terms):
        microfacet         f = D G2 / (4 (n.l)(n.v)) [x F]:          g = D G2 (v.h) / (n.v)
        blinn_phong        f = (s + 8)/(8 pi) (n.h)^s [x F]:          g = (s + 8)/(8 pi) (n.h)^s 4 (n.l)(v.h)
        ashikhmin_shirley  f = (s + 1)/(8 pi) (n.h)^s / ((v.h) max(n.l, n.v)) [x F]:
                                                                      g = (s + 1)/(2 pi) (n.h)^s (n.l) / max(n.l, n.v)
    with s = 2 / alpha^2 - 2 for the last two (ndf_name, masking_name are then unused)."""
    if channels_name == "multiscatter_cloth":
        return cloth_integrand_for(ndf_name, masking_name)
    if channels_name in SHEEN_LAYOUTS:
        return sheen_integrand_for(channels_name)
    ch, vec = channels_for(channels_name)
    if form == "microfacet":
        D = sets.NDFS[ndf_name].D
        G2 = sets.G2_for(ndf_name, masking_name)

        @wp.func
        def weight(v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha: float):
            return D(h, alpha) * G2(v[2], l[2], h[2], VoH, alpha) * VoH / v[2]
    elif form == "blinn_phong":

        @wp.func
        def weight(v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha: float):
            s = ndf.shininess_from_alpha(alpha)
            return (s + 8.0) / (8.0 * wp.pi) * wp.exp(s * ndf.log_cos(h)) * 4.0 * l[2] * VoH
    elif form == "ashikhmin_shirley":

        @wp.func
        def weight(v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha: float):
            s = ndf.shininess_from_alpha(alpha)
            return (s + 1.0) / (2.0 * wp.pi) * wp.exp(s * ndf.log_cos(h)) * l[2] / wp.max(l[2], v[2])
    else:
        raise KeyError(form)

    @wp.func
    def integrand(v: wp.vec3, h: wp.vec3, alpha: float, param: float):
        l = reflect(v, h)
        NoL = l[2]
        NoV = v[2]
        VoH = wp.dot(v, h)
        if NoL <= COS_EPS or VoH <= COS_EPS or NoV <= COS_EPS or h[2] <= 0.0:
            return vec()
        return ch(VoH, param) * weight(v, h, l, VoH, alpha)

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


@functools.lru_cache(maxsize=None)
def cloth_integrand_for(ndf_name: str, masking_name: str):
    """(Fc s, s, D_charlie V_ashikhmin (n.l) 4 (v.h)) with s = D G2 (v.h)/(n.v): the multiscatter
    channels plus Filament's cloth DV (DFV_Charlie_Uniform), 0 where n.l or v.h <= COS_EPS (back-facing)."""
    D = sets.NDFS[ndf_name].D
    G2 = sets.G2_for(ndf_name, masking_name)

    @wp.func
    def integrand(v: wp.vec3, h: wp.vec3, alpha: float, param: float):
        l = reflect(v, h)
        NoL = l[2]
        NoV = v[2]
        VoH = wp.dot(v, h)
        if NoL <= COS_EPS or VoH <= COS_EPS or NoV <= COS_EPS:
            return wp.vec3()
        spec = D(h, alpha) * G2(NoV, NoL, h[2], VoH, alpha) * VoH / NoV
        cloth = ndf.D_charlie(h, alpha) * masking.V_ashikhmin(NoV, NoL) * NoL * 4.0 * VoH
        return channels_multiscatter3(VoH, param) * spec + wp.vec3(0.0, 0.0, cloth)

    return integrand


@functools.lru_cache(maxsize=None)
def sheen_integrand_for(layout: str):
    """The sheen lobe f = D_charlie(h; alpha) V (KHR_materials_sheen, no Fresnel) alone, as g(h) = f (n.l) 4 (v.h):
        charlie       (0, 0, D_charlie V_ashikhmin (n.l) 4 (v.h))   the glTF Sample Viewer's lut_charlie (read .b)
        sheen_albedo  (D_charlie V_charlie (n.l) 4 (v.h), D_charlie V_ashikhmin (n.l) 4 (v.h))
                      R: E(mu) with the spec's Charlie visibility, G: with Ashikhmin's
    0 where n.l, v.h or n.v <= COS_EPS (back-facing). alpha is the texel's alpha (roughness = "alpha": the
    sheenRoughness itself, as the KHR spec's D and Lambda fit use it). The ``*_clamped`` layouts clamp each V
    to [0, 1], as the glTF Sample Viewer's V_Ashikhmin (ibl_filtering.frag) and V_Sheen (brdf.glsl) do."""
    clamped = layout.endswith("_clamped")
    vmax = 1.0 if clamped else 1.0e30
    base = layout.removesuffix("_clamped")

    @wp.func
    def integrand(v: wp.vec3, h: wp.vec3, alpha: float, param: float):
        l = reflect(v, h)
        NoL = l[2]
        NoV = v[2]
        VoH = wp.dot(v, h)
        if NoL <= COS_EPS or VoH <= COS_EPS or NoV <= COS_EPS:
            return wp.vec3()
        d = ndf.D_charlie(h, alpha) * NoL * 4.0 * VoH
        ash = d * wp.min(masking.V_ashikhmin(NoV, NoL), wp.static(vmax))
        if wp.static(base == "charlie"):
            return wp.vec3(0.0, 0.0, ash)
        return wp.vec3(d * wp.min(masking.V_charlie(NoV, NoL, alpha), wp.static(vmax)), ash, 0.0)

    return integrand


ESTIMATORS = {
    "gauss_legendre": "deterministic product Gauss-Legendre over panels in theta_h (or CDF(theta_h)) and phi, "
    "split exactly at the horizon (default; converges exponentially)",
    "sobol_vndf": "scrambled Sobol' points, GGX visible-normal sampling (Dupuy & Benyoub 2023)",
    "sobol_ndf": "scrambled Sobol' points, NDF importance sampling of D(h)(n.h)",
    "hammersley_ndf": "Hammersley points, NDF importance sampling (Filament cmgen's estimator)",
}
DEFAULT_SAMPLES = {"gauss_legendre": 432, "sobol_vndf": 4096, "sobol_ndf": 4096, "hammersley_ndf": 1024}


def kernel_for(ndf_name: str, masking_name: str, channels_name: str, estimator: str, form: str = "microfacet"):
    """The table kernel for a (terms, channels, estimator, integrand form) key; compiled once per Warp cache.
    For the forms blinn_phong and ashikhmin_shirley ``ndf_name`` names the NDF the estimator samples
    (blinn_phong) and ``masking_name`` is ignored."""
    if form != "microfacet":
        masking_name = "none"
    return _kernel_for(ndf_name, masking_name, channels_name, estimator, form)


@functools.lru_cache(maxsize=None)
def _kernel_for(ndf_name: str, masking_name: str, channels_name: str, estimator: str, form: str):
    nd = sets.NDFS[ndf_name]
    g = integrand_for(ndf_name, masking_name, channels_name, form)
    vec = wp.vec3 if channels_name in ("multiscatter_cloth",) + SHEEN_LAYOUTS else channels_for(channels_name)[1]
    acc = wp.vec3d if vec is wp.vec3 else wp.vec2d
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


def samples_note(estimator: str, samples: int | None) -> str:
    """Why ``effective_samples`` differs from the ``samples`` asked for ('' when it does not)."""
    if samples is None or effective_samples(estimator, samples) == samples:
        return ""
    if estimator == "gauss_legendre":
        n = gl_order(samples)
        return (
            f"samples = {samples} asked; gauss_legendre integrates 3 regions x n x n points with "
            f"n = round(sqrt({samples} / 3)) = {n}: 3 x {n}^2 = {3 * n * n}"
        )
    if estimator.startswith("sobol"):
        return (
            f"samples = {samples} asked; Sobol' points come in powers of two: {effective_samples(estimator, samples)}"
        )
    return ""


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


def integrate(
    kernel,
    nov: np.ndarray,
    alpha: np.ndarray,
    estimator: str,
    samples: int,
    seed: int,
    nch: int,
    device: str = "cpu",
    param: np.ndarray | None = None,
) -> np.ndarray:
    """Run one launch over texels (nov[i], alpha[i], param[i]) -> float64 array (len, nch);
    ``param`` (the integrand's per-texel scalar, e.g. f0) defaults to 0."""
    n = len(nov)
    out = wp.zeros((n, nch), dtype=wp.float64, device=device)
    if param is None:
        param = np.zeros(n, dtype=np.float32)
    inputs = [
        wp.array(np.ascontiguousarray(nov, dtype=np.float32), dtype=float, device=device),
        wp.array(np.ascontiguousarray(alpha, dtype=np.float32), dtype=float, device=device),
        wp.array(np.ascontiguousarray(param, dtype=np.float32), dtype=float, device=device),
    ]
    inputs += point_arrays(estimator, samples, seed, device)
    wp.launch(kernel, dim=n, inputs=inputs + [out], device=device)
    return out.numpy()


def load(kernel, device: str = "cpu") -> None:
    """Compile (or load from Warp's cache) a kernel's module before worker threads launch it."""
    wp.load_module(kernel.module, device=device)


ERROR_PROBE_TEXELS = 256  # texels re-integrated at a higher budget for lutbake:error_estimate


def probe_indices(nov: np.ndarray) -> np.ndarray:
    """A strided subset of texels plus the most grazing ones (where every estimator converges slowest)."""
    n = len(nov)
    strided = np.arange(0, n, max(1, n // ERROR_PROBE_TEXELS))
    grazing = np.flatnonzero(nov <= nov.min())
    return np.unique(np.concatenate([strided, grazing[:: max(1, len(grazing) // 64)]]))


def hemisphere_plan(
    *,
    key: tuple,
    nov: np.ndarray,
    alpha: np.ndarray,
    param: np.ndarray | None,
    samples: int | None,
    seed: int,
    nch: int,
    kernel_channels: int = 2,
    **plan_fields,
) -> Plan:
    """The plan of every table that is a per-texel integral of ``kernel_for(*key)``: texel i integrates
    (nov[i], alpha[i], param[i]); the first ``nch`` of the kernel's channels are kept.

    Its error estimate re-integrates probe_indices() at a higher budget: Gauss-Legendre at order n + 4
    (the difference bounds the error of order n, the higher rule being far more accurate), QMC with
    another scrambling seed (the difference is ~sqrt(2) times the error)."""
    est = key[3]  # kernel_for(ndf, masking, channels, estimator[, form])
    samples = samples or DEFAULT_SAMPLES[est]
    param = np.zeros(len(nov), np.float32) if param is None else param

    def run(idx, budget, s, device):
        k = kernel_for(*key)
        return integrate(k, nov[idx], alpha[idx], est, budget, s, kernel_channels, device, param[idx])[:, :nch]

    def run_tile(start: int, stop: int, device: str) -> np.ndarray:
        return run(slice(start, stop), samples, seed, device)

    def error_estimate(data: np.ndarray, device: str) -> tuple[float, str]:
        idx = probe_indices(nov)
        if est == "gauss_legendre":
            n = gl_order(samples)
            other, how = run(idx, 3 * (n + 4) ** 2, seed, device), f"max |order {n} - order {n + 4}|"
        else:
            other, how = run(idx, samples, seed + 1, device), "max |seed - (seed + 1)| (two scramblings)"
        err = float(np.max(np.abs(data.reshape(len(nov), nch)[idx] - other)))
        return err, f"{how} over {len(idx)} probe texels (strided + most grazing NoV)"

    eff = effective_samples(est, samples)
    return Plan(
        n_texels=len(nov),
        n_channels=nch,
        run_tile=run_tile,
        prepare=lambda d: load(kernel_for(*key), d),
        samples=eff,
        estimator=est,
        cost=float(len(nov)) * eff,
        error_estimate=error_estimate,
        **plan_fields,
    )
