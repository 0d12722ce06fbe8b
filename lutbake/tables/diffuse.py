"""Kind ``diffuse``: the diffuse AmbientBRDF table, NoV x sigma, for any diffuse model; and the
microfacet diffuse BRDF of Gotanda 2014 (course notes, Eq. 4), integrated over the facet normal m.

Microfacet diffuse (every facet Lambertian, rho = 1):
    f(l, v) = 1 / (pi (n.l)(n.v)) ∫_Ω (m.l)+ (m.v)+ D(m) F_facet(m.l, m.v) G2(m, l, v) dω_m
GGX D, height-correlated Smith G2 = χ+(m.l) χ+(m.v) / (1 + Λ(n.v) + Λ(n.l)) (Heitz 2014, Eq. 99): apart from
the χ+ (the clamps), G2 does not depend on m and leaves the integral:
    f = G2(l, v) / (pi (n.l)(n.v)) ∫ (m.l)+ (m.v)+ F_facet D(m) dω_m.
Quadrature (``fd_microfacet_for``), deterministic:
- u = CDF(theta_m) of D(m)(n.m) (GGX: tan^2 theta_m = alpha^2 u / (1 - u)), so D(m) dω_m = du dphi / (2 pi (n.m))
  and the integrand is (m.l)+ (m.v)+ F_facet / (2 pi (n.m)); D, however peaked, is absorbed into u.
- the facet m sees x (x = l or v) for every phi while theta_m < pi/2 - theta_x, i.e. u < u_x =
  (n.x)^2 / (alpha^2 (1 - (n.x)^2) + (n.x)^2); u is cut at u_l and u_v into three panels, each smoothstep-mapped
  (removes the sqrt-like onset of the clamp at u_x and the integrable 1/sqrt(1 - u) of 1/(n.m) at u = 1).
- for each u, (m.x) >= 0 on the arc |phi - phi_x| <= acos(-cot(theta_m) cot(theta_x)); the four arc ends cut
  [0, 2 pi) into four intervals on each of which the integrand is either 0 or smooth (no kink inside).
- each panel and interval gets an n-point Gauss-Legendre rule: 12 n^2 evaluations per (l, v).
At sigma -> 0, D -> delta(m - n) / (n.m) and f -> F_facet(n.l, n.v) / pi: Lambert x Eq. 6 for the Eq. 6 facet form.

AmbientBRDF (directional reflectance under uniform white light, rho = 1):
    E(v) = ∫ f(l, v) (n.l) dω_l = 2 ∫_0^pi dphi_l ∫_0^1 d(n.l) f (n.l)       (f is even in phi_l)
with n-point GL on 2 x 2 panels: n.l split at n.v (the max(n.l, n.v) kink of Oren-Nayar) and phi_l at pi/2
(s = l.v - (n.l)(n.v) changes sign there: the branches of Eq. 5, 7, 8 and the max(0, cos phi) of Oren-Nayar).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import warp as wp

from ..axes import TEXELS, Axis
from ..edge import ALPHA_MIN, COS_EPS
from ..sampling import points
from ..terms import diffuse, masking
from ..terms.frame import view_dir
from . import diffuse_albedo
from .base import Key, Kind, Plan

TWO_PI64 = wp.constant(wp.float64(2.0 * math.pi))
PI64 = wp.constant(wp.float64(math.pi))

FACET_FRESNEL = {
    "eq6": "Eq. 6 on each facet: 21/20 (1 - f0)(1 - (1 - m.l)^5)(1 - (1 - m.v)^5); E scales with (1 - f0)",
    "schlick": "(1 - F(m.l))(1 - F(m.v)), F Schlick: (1 - f0)^2 (1 - (1 - m.l)^5)(1 - (1 - m.v)^5); E scales with (1 - f0)^2",
    "dielectric_f0": "(1 - F(m.l))(1 - F(m.v)), F the exact dielectric Fresnel of Eq. 2 written with f0: f0 does not "
    "factor out (kind diffuse_3d bakes an f0 axis; kind diffuse bakes the given f0 only)",
}
FACET_FUNCS = {
    "eq6": diffuse.F_facet_eq6,
    "schlick": diffuse.F_facet_schlick,
    "dielectric_f0": diffuse.F_facet_dielectric_f0,
}
SIGMA_TO_ALPHA = {
    "sigma": "GGX alpha = sigma",
    "sigma_squared": "GGX alpha = sigma^2 (sigma as a perceptual roughness)",
}
MODELS = {
    "lambert": "Lambert, rho / pi",
    "oren_nayar": "classic Oren-Nayar as taught in lecture 003 (A with 0.57)",
    "oren_nayar_improved": "improved Oren-Nayar, Gotanda 2014 Eq. 5",
    "oren_nayar_fresnel": "Oren-Nayar with Fresnel, Gotanda 2014 Eq. 7 ((1 - f0) counted once)",
    "fitted": "Gotanda's fitted microfacet diffuse, Eq. 8 (course-notes reading)",
    "fitted_slides": "Eq. 8 with the slides' reading of F_r's second factor",
    "microfacet": "the microfacet diffuse model, Eq. 4, integrated over m (GGX, height-correlated Smith)",
}


F0_NONE = "none: f0 does not factor out; the table holds E at the baked f0 only (kind diffuse_3d has an f0 axis)"


def f0_factor(model: str, facet_fresnel: str) -> str:
    """How f0 enters a model: every model here is g(f0) times an f0-free function."""
    if model in ("lambert", "oren_nayar", "oren_nayar_improved"):
        return "1"
    if model == "microfacet" and facet_fresnel == "schlick":
        return "(1 - f0)^2"
    if model == "microfacet" and facet_fresnel == "dielectric_f0":
        return F0_NONE
    return "(1 - f0)"


@wp.func
def wrap_2pi(x: wp.float64):
    return x - TWO_PI64 * wp.floor(x / TWO_PI64)


@wp.func
def arc_half_width(cos_m: wp.float64, sin_m: wp.float64, cos_x: wp.float64, sin_x: wp.float64):
    """Half-width in phi of the arc where m.x >= 0, m at polar angle theta_m, x at theta_x:
    acos(-cot(theta_m) cot(theta_x)), clamped to [0, pi] (pi: the whole circle)."""
    den = sin_m * sin_x
    num = -cos_m * cos_x
    if den <= wp.abs(num):
        if num <= wp.float64(0.0):
            return PI64
        return wp.float64(0.0)
    return wp.acos(wp.clamp(num / den, wp.float64(-1.0), wp.float64(1.0)))


@wp.func
def u_visible_ggx(cos_x: wp.float64, alpha: wp.float64):
    """u = CDF(theta_m) at theta_m = pi/2 - theta_x: (n.x)^2 / (alpha^2 (1 - (n.x)^2) + (n.x)^2)."""
    c2 = cos_x * cos_x
    return c2 / (alpha * alpha * (wp.float64(1.0) - c2) + c2)


@wp.func
def om_visible_ggx(cos_x: wp.float64, alpha: wp.float64):
    """1 - u_visible_ggx, without cancellation: alpha^2 (1 - (n.x)^2) / (alpha^2 (1 - (n.x)^2) + (n.x)^2)."""
    c2 = cos_x * cos_x
    t = alpha * alpha * (wp.float64(1.0) - c2)
    return t / (t + c2)


@functools.lru_cache(maxsize=None)
def fd_microfacet_for(facet_fresnel: str):
    """The microfacet diffuse BRDF ``fd_microfacet(l, v, alpha, f0, xg, wg) -> float64`` (rho = 1), Eq. 4,
    integrated as in the module docstring with the n-point GL rule (xg, wg) on [0, 1]."""
    Ff = FACET_FUNCS[facet_fresnel]

    @wp.func
    def fd_microfacet(
        l: wp.vec3, v: wp.vec3, alpha: float, f0: float, xg: wp.array(dtype=wp.float64), wg: wp.array(dtype=wp.float64)
    ):
        NoL = l[2]
        NoV = v[2]
        if NoL <= COS_EPS or NoV <= COS_EPS:
            return wp.float64(0.0)
        one = wp.float64(1.0)
        a64 = wp.float64(alpha)
        G2 = masking.G2_smith_height_correlated(masking.Lambda_ggx(NoV, alpha), masking.Lambda_ggx(NoL, alpha))
        cl = wp.float64(NoL)
        cv = wp.float64(NoV)
        sl = wp.sqrt(wp.max(one - cl * cl, wp.float64(0.0)))
        sv = wp.sqrt(wp.max(one - cv * cv, wp.float64(0.0)))
        phl = wp.atan2(wp.float64(l[1]), wp.float64(l[0]))
        phv = wp.atan2(wp.float64(v[1]), wp.float64(v[0]))
        ul = u_visible_ggx(cl, a64)
        uv = u_visible_ggx(cv, a64)
        oml = om_visible_ggx(cl, a64)
        omv = om_visible_ggx(cv, a64)
        u1 = wp.min(ul, uv)
        u2 = wp.max(ul, uv)
        om1 = wp.max(oml, omv)  # 1 - u1
        om2 = wp.min(oml, omv)  # 1 - u2
        n = xg.shape[0]
        acc = wp.float64(0.0)
        n_geo = diffuse_albedo.n_tail_cuts(a64)
        prev = wp.float64(0.0)
        om_prev = one
        for g in range(n_geo + 1):
            cut = one
            om_cut = wp.float64(0.0)
            if g < n_geo:
                r2 = wp.pow(diffuse_albedo.TAIL_RATIO64, wp.float64(2 * (g + 1)))
                om_cut = one / (one + r2)
                cut = r2 / (one + r2)
            # the segment [prev, cut] cut at u1 and u2 where they fall inside it
            om_a = wp.clamp(om1, om_cut, om_prev)
            om_b = wp.clamp(om2, om_cut, om_prev)
            for p in range(3):
                lo = prev
                om_lo = om_prev
                om_hi = om_a
                if p == 1:
                    om_lo = om_a
                    om_hi = om_b
                if p == 2:
                    om_lo = om_b
                    om_hi = om_cut
                if p > 0:
                    lo = one - om_lo
                du = om_lo - om_hi
                if du > wp.float64(0.0):
                    for k in range(n):
                        s = xg[k]
                        u = lo + du * s * s * (wp.float64(3.0) - wp.float64(2.0) * s)
                        wu = wg[k] * du * wp.float64(6.0) * s * (one - s)
                        # 1 - u without cancellation (u_l -> 1 for n.l -> 1 and small alpha)
                        omu = om_hi + du * (one - s) * (one - s) * (one + wp.float64(2.0) * s)
                        tan2 = a64 * a64 * u / omu
                        cm = one / wp.sqrt(one + tan2)
                        sm = wp.sqrt(tan2) * cm
                        wl = arc_half_width(cm, sm, cl, sl)
                        wv = arc_half_width(cm, sm, cv, sv)
                        b0 = wrap_2pi(phl - wl)
                        b1 = wrap_2pi(phl + wl)
                        b2 = wrap_2pi(phv - wv)
                        b3 = wrap_2pi(phv + wv)
                        # sorting network for four values
                        if b0 > b1:
                            t = b0
                            b0 = b1
                            b1 = t
                        if b2 > b3:
                            t = b2
                            b2 = b3
                            b3 = t
                        if b0 > b2:
                            t = b0
                            b0 = b2
                            b2 = t
                        if b1 > b3:
                            t = b1
                            b1 = b3
                            b3 = t
                        if b1 > b2:
                            t = b1
                            b1 = b2
                            b2 = t
                        row = wp.float64(0.0)
                        for q in range(4):
                            a = b0
                            b = b1
                            if q == 1:
                                a = b1
                                b = b2
                            if q == 2:
                                a = b2
                                b = b3
                            if q == 3:
                                a = b3
                                b = b0 + TWO_PI64
                            dphi = b - a
                            if dphi > wp.float64(0.0):
                                for j in range(n):
                                    phi = a + dphi * xg[j]
                                    m = wp.vec3(float(sm * wp.cos(phi)), float(sm * wp.sin(phi)), float(cm))
                                    MoL = wp.dot(m, l)
                                    MoV = wp.dot(m, v)
                                    if MoL > 0.0 and MoV > 0.0:
                                        row = row + wg[j] * dphi * wp.float64(MoL * MoV * Ff(MoL, MoV, f0))
                        acc = acc + wu * row / cm
            prev = cut
            om_prev = om_cut
        return wp.float64(G2) * acc / (TWO_PI64 * PI64 * cl * cv)

    return fd_microfacet


@functools.lru_cache(maxsize=None)
def brdf_for(model: str, facet_fresnel: str = "eq6"):
    """``brdf(l, v, sigma, alpha, f0, xg, wg) -> float64``: the model's BRDF for rho = 1 (closed forms ignore
    alpha and the GL arrays; the microfacet model ignores sigma)."""
    if model == "microfacet":
        fm = fd_microfacet_for(facet_fresnel)

        @wp.func
        def brdf(
            l: wp.vec3,
            v: wp.vec3,
            sigma: float,
            alpha: float,
            f0: float,
            xg: wp.array(dtype=wp.float64),
            wg: wp.array(dtype=wp.float64),
        ):
            return fm(l, v, alpha, f0, xg, wg)

        return brdf
    closed = {
        "oren_nayar": diffuse.Fd_oren_nayar,
        "oren_nayar_improved": diffuse.Fd_oren_nayar_improved,
    }
    with_f0 = {
        "oren_nayar_fresnel": diffuse.Fd_oren_nayar_fresnel,
        "fitted": diffuse.Fd_gotanda_fitted,
        "fitted_slides": diffuse.Fd_gotanda_fitted_slides,
    }
    if model == "lambert":

        @wp.func
        def brdf(
            l: wp.vec3,
            v: wp.vec3,
            sigma: float,
            alpha: float,
            f0: float,
            xg: wp.array(dtype=wp.float64),
            wg: wp.array(dtype=wp.float64),
        ):
            if l[2] <= COS_EPS or v[2] <= COS_EPS:
                return wp.float64(0.0)
            return wp.float64(diffuse.Fd_lambert(1.0))
    elif model in closed:
        F = closed[model]

        @wp.func
        def brdf(
            l: wp.vec3,
            v: wp.vec3,
            sigma: float,
            alpha: float,
            f0: float,
            xg: wp.array(dtype=wp.float64),
            wg: wp.array(dtype=wp.float64),
        ):
            return wp.float64(F(1.0, l[2], v[2], wp.dot(l, v), sigma))
    elif model in with_f0:
        F = with_f0[model]

        @wp.func
        def brdf(
            l: wp.vec3,
            v: wp.vec3,
            sigma: float,
            alpha: float,
            f0: float,
            xg: wp.array(dtype=wp.float64),
            wg: wp.array(dtype=wp.float64),
        ):
            return wp.float64(F(1.0, l[2], v[2], wp.dot(l, v), sigma, f0))
    else:
        raise KeyError(model)
    return brdf


@functools.lru_cache(maxsize=None)
def albedo_kernel_for(model: str, facet_fresnel: str = "eq6"):
    """Kernel: E(v) = ∫ f (n.l) dω_l per texel (nov[i], sigma[i], alpha[i]); outer GL (xo, wo) on 2 x 2
    panels, inner GL (xg, wg) for the microfacet integral."""
    brdf = brdf_for(model, facet_fresnel)

    @wp.kernel(enable_backward=False, module="unique")
    def albedo_kernel(
        nov: wp.array(dtype=float),
        sigma: wp.array(dtype=float),
        alpha: wp.array(dtype=float),
        f0: float,
        xo: wp.array(dtype=wp.float64),
        wo: wp.array(dtype=wp.float64),
        xg: wp.array(dtype=wp.float64),
        wg: wp.array(dtype=wp.float64),
        out: wp.array2d(dtype=wp.float64),
    ):
        i = wp.tid()
        v = view_dir(nov[i])
        cv = wp.float64(v[2])
        half_pi = PI64 * wp.float64(0.5)
        acc = wp.float64(0.0)
        for pm in range(2):
            mlo = wp.float64(0.0)
            mhi = cv
            if pm == 1:
                mlo = cv
                mhi = wp.float64(1.0)
            for pp in range(2):
                plo = half_pi * wp.float64(pp)
                for a in range(xo.shape[0]):
                    mu = mlo + (mhi - mlo) * xo[a]
                    st = wp.sqrt(wp.max(wp.float64(1.0) - mu * mu, wp.float64(0.0)))
                    for b in range(xo.shape[0]):
                        phi = plo + half_pi * xo[b]
                        l = wp.vec3(float(st * wp.cos(phi)), float(st * wp.sin(phi)), float(mu))
                        f = brdf(l, v, sigma[i], alpha[i], f0, xg, wg)
                        acc = acc + wo[a] * wo[b] * (mhi - mlo) * half_pi * f * mu
        out[i, 0] = wp.float64(2.0) * acc

    return albedo_kernel


@functools.lru_cache(maxsize=None)
def brdf_kernel_for(model: str, facet_fresnel: str = "eq6"):
    """Kernel: f(l[i], v[i]) for given direction pairs (tests, plots, BTF slices)."""
    brdf = brdf_for(model, facet_fresnel)

    @wp.kernel(enable_backward=False, module="unique")
    def brdf_kernel(
        l: wp.array(dtype=wp.vec3),
        v: wp.array(dtype=wp.vec3),
        sigma: wp.array(dtype=float),
        alpha: wp.array(dtype=float),
        f0: float,
        xg: wp.array(dtype=wp.float64),
        wg: wp.array(dtype=wp.float64),
        out: wp.array(dtype=wp.float64),
    ):
        i = wp.tid()
        out[i] = brdf(l[i], v[i], sigma[i], alpha[i], f0, xg, wg)

    return brdf_kernel


def alpha_from_sigma(sigma, mapping: str) -> np.ndarray:
    """GGX alpha for sigma under ``mapping`` (SIGMA_TO_ALPHA), clamped to ALPHA_MIN (lutbake.edge)."""
    s = np.asarray(sigma, dtype=np.float64)
    a = s if mapping == "sigma" else s * s
    return np.maximum(a, ALPHA_MIN).astype(np.float32)


def _gl(n: int, device: str):
    x, w = points.gauss_legendre(n)
    return [wp.array(x, dtype=wp.float64, device=device), wp.array(w, dtype=wp.float64, device=device)]


def eval_brdf(
    model: str,
    l: np.ndarray,
    v: np.ndarray,
    sigma,
    f0: float = 0.0,
    facet_fresnel: str = "eq6",
    sigma_to_alpha: str = "sigma",
    order: int = 8,
    device: str = "cpu",
) -> np.ndarray:
    """f(l_i, v_i) for unit direction arrays (N, 3) (n = +z), rho = 1; float64 (N,)."""
    l = np.ascontiguousarray(l, dtype=np.float32).reshape(-1, 3)
    v = np.ascontiguousarray(v, dtype=np.float32).reshape(-1, 3)
    n = len(l)
    s = np.broadcast_to(np.asarray(sigma, dtype=np.float32), (n,)).copy()
    a = alpha_from_sigma(s, sigma_to_alpha)
    out = wp.zeros(n, dtype=wp.float64, device=device)
    k = brdf_kernel_for(model, facet_fresnel)
    wp.launch(
        k,
        dim=n,
        inputs=[
            wp.array(l, dtype=wp.vec3, device=device),
            wp.array(v, dtype=wp.vec3, device=device),
            wp.array(s, dtype=float, device=device),
            wp.array(a, dtype=float, device=device),
            float(f0),
            *_gl(order, device),
            out,
        ],
        device=device,
    )
    return out.numpy()


def albedo(
    model: str,
    nov: np.ndarray,
    sigma: np.ndarray,
    f0: float = 0.0,
    facet_fresnel: str = "eq6",
    sigma_to_alpha: str = "sigma",
    order: int = 8,
    outer_order: int | None = None,
    device: str = "cpu",
) -> np.ndarray:
    """E(nov_i, sigma_i) = ∫ f (n.l) dω_l (rho = 1), float64 (N,)."""
    nov = np.ascontiguousarray(nov, dtype=np.float32)
    s = np.ascontiguousarray(np.broadcast_to(np.asarray(sigma, dtype=np.float32), nov.shape))
    a = alpha_from_sigma(s, sigma_to_alpha)
    out = wp.zeros((len(nov), 1), dtype=wp.float64, device=device)
    k = albedo_kernel_for(model, facet_fresnel)
    wp.launch(
        k,
        dim=len(nov),
        inputs=[
            wp.array(nov, dtype=float, device=device),
            wp.array(s, dtype=float, device=device),
            wp.array(a, dtype=float, device=device),
            float(f0),
            *_gl(outer_order or order, device),
            *_gl(order, device),
            out,
        ],
        device=device,
    )
    return out.numpy()[:, 0]


# ---- the table kind ----

DEFAULT_ORDER = {"microfacet": 12}  # base GL order (lutbake.tables.diffuse_albedo); closed forms: CLOSED_ORDER
CLOSED_ORDER = 24

KEYS = {
    "name": Key(
        "name", "name", None, "output stem: <out-dir>/<name>.exr; letters, digits, - and _ only", required=True
    ),
    "kind": Key("kind", "str", None, "table kind (lutbake list)", required=True),
    "size": Key("size", "int_pair", [64, 64], "[NoV, sigma] texel counts", minimum=1),
    "model": Key("model", "str", "microfacet", "the diffuse model integrated", MODELS),
    "f0": Key(
        "f0",
        "float",
        0.0,
        "Fresnel reflectance at normal incidence the table is baked for; every model is "
        "g(f0) times an f0-free function (metadata lutbake:f0_factor), so f0 = 0 bakes the f0-free table",
        minimum=0.0,
        maximum=0.999,
    ),
    "sigma_to_alpha": Key("sigma_to_alpha", "str", "sigma", "GGX alpha from sigma (microfacet model)", SIGMA_TO_ALPHA),
    "facet_fresnel": Key(
        "facet_fresnel", "str", "eq6", "Fresnel transmission on each facet (microfacet model)", FACET_FRESNEL
    ),
    "samples": Key(
        "samples",
        "int",
        None,
        "Gauss-Legendre order n per panel and dimension; microfacet: the base "
        "order of the swapped integral (lutbake.tables.diffuse_albedo: 4 n^3 + n^2 evaluations per "
        "texel per u panel, 1.5 n in u and n.l where NoV < 0.1), closed forms: outer 4 n^2 directions "
        "l; omitted: 12 for microfacet, 24 otherwise",
        minimum=2,
        maximum=64,
    ),
    "dtype": Key("dtype", "str", "float32", "pixel type written", {"float32": "32-bit float", "half": "16-bit float"}),
    "texel": Key("texel", "str", "center", "texel convention of both axes", TEXELS),
    "nov_range": Key("nov_range", "float_range", [0.0, 1.0], "NoV at t = 0 and t = 1", minimum=0.0, maximum=1.0),
    "sigma_range": Key("sigma_range", "float_range", [0.0, 1.0], "sigma at t = 0 and t = 1", minimum=0.0, maximum=1.0),
}

RECONSTRUCTION = (
    "uv = vec2(NoV, sigma) (texel centres per lutbake:axes); E = texture(lut, uv).r; "
    "diffuse = albedo * (irradiance / pi) * E * g(f0) / g(f0_baked), irradiance = ∫ L cos dω "
    "(g = lutbake:f0_factor; with f0_baked = 0: diffuse = albedo * (irradiance / pi) * E * g(f0))"
)


def order_for(o: dict) -> int:
    return o["samples"] or DEFAULT_ORDER.get(o["model"], CLOSED_ORDER)


def plan(spec) -> Plan:
    import json

    o = spec.options
    n_nov, n_sigma = o["size"]
    axes = [
        Axis("sigma", "y", n_sigma, *o["sigma_range"], texel=o["texel"]),
        Axis("NoV", "x", n_nov, *o["nov_range"], texel=o["texel"]),
    ]
    sig_axis, nov_axis = axes
    nov = np.tile(nov_axis.values(), n_sigma)
    sigma = np.repeat(sig_axis.values(), n_nov)
    model = o["model"]
    ff = o["facet_fresnel"]
    order = order_for(o)
    terms = {"model": model, "f0": str(o["f0"]), "f0_factor": f0_factor(model, ff)}
    if model == "microfacet":
        terms.update(ndf="ggx", masking="smith_height_correlated", facet_fresnel=ff, sigma_to_alpha=o["sigma_to_alpha"])
    extra = {
        "f0_factor": f0_factor(model, ff),
        "f0": repr(o["f0"]),
        "rho": "1",
        "sigma_alpha": json.dumps([float(a) for a in alpha_from_sigma(sig_axis.values(), o["sigma_to_alpha"])]),
    }
    fields = dict(
        axes=axes,
        channels={
            "E": "∫ f_r (n.l) dω_l for rho = 1 at the baked f0: directional diffuse "
            "reflectance under uniform white light"
        },
        reconstruction=RECONSTRUCTION,
        terms=terms,
        extra=extra,
    )
    if model == "microfacet":
        alpha = alpha_from_sigma(sigma, o["sigma_to_alpha"])
        return diffuse_albedo.microfacet_albedo_plan(
            nov=nov, alpha=alpha, f0=np.full(len(nov), o["f0"]), facet_fresnel=ff, order=order, **fields
        )
    key = (model, ff)

    def prepare(device: str) -> None:
        wp.load_module(albedo_kernel_for(*key).module, device=device)

    def run(idx, n, device):
        return albedo(model, nov[idx], sigma[idx], o["f0"], ff, o["sigma_to_alpha"], n, device=device)[:, None]

    def run_tile(start: int, stop: int, device: str) -> np.ndarray:
        return run(slice(start, stop), order, device)

    def error_estimate(data: np.ndarray, device: str) -> tuple[float, str]:
        idx = np.unique(
            np.concatenate([np.arange(0, len(nov), max(1, len(nov) // 256)), np.flatnonzero(nov <= nov.min())])
        )
        err = float(np.max(np.abs(data[idx] - run(idx, order + 8, device))))
        return err, f"max |order {order} - order {order + 8}| over {len(idx)} probe texels (strided + most grazing NoV)"

    evals = 4 * order * order
    return Plan(
        n_texels=len(nov),
        n_channels=1,
        run_tile=run_tile,
        prepare=prepare,
        samples=evals,
        estimator="gauss_legendre",
        cost=float(len(nov)) * evals,
        error_estimate=error_estimate,
        **fields,
    )


DIFFUSE = Kind(
    "diffuse",
    "diffuse AmbientBRDF: NoV x sigma, E = ∫ f_r (n.l) dω_l for Lambert, Oren-Nayar variants, "
    "Gotanda's fitted model or the integrated microfacet model (Eq. 4)",
    KEYS,
    plan,
    aliases=("ambient_brdf_diffuse",),
)
