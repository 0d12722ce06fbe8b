"""Integrands of the specular tables: g(h) per texel, for the hemisphere estimators of lutbake.sampling.hemisphere.

Cook-Torrance microfacet BRDF (Gotanda 2014 course notes, Eq. 1):
    f(l, v) = D(h) F(v.h) G2(l, v, h) / (4 (n.l)(n.v))
In the half-vector measure (see lutbake.sampling.hemisphere) the integrand is
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

from dataclasses import dataclass

import numpy as np
import warp as wp

from .. import metals
from ..edge import COS_EPS, effective_alpha
from ..runtime.warp_runtime import kernel_factory
from ..terms import fresnel as fresnel_terms
from ..terms import masking, ndf
from ..terms.distributions import Distribution, distribution
from ..terms.frame import reflect

# the sheen lobe alone: no GGX term (sheen_integrand_for); *_clamped: V clamped to [0, 1] (the viewer's shaders)
SHEEN_LAYOUTS = ("charlie", "sheen_albedo", "charlie_clamped", "sheen_albedo_clamped", "sheen_fgd")


def fc_of(fresnel):
    """``Fc(c)`` of a Fresnel record linear in f0, F = f0 + (1 - f0) Fc(c) (lutbake.records): its own ``Fc`` where it
    has one (Schlick's (1 - c)^5), else F(0, c). None: Schlick's."""
    if fresnel is None:
        return fresnel_terms.Fc_schlick
    if fresnel.get("Fc") is not None:
        return fresnel["Fc"]
    F = fresnel["F"]

    @wp.func
    def Fc(c: float):
        return F(0.0, c)

    return Fc


@kernel_factory
def split_channels(fresnel=None) -> dict:
    """The split-sum channel sets of a Fresnel linear in f0, F = f0 (1 - Fc) + Fc (Karis 2013):
    scale_bias (1 - Fc, Fc) -> E = f0 scale + bias; multiscatter (Fc, 1) -> E = mix(R, G, f0)."""
    Fc = fc_of(fresnel)

    @wp.func
    def channels_scale_bias(VoH: float, f0: float):
        w = Fc(VoH)
        return wp.vec2(1.0 - w, w)

    @wp.func
    def channels_multiscatter(VoH: float, f0: float):
        return wp.vec2(Fc(VoH), 1.0)

    return {"scale_bias": channels_scale_bias, "multiscatter": channels_multiscatter}


@wp.func
def channels_albedo(VoH: float, f0: float):
    return wp.vec2(1.0, 0.0)


@kernel_factory
def fresnel_channels(fresnel):
    """specular_3d: R = F(f0, v.h) of the Fresnel record for the texel's f0 (the kernel's per-texel param); G unused
    (0)."""
    F = fresnel["F"]

    @wp.func
    def channels_F(VoH: float, f0: float):
        return wp.vec2(F(f0, VoH), 0.0)

    return channels_F


# Blender EEVEE's F82-tint layout: (1 - Fc, Fc, (v.h)(1 - v.h)^6)
@wp.func
def channels_scale_bias_f82(VoH: float, f0: float):
    Fc = fresnel_terms.Fc_schlick(VoH)
    return wp.vec3(1.0 - Fc, Fc, VoH * Fc * wp.clamp(1.0 - VoH, 0.0, 1.0))


@wp.func
def channels_multiscatter3(VoH: float, f0: float):
    return wp.vec3(fresnel_terms.Fc_schlick(VoH), 1.0, 0.0)


@dataclass(frozen=True)
class ChannelSet:
    """What a specular table's kernel returns per h: ``length`` channels (the kernel vector), of which a table keeps
    ``stored`` (lutbake.layouts name them); ``fresnel``: the channels take the config's Fresnel (linear in f0 for the
    split-sum pairs; any for "F"); ``charlie``: a Charlie lobe with its own integrand (charlie_pair_for)."""

    name: str
    length: int
    stored: int
    fresnel: bool = False
    charlie: bool = False


CHANNEL_SETS = {
    c.name: c
    for c in (
        ChannelSet("scale_bias", 2, 2, fresnel=True),
        ChannelSet("multiscatter", 2, 2, fresnel=True),
        ChannelSet("albedo", 2, 2),
        ChannelSet("F", 2, 1, fresnel=True),
        ChannelSet("scale_bias_f82", 3, 3),
        ChannelSet("metal", 3, 3),
        ChannelSet("multiscatter_cloth", 3, 3, charlie=True),
        *(ChannelSet(n, 3, 3 if n.startswith("charlie") else 2, charlie=True) for n in SHEEN_LAYOUTS),
    )
}
N_CHANNELS = {name: c.stored for name, c in CHANNEL_SETS.items()}


# the metals' complex indices as one constant table, row i = METAL_ORDER[i]: (n_R, n_G, n_B, k_R, k_G, k_B). Every
# metal table runs the one "metal" integrand (its per-texel param is the row), so a batch compiles one kernel module
# for all of them (a module per metal before: ~1 s of compile each on a new machine)
METAL_ORDER = tuple(metals.METALS)
METAL_NK = wp.constant(
    wp.types.matrix(shape=(len(METAL_ORDER), 6), dtype=float)(
        *[float(x) for name in METAL_ORDER for x in (*metals.METALS[name].n, *metals.METALS[name].k)]
    )
)


def metal_param(name: str) -> float:
    """The per-texel param of the "metal" channels: the metal's row of METAL_NK."""
    return float(METAL_ORDER.index(metals.lookup_metal(name).name))


@wp.func
def channels_metal(VoH: float, row: float):
    """RGB = F_conductor(n_c + i k_c, v.h) of the metal in row ``row`` of METAL_NK (lutbake.metals)."""
    m = METAL_NK
    i = int(row)
    return wp.vec3(
        fresnel_terms.F_conductor(m[i, 0], m[i, 3], VoH),
        fresnel_terms.F_conductor(m[i, 1], m[i, 4], VoH),
        fresnel_terms.F_conductor(m[i, 2], m[i, 5], VoH),
    )


@kernel_factory
def channels_for(channels_name: str, fresnel=None):
    """(channel wp.func (VoH, param) -> vec, vec type) of a CHANNEL_SETS name: the split-sum pairs of ``fresnel``
    (a Fresnel record linear in f0; None: Schlick's), "F" for F(f0, v.h) of ``fresnel`` itself (specular_3d), "metal"
    for RGB = F_conductor(n_c, k_c, v.h) of the metal whose METAL_NK row is the param (metal_param)."""
    vec = wp.vec3 if CHANNEL_SETS[channels_name].length == 3 else wp.vec2
    fixed = {
        "albedo": channels_albedo,
        "scale_bias_f82": channels_scale_bias_f82,
        "metal": channels_metal,
    }
    if channels_name in fixed:
        return fixed[channels_name], vec
    if channels_name == "F":
        return fresnel_channels(fresnel), vec
    return split_channels(fresnel)[channels_name], vec


def half_vector_integrand(lobe, vec, skip_below_horizon_h: bool):
    """g(v, h, alpha, param) = lobe(v, h, l, v.h, alpha, param) with l = reflect(v, h), and 0 (``vec()``) where n.l,
    v.h or n.v <= COS_EPS (back-facing; also n.h <= 0 if ``skip_below_horizon_h``): the common prologue of every
    specular integrand."""

    @wp.func
    def integrand(v: wp.vec3, h: wp.vec3, alpha: float, param: float):
        l = reflect(v, h)
        VoH = wp.dot(v, h)
        if l[2] <= COS_EPS or VoH <= COS_EPS or v[2] <= COS_EPS or (wp.static(skip_below_horizon_h) and h[2] <= 0.0):
            return vec()
        return lobe(v, h, l, VoH, alpha, param)

    return integrand


def charlie_integrands(lobe, vec):
    """(g, g_sin2) of a lobe with a Charlie NDF, ``lobe(v, h, l, v.h, alpha, param, D)`` given D's value:
    ``g(v, h, alpha, param)`` with D = D_charlie of the float32 h (the QMC estimators), ``g_sin2(v, h, alpha,
    param, sin2)`` with D = D_charlie_sin2 of sin^2(theta_h) in float64 (the gauss_legendre panel rules pass their
    node's: sin^(1/alpha) multiplies a float32 h's rounding by 1 / (2 alpha), 5e3 at alpha = 1e-4). Both 0 where
    n.l, v.h or n.v <= COS_EPS (half_vector_integrand's prologue) and where n.h <= 0 (D_charlie = 0 there)."""

    @wp.func
    def lobe32(v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha: float, param: float):
        return lobe(v, h, l, VoH, alpha, param, ndf.D_charlie(h, alpha))

    @wp.func
    def g_sin2(v: wp.vec3, h: wp.vec3, alpha: float, param: float, sin2: wp.float64):
        l = reflect(v, h)
        VoH = wp.dot(v, h)
        if l[2] <= COS_EPS or VoH <= COS_EPS or v[2] <= COS_EPS or h[2] <= 0.0:
            return vec()
        return lobe(v, h, l, VoH, alpha, param, ndf.D_charlie_sin2(sin2, alpha))

    return half_vector_integrand(lobe32, vec, False), g_sin2


@kernel_factory
def weight_for(nd, masking_name: str, form: str):
    """f (n.l) 4 (v.h) / F of an integrand form (``integrand_for``) at (v, h, l, v.h, alpha)."""
    if form == "microfacet":
        D = distribution(nd).D
        G2 = distribution(nd).G2(masking_name)

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
    return weight


@kernel_factory
def integrand_for(nd, masking_name: str, channels_name: str, form: str = "microfacet", fresnel=None):
    """g(h) = f(l, v) (n.l) 4 (v.h) * channels(v.h, param), 0 where n.l, v.h or n.v <= COS_EPS (back-facing).
    ``form`` (model_terms):
        microfacet         f = D G2 / (4 (n.l)(n.v)) [x F]:          g = D G2 (v.h) / (n.v)
        blinn_phong        f = (s + 8)/(8 pi) (n.h)^s [x F]:          g = (s + 8)/(8 pi) (n.h)^s 4 (n.l)(v.h)
        ashikhmin_shirley  f = (s + 1)/(8 pi) (n.h)^s / ((v.h) max(n.l, n.v)) [x F]:
                                                                      g = (s + 1)/(2 pi) (n.h)^s (n.l) / max(n.l, n.v)
    with s = 2 / alpha^2 - 2 for the last two (nd, masking_name are then unused)."""
    charlie = charlie_pair_for(nd, masking_name, channels_name)
    if charlie is not None:
        return charlie[0]
    ch, vec = channels_for(channels_name, fresnel)
    weight = weight_for(nd, masking_name, form)

    @wp.func
    def lobe(v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha: float, param: float):
        return ch(VoH, param) * weight(v, h, l, VoH, alpha)

    return half_vector_integrand(lobe, vec, True)


def charlie_pair_for(nd, masking_name: str, channels_name: str):
    """(g, g_sin2) of the channels with a Charlie lobe (charlie_integrands: the cloth and sheen layouts), else None."""
    if channels_name == "multiscatter_cloth":
        return cloth_integrand_for(nd, masking_name)
    if channels_name in SHEEN_LAYOUTS:
        return sheen_integrand_for(channels_name)
    return None


@kernel_factory
def cloth_integrand_for(nd, masking_name: str):
    """(Fc s, s, D_charlie V_ashikhmin (n.l) 4 (v.h)) with s = D G2 (v.h)/(n.v): the multiscatter
    channels plus Filament's cloth DV (DFV_Charlie_Uniform), 0 where n.l or v.h <= COS_EPS (back-facing): (g, g_sin2),
    charlie_integrands."""
    weight = weight_for(nd, masking_name, "microfacet")

    @wp.func
    def lobe(v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha: float, param: float, dch: float):
        cloth = dch * masking.V_ashikhmin(v[2], l[2]) * l[2] * 4.0 * VoH
        return channels_multiscatter3(VoH, param) * weight(v, h, l, VoH, alpha) + wp.vec3(0.0, 0.0, cloth)

    return charlie_integrands(lobe, wp.vec3)


@kernel_factory
def sheen_integrand_for(layout: str):
    """The sheen lobe f = D_charlie(h; alpha) V (KHR_materials_sheen, no Fresnel) alone, as g(h) = f (n.l) 4 (v.h):
        charlie       (0, 0, D_charlie V_ashikhmin (n.l) 4 (v.h))   the glTF Sample Viewer's lut_charlie (read .b)
        sheen_albedo  (D_charlie V_charlie (n.l) 4 (v.h), D_charlie V_ashikhmin (n.l) 4 (v.h))
                      R: E(mu) with the spec's Charlie visibility, G: with Ashikhmin's
        sheen_fgd     (D_charlie V_charlie Fc (n.l) 4 (v.h), D_charlie V_charlie (n.l) 4 (v.h)), Fc = (1 - v.h)^5:
                      the multiscatter pair of the sheen lobe (Unity HDRP PreIntegratedFGD_CharlieFabricLambert)
    0 where n.l, v.h or n.v <= COS_EPS (back-facing): (g, g_sin2), charlie_integrands. alpha is the texel's alpha
    (roughness = "alpha": the sheenRoughness itself, as the KHR spec's D and Lambda fit use it). The ``*_clamped``
    layouts clamp each V to [0, 1], as the glTF Sample Viewer's V_Ashikhmin (ibl_filtering.frag) and V_Sheen
    (brdf.glsl) do."""
    clamped = layout.endswith("_clamped")
    vmax = 1.0 if clamped else 1.0e30
    base = layout.removesuffix("_clamped")

    @wp.func
    def lobe(v: wp.vec3, h: wp.vec3, l: wp.vec3, VoH: float, alpha: float, param: float, dch: float):
        NoL = l[2]
        NoV = v[2]
        d = dch * NoL * 4.0 * VoH
        ash = d * wp.min(masking.V_ashikhmin(NoV, NoL), wp.static(vmax))
        if wp.static(base == "charlie"):
            return wp.vec3(0.0, 0.0, ash)
        if wp.static(base == "sheen_fgd"):
            dc = d * masking.V_charlie(NoV, NoL, alpha)
            return wp.vec3(dc * fresnel_terms.Fc_schlick(VoH), dc, 0.0)
        return wp.vec3(d * wp.min(masking.V_charlie(NoV, NoL, alpha), wp.static(vmax)), ash, 0.0)

    return charlie_integrands(lobe, wp.vec3)


# ``masking`` from the config; the others fix them: (integrand form, NDF whose CDF the estimators sample, masking).


@dataclass(frozen=True)
class SpecularIntegrand:
    """g(v, h, alpha, param) -> vec of one specular table, and what its estimators need beside it.

    ``distribution``: the NDF whose CDF / pdf / sampler the estimators use; ``kernel_channels``: the length of
    ``vec``, of which the first ``nch`` are kept; ``mirror(v, param) -> vec``: the exact alpha -> 0 limit where one
    exists (the microfacet form: D -> delta about n, G2 -> 1 for n.v > 0, so E = channels(n.v, param);
    lutbake.edge), else None and alpha is clamped to ALPHA_MIN. ``nol_kink``: a cosine n.l where g is only C1
    (Estevez & Kulla's Lambda fit switches formula at cos = 0.5: its second derivative jumps), which the
    gauss_legendre panels split at (lutbake.sampling.hemisphere), else None; ``kink_at_nov``: g is only C1 along
    n.l = n.v, a kink per texel (Ashikhmin-Shirley's max(n.l, n.v)), split the same way. ``grazing_peak``: g has a
    Charlie lobe, whose NDF peaks at theta_h = pi/2 (the gauss_legendre panels grade towards the end of the
    half-vector domain). ``ndf_peak``: g has the lobe of ``distribution`` (False for the sheen layouts, whose GGX
    distribution only panels: no u = CDF(theta_h) variable). ``g64(v, h, alpha, param, v.h as float64)``: g given
    v.h to float64, where float32's rounding of it matters (the dielectric's refraction near total internal
    reflection); the gauss_legendre panel rules pass it (lutbake.sampling.facet_rules.facet_rules_for), else None.
    ``g64_parts``: (part, rest) with g64(v, h, alpha, param, c) = rest(part(v, h, alpha, c), v, h, alpha, param, c),
    ``part`` free of the param (texels that differ only in it share it per node), else None. ``g_sin2(v, h, alpha,
    param, sin^2(theta_h) as float64)``: g with its Charlie D from sin^2(theta_h) to float64 (charlie_integrands), which
    the gauss_legendre panel rules pass where it is set, else None.
    """

    key: tuple
    g: object
    vec: type
    acc: type
    kernel_channels: int
    nch: int
    distribution: Distribution
    mirror: object | None
    nol_kink: float | None = None
    grazing_peak: bool = False
    ndf_peak: bool = True
    kink_at_nov: bool = False
    g64: object | None = None
    g64_parts: tuple | None = None
    g_sin2: object | None = None

    def alpha_input(self, alpha) -> np.ndarray:
        """The per-texel alpha the kernels receive (float32): lutbake.edge.effective_alpha."""
        return effective_alpha(alpha, self.mirror is not None)


@kernel_factory
def mirror_for(channels_name: str, fresnel=None):
    """E at alpha = 0 for the microfacet form: the mirror direction l = reflect(v, n), h = n, v.h = n.v, G2 = 1."""
    ch, vec = channels_for(channels_name, fresnel)

    @wp.func
    def mirror(v: wp.vec3, param: float):
        if v[2] <= COS_EPS:
            return vec()
        return ch(v[2], param)

    return mirror


@kernel_factory
def specular_integrand(
    nd, masking_name: str, channels_name: str, form: str = "microfacet", nch: int | None = None, fresnel=None
) -> SpecularIntegrand:
    """The integrand record of a (terms, channels, form) key, the first ``nch`` channels kept (all if None).
    For the forms blinn_phong and ashikhmin_shirley ``nd`` is the NDF the estimators sample and
    ``masking_name`` is ignored. The layouts with a Charlie channel (cloth, sheen) have no mirror limit."""
    if form != "microfacet":
        masking_name = "none"
    pair = charlie_pair_for(nd, masking_name, channels_name)
    charlie = pair is not None
    vec = wp.vec3 if charlie else channels_for(channels_name, fresnel)[1]
    k = vec._length_
    mirror = mirror_for(channels_name, fresnel) if form == "microfacet" and not charlie else None
    return SpecularIntegrand(
        (distribution(nd), masking_name, channels_name, form, fresnel),
        integrand_for(nd, masking_name, channels_name, form, fresnel),
        vec,
        wp.vec3d if k == 3 else wp.vec2d,
        k,
        nch or k,
        distribution(nd),
        mirror,
        masking.LAMBDA_SHEEN_SWITCH
        if channels_name.removesuffix("_clamped") in ("sheen_albedo", "sheen_fgd")
        else None,
        charlie,
        channels_name not in SHEEN_LAYOUTS,
        form == "ashikhmin_shirley",
        g_sin2=pair[1] if charlie else None,
    )


def hemisphere_integral(
    nd,
    masking_name: str,
    channels_name: str,
    nov,
    alpha,
    estimator: str = "gauss_legendre",
    samples: int | None = None,
    seed: int = 0,
    param=None,
    form: str = "microfacet",
    device: str = "cpu",
    fresnel=None,
) -> np.ndarray:
    """Host helper (checks, tests, benchmarks): the integrand of (terms, channels, form) at texels (nov[i],
    alpha[i], param[i]) by a hemisphere estimator (lutbake.sampling.hemisphere), every kernel channel, float64
    (N, C). ``nd``: a Distribution or the name of one of lutbake's; ``fresnel``: the Fresnel record of the channels
    that take one (None: Schlick's). alpha goes through the edge policy (lutbake.edge.effective_alpha) as in a
    table."""
    from ..sampling.hemisphere import estimator_for

    integrand = specular_integrand(nd, masking_name, channels_name, form, fresnel=fresnel)
    nov = np.asarray(nov, np.float32)
    param = np.zeros(len(nov), np.float32) if param is None else np.asarray(param, np.float32)
    inputs = {"nov": nov, "alpha": integrand.alpha_input(np.asarray(alpha, np.float32)), "param": param}
    return estimator_for(estimator, samples, seed).evaluate(integrand, inputs, device)
