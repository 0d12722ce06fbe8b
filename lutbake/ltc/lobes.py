"""The lobes an LTC table fits: f(v, l) (n.l) with F = 1, a sampler of l and its density, as ``@wp.func``s.

Every lobe is evaluated in the shading frame (n = +z, v in the xz-plane, v.x >= 0) from lutbake's own terms
(lutbake.terms). The sampler and density only serve the fit's error estimate (Heitz et al. 2016, the MIS
estimate of the L3 distance; lutbake.ltc.fit), so any sampler that covers the lobe is correct; for GGX and
Beckmann they are exactly ltc_code's (selfshadow/ltc_code fit/brdf_ggx.h, fit/brdf_beckmann.h: NDF sampling
with phi = 2 pi u1 and the slope radius from u2, pdf = D (n.h) / (4 |v.h|)), so lutbake's error metric and
ltc_code's agree sample for sample on GGX.

| lobe | f (n.l) | sampler |
| --- | --- | --- |
| ggx | D_ggx G2 / (4 n.v), height-correlated Smith (ltc_code's BrdfGGX) | NDF (tan^2 = alpha^2 u/(1 - u)) |
| beckmann | D_beckmann G2 / (4 n.v), height-correlated Smith, exact Lambda (ltc_code: Walter's fit) | NDF, log |
| charlie | D_charlie V_ashikhmin (n.l) (the gltf-charlie preset's lobe, alpha = sheenRoughness) | cosine |
| lambert | (n.l) / pi (the identity LTC: a check) | cosine |
| gotanda | Gotanda 2014 Eq. 4 (GGX alpha = sigma, Eq. 6 facets, f0 = 0), tabulated per texel | cosine |
| eon | energy-preserving Oren-Nayar (Portsmouth et al. 2024; OpenPBR), rho = 1, exact albedo | cosine |
| zeltner | Zeltner et al. 2022's analytic volumetric sheen (lutbake.terms.sheen_volume), sigma = alpha^2 | cosine |

A tabulated lobe (``Lobe.tabulate``: gotanda) takes two more arguments, its per-texel table and the texel index:
f_cos(v, l, alpha, tab, t) (lutbake.ltc.tabulated); lutbake.ltc.fit adapts the others.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import warp as wp

from ..edge import COS_EPS
from ..runtime.warp_runtime import kernel_factory
from ..terms import diffuse, masking, ndf, sheen_volume
from ..terms.frame import reflect
from .tabulated import gotanda_f_cos, tabulate_gotanda

INV_PI = 0.31830988618379067


@wp.func
def pdf_reflected_ndf(D_h: float, h: wp.vec3, v: wp.vec3):
    """Density of l = reflect(v, h) when h is drawn from D(h)(n.h): D (n.h) / (4 |v.h|) (Walter et al. 2007,
    Eq. 14 and 38), as ltc_code's brdf_*.h (0 where v.h = 0)."""
    VoH = wp.abs(wp.dot(v, h))
    if VoH <= COS_EPS:
        return 0.0
    return D_h * wp.abs(h[2]) / (4.0 * VoH)


@wp.func
def half_vector(v: wp.vec3, l: wp.vec3):
    """h = normalize(v + l); (0, 0, 1) where v + l = 0."""
    s = v + l
    n = wp.length(s)
    if n <= 0.0:
        return wp.vec3(0.0, 0.0, 1.0)
    return s / n


@wp.func
def smith_f_cos(D_h: float, Lambda_v: float, Lambda_l: float, NoV: float, NoL: float):
    """f (n.l) = D G2 / (4 n.v) with height-correlated Smith G2 = 1 / (1 + Lambda(v) + Lambda(l))
    (Heitz 2014, Eq. 99); 0 for a back-facing l or v."""
    if NoL <= COS_EPS or NoV <= COS_EPS:
        return 0.0
    return D_h * masking.G2_smith_height_correlated(Lambda_v, Lambda_l) / (4.0 * NoV)


@wp.func
def D_ggx_abs(h: wp.vec3, alpha: float):
    """D_ggx evaluated at the upper-hemisphere mirror of h (ltc_code's D uses (n.h)^4 and slopes, even in n.h):
    only the sampling density needs it, for h with n.h < 0 (l far below the horizon)."""
    return ndf.D_ggx(wp.vec3(h[0], h[1], wp.abs(h[2])), alpha)


@wp.func
def D_beckmann_abs(h: wp.vec3, alpha: float):
    """D_beckmann at the upper-hemisphere mirror of h (see D_ggx_abs)."""
    return ndf.D_beckmann(wp.vec3(h[0], h[1], wp.abs(h[2])), alpha)


@wp.func
def slope_radius_ggx(alpha: float, u: float):
    """ltc_code BrdfGGX::sample: slope radius alpha sqrt(u / (1 - u)) (the GGX NDF's inverse CDF in tan theta_h)."""
    return alpha * wp.sqrt(u / (1.0 - u))


@wp.func
def slope_radius_beckmann(alpha: float, u: float):
    """ltc_code BrdfBeckmann::sample: slope radius alpha sqrt(-log u)."""
    return alpha * wp.sqrt(-wp.log(u))


def microfacet_lobe(D_abs, Lambda, slope_radius):
    """(f_cos, sample, pdf, f_pdf) of a microfacet lobe with height-correlated Smith masking:
    f (n.l) = D(h) G2 / (4 n.v) (ltc_code Brdf*::eval), l = reflect(v, h) with h of slope radius
    slope_radius(alpha, u2) at azimuth 2 pi u1, density D (n.h) / (4 |v.h|)."""

    @wp.func
    def f_pdf(v: wp.vec3, l: wp.vec3, alpha: float):
        h = half_vector(v, l)
        d = D_abs(h, alpha)  # = D(h) wherever f != 0 (n.l, n.v > 0 imply n.h > 0)
        f = smith_f_cos(d, Lambda(v[2], alpha), Lambda(l[2], alpha), v[2], l[2])
        return wp.vec2(f, pdf_reflected_ndf(d, h, v))

    @wp.func
    def f_cos(v: wp.vec3, l: wp.vec3, alpha: float):
        return f_pdf(v, l, alpha)[0]

    @wp.func
    def pdf(v: wp.vec3, l: wp.vec3, alpha: float):
        return f_pdf(v, l, alpha)[1]

    @wp.func
    def sample(v: wp.vec3, alpha: float, u1: float, u2: float):
        phi = 2.0 * wp.pi * u1
        r = slope_radius(alpha, u2)
        h = wp.normalize(wp.vec3(r * wp.cos(phi), r * wp.sin(phi), 1.0))
        return reflect(v, h)

    return f_cos, sample, pdf, f_pdf


GGX_FUNCS = microfacet_lobe(D_ggx_abs, masking.Lambda_ggx, slope_radius_ggx)
BECKMANN_FUNCS = microfacet_lobe(D_beckmann_abs, masking.Lambda_beckmann, slope_radius_beckmann)


@wp.func
def charlie_f_cos(v: wp.vec3, l: wp.vec3, alpha: float):
    """KHR_materials_sheen lobe as the gltf-charlie table: D_charlie(h; alpha) V_ashikhmin (n.l), no Fresnel."""
    if l[2] <= COS_EPS or v[2] <= COS_EPS:
        return 0.0
    h = half_vector(v, l)
    return ndf.D_charlie(h, alpha) * masking.V_ashikhmin(v[2], l[2]) * l[2]


@wp.func
def lambert_f_cos(v: wp.vec3, l: wp.vec3, alpha: float):
    """Lambert: (n.l) / pi (alpha unused)."""
    if l[2] <= COS_EPS or v[2] <= COS_EPS:
        return 0.0
    return l[2] * INV_PI


@wp.func
def cosine_sample(v: wp.vec3, alpha: float, u1: float, u2: float):
    """Cosine-weighted hemisphere (as ltc_code's LTC::sample of the clamped cosine): phi = 2 pi u2, cos = sqrt(u1)."""
    phi = 2.0 * wp.pi * u2
    s = wp.sqrt(wp.max(1.0 - u1, 0.0))
    return wp.vec3(s * wp.cos(phi), s * wp.sin(phi), wp.sqrt(u1))


@wp.func
def cosine_pdf(v: wp.vec3, l: wp.vec3, alpha: float):
    return wp.max(l[2], 0.0) * INV_PI


@wp.func
def charlie_f_pdf(v: wp.vec3, l: wp.vec3, alpha: float):
    return wp.vec2(charlie_f_cos(v, l, alpha), cosine_pdf(v, l, alpha))


@wp.func
def lambert_f_pdf(v: wp.vec3, l: wp.vec3, alpha: float):
    return wp.vec2(lambert_f_cos(v, l, alpha), cosine_pdf(v, l, alpha))


@wp.func
def eon_f_cos(v: wp.vec3, l: wp.vec3, r: float):
    """EON (lutbake.terms.diffuse.Fd_eon) for rho = 1 times (n.l); r = OpenPBR's base_diffuse_roughness."""
    if l[2] <= COS_EPS or v[2] <= COS_EPS:
        return 0.0
    return diffuse.Fd_eon(1.0, l[2], v[2], wp.dot(l, v), r) * l[2]


@wp.func
def eon_f_pdf(v: wp.vec3, l: wp.vec3, r: float):
    return wp.vec2(eon_f_cos(v, l, r), cosine_pdf(v, l, r))


@wp.func
def zeltner_f_pdf(v: wp.vec3, l: wp.vec3, alpha: float):
    return wp.vec2(sheen_volume.f_cos_sheen_approx(v, l, alpha), cosine_pdf(v, l, alpha))


@wp.func
def gotanda_pdf(v: wp.vec3, l: wp.vec3, alpha: float, tab: wp.array3d(dtype=float), t: int):
    return cosine_pdf(v, l, alpha)


@wp.func
def gotanda_f_pdf(v: wp.vec3, l: wp.vec3, alpha: float, tab: wp.array3d(dtype=float), t: int):
    return wp.vec2(gotanda_f_cos(v, l, alpha, tab, t), cosine_pdf(v, l, alpha))


@kernel_factory
def cosine_sampled(f_cos):
    """(f_cos guarded, f_pdf) of a plugin's lobe (lutbake.plugins.register_brdf): 0 where n.l or n.v <= COS_EPS
    (back-facing), sampled cosine-weighted (cosine_sample, cosine_pdf)."""

    @wp.func
    def guarded(v: wp.vec3, l: wp.vec3, x: float):
        if l[2] <= COS_EPS or v[2] <= COS_EPS:
            return 0.0
        return f_cos(v, l, x)

    @wp.func
    def f_pdf(v: wp.vec3, l: wp.vec3, x: float):
        return wp.vec2(guarded(v, l, x), cosine_pdf(v, l, x))

    return guarded, f_pdf


def custom_lobe(name: str, f_cos, roughness: str, origin: str) -> Lobe:
    """The Lobe of a plugin's cosine-weighted BRDF f(l, v)(n.l): cosine-sampled, its magnitude integrated from the
    lobe itself; ``roughness``: Lobe.roughness ("alpha", "perceptual" or "none"); ``origin``: the plugin text's
    sha256 (Lobe.origin)."""
    guarded, f_pdf = cosine_sampled(f_cos)
    return Lobe(name, guarded, cosine_sample, cosine_pdf, f_pdf, "lobe_adaptive", roughness, origin=origin)


@dataclass(frozen=True)
class Lobe:
    """A lobe the ltc kind fits (its name, description and citation: its record, lutbake.records)."""

    name: str
    f_cos: object
    sample: object
    pdf: object
    f_pdf: object  # (f_cos, pdf) at once, sharing the terms both need
    magnitude: str  # how the magnitude / Fresnel channels are integrated (lutbake.ltc.magnitude)
    roughness: str  # "perceptual": x = r, alpha = r^2; "alpha": x = alpha; "sigma": x = sigma, GGX alpha = sigma;
    # "diffuse_roughness": x = the model's own roughness (EON's r), passed to the lobe as its parameter; "none"
    tabulate: object = None  # host (v (n, 3), alpha (n,), device, workers) -> per-texel table, or None (closed form)
    free_frame: bool = False  # fit the frame angle too (4 parameters, lutbake.ltc.fit.Problem.matrices), not only
    # ltc_code's 3 with Z = the lobe's average direction
    normal_frame: bool = False  # fit Zeltner et al. 2022's M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]] in the normal's
    # frame (2 parameters, lutbake.ltc.fit.Problem.matrices) instead of ltc_code's lobe-average frame
    origin: str = ""  # a plugin's lobe: the sha256 of its text (fits are memoised per (name, origin): lutbake.ltc.fit)
    general_frame: bool = False  # a lobe not symmetric about the plane of incidence (lutbake.ltc.aniso): M fitted in
    # the general 5-parameter form (lutbake.ltc.fit.general_matrices), the frame Z = the lobe's 3D average direction


LOBES = {
    "ggx": Lobe(
        "ggx",
        *GGX_FUNCS,
        "dfg:ggx",
        "perceptual",
    ),
    "beckmann": Lobe(
        "beckmann",
        *BECKMANN_FUNCS,
        "dfg:beckmann",
        "perceptual",
    ),
    "charlie": Lobe(
        "charlie",
        charlie_f_cos,
        cosine_sample,
        cosine_pdf,
        charlie_f_pdf,
        "dfg:charlie",
        "alpha",
        free_frame=True,
    ),
    "lambert": Lobe(
        "lambert",
        lambert_f_cos,
        cosine_sample,
        cosine_pdf,
        lambert_f_pdf,
        "lambert",
        "none",
    ),
    "gotanda": Lobe(
        "gotanda",
        gotanda_f_cos,
        cosine_sample,
        gotanda_pdf,
        gotanda_f_pdf,
        "diffuse:microfacet",
        "sigma",
        tabulate_gotanda,
    ),
    "eon": Lobe(
        "eon",
        eon_f_cos,
        cosine_sample,
        cosine_pdf,
        eon_f_pdf,
        "diffuse:eon",
        "diffuse_roughness",
    ),
    "zeltner": Lobe(
        "zeltner",
        sheen_volume.f_cos_sheen_approx,
        cosine_sample,
        cosine_pdf,
        zeltner_f_pdf,
        "lobe",
        "alpha",
        normal_frame=True,
    ),
}


@functools.lru_cache(maxsize=None)
def lobe(name) -> Lobe:
    """``name`` itself if it is a Lobe (a record's object: a plugin's lobe), else lutbake's lobe of that name."""
    if isinstance(name, Lobe):
        return name
    if name not in LOBES:
        raise KeyError(f"unknown LTC lobe {name!r}; valid: {', '.join(LOBES)}")
    return LOBES[name]
