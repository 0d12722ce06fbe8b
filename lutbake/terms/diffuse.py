"""Diffuse BRDF terms: Lambert, Oren-Nayar (classic, improved, with Fresnel), the diffuse Fresnel
factor and Gotanda's fitted microfacet-diffuse model; the microfacet model itself (Eq. 4), which has
no closed form, is integrated in lutbake.sampling.facets (the BRDF) and lutbake.sampling.swapped (its albedo).

Convention (all ``Fd_*``): the value returned is the **BRDF** f_r (1/sr), for albedo ``rho``. The seeds
write radiance L_r for an irradiance E0 from direction l (L_r = f_r E0 (n.l)); those forms are divided by
E0 (n.l) here, so the cosine of the light is *not* included, as for the specular terms.
Arguments are cosines in the shading frame: NoL, NoV and LoV = l.v, whence
    s = LoV - NoL NoV = sin(theta_l) sin(theta_v) cos(phi)
(phi the azimuth between l and v; s >= 0 exactly when cos(phi) >= 0).
Edge policy (lutbake.edge): every term returns 0 when NoL or NoV <= COS_EPS (light or view below the
horizon). sigma is the roughness of Gotanda's models, in [0, 1].
"""

import warp as wp

from ..edge import COS_EPS
from .fresnel import F_dielectric_f0

INV_PI = wp.constant(0.31830988618379067)


@wp.func
def pow5_weight(c: float):
    """1 - (1 - c)^5 for c in [0, 1] (clamped): the diffuse Fresnel transmission shape."""
    m = wp.clamp(1.0 - c, 0.0, 1.0)
    m2 = m * m
    return 1.0 - m2 * m2 * m


@wp.func
def F_diff(NoL: float, NoV: float, f0: float):
    """Diffuse Fresnel factor (Gotanda 2014 course notes, Eq. 6, after Shirley et al. 1997):
    F_diff = 21/20 (1 - f0) (1 - (1 - n.l)^5) (1 - (1 - n.v)^5).
    Dimensionless; 21/20 (1 - f0) at NoL = NoV = 1, 0 at either horizon. Its cosine-weighted mean
    over l at NoV = 1 is exactly 1 - f0 (the 21/20 normalises it)."""
    return 1.05 * (1.0 - f0) * pow5_weight(NoL) * pow5_weight(NoV)


@wp.func
def Fd_lambert(rho: float):
    """Lambert: f = rho / pi. Directional albedo rho for every view."""
    return rho * INV_PI


@wp.func
def oren_nayar_AB(sigma: float, a_denominator: float):
    """Oren-Nayar's (A, B) = (1 - 0.5 sigma^2 / (sigma^2 + a_denominator), 0.45 sigma^2 / (sigma^2 + 0.09)):
    a_denominator = 0.57 in the classic model (Oren & Nayar 1994), 0.65 in Gotanda 2014, Eq. 5 and 7."""
    s2 = sigma * sigma
    return wp.vec2(1.0 - 0.5 * s2 / (s2 + a_denominator), 0.45 * s2 / (s2 + 0.09))


@wp.func
def Fd_oren_nayar(rho: float, NoL: float, NoV: float, LoV: float, sigma: float):
    """Classic Oren-Nayar, qualitative model as taught in lecture 003 (Oren & Nayar 1994, Eq. 30):
    f = rho/pi (A + B max(0, cos phi) sin(a) tan(b)), a = max(theta_l, theta_v), b = min(theta_l, theta_v),
    A = 1 - 0.5 sigma^2/(sigma^2 + 0.57), B = 0.45 sigma^2/(sigma^2 + 0.09).
    Computed without angles: max(0, cos phi) sin(a) tan(b) = max(0, s) / max(NoL, NoV).
    The lecture's slide multiplies (A + B max(0, cos phi)) by C = sin(a) tan(b); that reading does not
    reduce to Lambert at sigma = 0 and is taken as a layout slip. sigma = 0: exactly Lambert."""
    if NoL <= COS_EPS or NoV <= COS_EPS:
        return 0.0
    AB = oren_nayar_AB(sigma, 0.57)
    s = LoV - NoL * NoV
    return rho * INV_PI * (AB[0] + AB[1] * wp.max(s, 0.0) / wp.max(NoL, NoV))


@wp.func
def Fd_oren_nayar_improved(rho: float, NoL: float, NoV: float, LoV: float, sigma: float):
    """Improved Oren-Nayar (Gotanda 2014 course notes, Eq. 5, from Gotanda 2012), radiance form
    L_r / (rho E0 / pi) = (n.l) A + B s min(1, n.l / n.v)   if s >= 0,
                        = (n.l) A + B s                      otherwise,
    A = 1 - 0.5 sigma^2/(sigma^2 + 0.65), B = 0.45 sigma^2/(sigma^2 + 0.09). Returned as the BRDF
    L_r / (E0 n.l): rho/pi (A + B s / max(n.l, n.v)) for s >= 0, rho/pi (A + B s / n.l) otherwise.
    The second branch is taken as printed; its radiance goes negative for a grazing light behind the
    viewer (n.l -> 0, cos phi < 0), so the radiance is clamped at 0. sigma = 0: exactly Lambert."""
    if NoL <= COS_EPS or NoV <= COS_EPS:
        return 0.0
    AB = oren_nayar_AB(sigma, 0.65)
    A = AB[0]
    B = AB[1]
    s = LoV - NoL * NoV
    radiance = NoL * A + B * s
    if s >= 0.0:
        radiance = NoL * A + B * s * wp.min(1.0, NoL / NoV)
    return rho * INV_PI * wp.max(radiance, 0.0) / NoL


@wp.func
def Fd_oren_nayar_fresnel(rho: float, NoL: float, NoV: float, LoV: float, sigma: float, f0: float):
    """Oren-Nayar with Fresnel (Gotanda 2014 course notes, Eq. 7), radiance form
    L_r / (rho E0 / pi) = (1 - f0) [F'(l, v) (n.l) A + B s min(1, n.l / n.v)],
    F'(l, v) = 21/20 (1 - (1 - n.l)^5)(1 - (1 - n.v)^5) = F_diff / (1 - f0),
    A, B as Eq. 5 (0.65, 0.09). The seed prints (1 - f0) twice (outside and inside F_diff); lutbake
    counts it **once**: only then does sigma = 0 give Lambert x Eq. 6, the sigma = 0 limit of the
    microfacet model (Eq. 4), and the same (1 - f0) prefactor as the fitted model (Eq. 8). Eq. 7 has a
    single branch (no s < 0 case), used as printed; the radiance is clamped at 0 (see Eq. 5).
    Returned as the BRDF L_r / (E0 n.l)."""
    if NoL <= COS_EPS or NoV <= COS_EPS:
        return 0.0
    AB = oren_nayar_AB(sigma, 0.65)
    s = LoV - NoL * NoV
    A = AB[0]
    B = AB[1]
    radiance = 1.05 * pow5_weight(NoL) * pow5_weight(NoV) * NoL * A + B * s * wp.min(1.0, NoL / NoV)
    return rho * INV_PI * (1.0 - f0) * wp.max(radiance, 0.0) / NoL


@wp.func
def gotanda_fitted_radiance(NoL: float, NoV: float, LoV: float, sigma: float, slides_reading: int):
    """F_r L_m + V_d B_p of Eq. 8 (Gotanda 2014 course notes), the bracket of the fitted model; it
    contains the light cosine. ``slides_reading`` = 0: F_r's second factor is the course notes'
    (1 - (1 - n.v)^(5 - 4 sigma^2) / (sigma^2 + 1.36053)); 1: the slides' layout
    (1 - (1 - n.v)^(5 - 4 sigma^2)) / (sigma^2 + 1.36053)."""
    s1 = sigma
    s2 = sigma * sigma
    s3 = s2 * sigma
    s4 = s2 * s2
    omv = wp.clamp(1.0 - NoV, 0.0, 1.0)
    oml = wp.clamp(1.0 - NoL, 0.0, 1.0)
    k = s2 + 1.36053
    fr1 = 1.0 - (0.542026 * s2 + 0.303573 * s1) / k
    fr2 = 1.0 - wp.pow(omv, 5.0 - 4.0 * s2) / k
    if slides_reading != 0:
        fr2 = (1.0 - wp.pow(omv, 5.0 - 4.0 * s2)) / k
    fr3 = (-0.733996 * s3 + 1.50912 * s2 - 1.16402 * s1) * wp.pow(omv, 1.0 + 1.0 / (39.0 * s4 + 1.0)) + 1.0
    Fr = fr1 * fr2 * fr3
    Lm = (wp.max(1.0 - 2.0 * s1, 0.0) * pow5_weight(NoL) + wp.min(2.0 * s1, 1.0)) * (
        (1.0 - 0.5 * s1) * NoL + 0.5 * s1 * NoL * NoL
    )
    Vd = (
        s2
        / ((s2 + 0.09) * (1.31072 + 0.995584 * NoV))
        * (1.0 - wp.pow(oml, (1.0 - 0.3726732 * NoV * NoV) / (0.188566 + 0.388410 * NoV)))
    )
    s = LoV - NoL * NoV
    Bp = s
    if s < 0.0:
        Bp = 1.4 * NoV * NoL * s
    return Fr * Lm + Vd * Bp


@wp.func
def Fd_gotanda_fitted(rho: float, NoL: float, NoV: float, LoV: float, sigma: float, f0: float):
    """Gotanda's fitted microfacet diffuse (Gotanda 2014 course notes, Eq. 8; course-notes reading of F_r):
    L_r = 21/(20 pi) (1 - f0) (F_r(v, l, sigma) L_m(l, sigma) + V_d(v, l, sigma) B_p(v, l)) for unit
    irradiance, returned as the BRDF L_r / (n.l) times rho (the bracket vanishes like n.l as n.l -> 0, so
    the quotient stays finite). sigma in [0, 1]; the seed states it is inaccurate when both l and v
    are near grazing, and that it must not be used to compute AmbientBRDF tables."""
    if NoL <= COS_EPS or NoV <= COS_EPS:
        return 0.0
    return rho * 1.05 * INV_PI * (1.0 - f0) * gotanda_fitted_radiance(NoL, NoV, LoV, sigma, 0) / NoL


@wp.func
def Fd_gotanda_fitted_slides(rho: float, NoL: float, NoV: float, LoV: float, sigma: float, f0: float):
    """Fd_gotanda_fitted with the slides' reading of F_r's second factor,
    (1 - (1 - n.v)^(5 - 4 sigma^2)) / (sigma^2 + 1.36053) (docs: EQUATIONS.md, Eq. 8 ambiguity)."""
    if NoL <= COS_EPS or NoV <= COS_EPS:
        return 0.0
    return rho * 1.05 * INV_PI * (1.0 - f0) * gotanda_fitted_radiance(NoL, NoV, LoV, sigma, 1) / NoL


# --- energy-preserving Oren-Nayar (EON; Portsmouth, Kutz & Hill 2024, "EON: A practical energy-preserving rough
# diffuse BRDF", JCGT 14(1) 2025; the OpenPBR diffuse lobe, adobe/openpbr-bsdf impl/openpbr_diffuse_lobe.h).
# r in [0, 1] is OpenPBR's base_diffuse_roughness (the Fujii Oren-Nayar sigma); r = 0 is Lambert.

FON_C1 = wp.constant(0.5 - 2.0 / (3.0 * 3.141592653589793))  # 1/2 - 2/(3 pi): A_F = 1 / (1 + FON_C1 r)
FON_C2 = wp.constant(2.0 / 3.0 - 28.0 / (15.0 * 3.141592653589793))  # 2/3 - 28/(15 pi): E_avg = A_F (1 + FON_C2 r)
EON_EPS = wp.constant(1.0e-7)  # the paper's floor on 1 - E in the multiple-scattering lobe


@wp.func
def A_fon(r: float):
    """A_F = 1 / (1 + (1/2 - 2/(3 pi)) r): the Fujii Oren-Nayar (FON) constant term (EON paper's listing, f_EON);
    B_F = r A_F."""
    return 1.0 / (1.0 + FON_C1 * r)


@wp.func
def E_fon(mu: float, r: float):
    """Directional albedo of the FON single-scattering lobe for rho = 1 (EON paper's listing, E_FON_exact):
    A_F + B_F / pi G(mu), G = S (acos(mu) - S mu) + 2/3 (S / mu (1 - S^3) - S), S = sqrt(1 - mu^2).
    (S / mu)(1 - S^3) is written S mu (1 + S + S^2) / (1 + S) (1 - S = mu^2 / (1 + S)), exact and free of the
    float32 cancellation at mu -> 0, where it tends to 0 (G(0) = pi/2 - 2/3, G(1) = 0). mu in (0, 1]."""
    m = wp.clamp(mu, 0.0, 1.0)
    S = wp.sqrt(wp.max(1.0 - m * m, 0.0))
    G = S * (wp.acos(m) - S * m) + (2.0 / 3.0) * (S * m * (1.0 + S + S * S) / (1.0 + S) - S)
    A = A_fon(r)
    return A + r * A * INV_PI * G


@wp.func
def E_fon_avg(r: float):
    """Cosine-weighted average of E_fon over the hemisphere, A_F (1 + (2/3 - 28/(15 pi)) r) (EON paper's listing,
    avgEF in f_EON)."""
    return A_fon(r) * (1.0 + FON_C2 * r)


@wp.func
def Fd_fon(rho: float, NoL: float, NoV: float, LoV: float, r: float):
    """Fujii Oren-Nayar single scattering (EON paper's listing, f_ss in f_EON): f = rho/pi A_F (1 + r s / t),
    s = l.v - (n.l)(n.v), t = max(n.l, n.v) if s > 0 else 1. 0 when NoL or NoV <= COS_EPS; r = 0: Lambert."""
    if NoL <= COS_EPS or NoV <= COS_EPS:
        return 0.0
    s = LoV - NoL * NoV
    s_over_t = s
    if s > 0.0:
        s_over_t = s / wp.max(NoL, NoV)
    return rho * INV_PI * A_fon(r) * (1.0 + r * s_over_t)


@wp.func
def Fd_eon_multiple(rho: float, NoL: float, NoV: float, r: float):
    """EON's multiple-scattering lobe (EON paper's listing, f_ms in f_EON):
    rho_ms/pi (1 - E_F(n.l))(1 - E_F(n.v)) / (1 - E_avg),
    rho_ms = rho^2 E_avg / (1 - rho (1 - E_avg)), each 1 - E floored at 1e-7 as the paper's listing.
    Its albedo is rho_ms (1 - E_F(n.v)), so E_EON = rho E_F + rho_ms (1 - E_F): 1 for rho = 1."""
    if NoL <= COS_EPS or NoV <= COS_EPS:
        return 0.0
    e_avg = E_fon_avg(r)
    rho_ms = rho * rho * e_avg / (1.0 - rho * (1.0 - e_avg))
    one_l = wp.max(EON_EPS, 1.0 - E_fon(NoL, r))
    one_v = wp.max(EON_EPS, 1.0 - E_fon(NoV, r))
    return rho_ms * INV_PI * one_l * one_v / wp.max(EON_EPS, 1.0 - e_avg)


@wp.func
def Fd_eon(rho: float, NoL: float, NoV: float, LoV: float, r: float):
    """Energy-preserving Oren-Nayar (EON paper's listing, f_EON with exact = true; OpenPBR's diffuse BRDF), the
    exact-albedo variant:
    f = Fd_fon + Fd_eon_multiple. Reciprocal; r = 0: Lambert (plus 1e-7 / pi from the paper's floors);
    0 when NoL or NoV <= COS_EPS. (adobe/openpbr-bsdf evaluates E_F by the paper's polynomial fit, E_FON_approx.)"""
    return Fd_fon(rho, NoL, NoV, LoV, r) + Fd_eon_multiple(rho, NoL, NoV, r)


@wp.func
def F_facet_eq6(MoL: float, MoV: float, f0: float):
    """Per-facet transmission of the microfacet diffuse model, Eq. 6 with m in place of n:
    21/20 (1 - f0)(1 - (1 - m.l)^5)(1 - (1 - m.v)^5) (the form whose sigma = 0 limit Eq. 8 fits)."""
    return F_diff(MoL, MoV, f0)


@wp.func
def F_facet_schlick(MoL: float, MoV: float, f0: float):
    """Per-facet transmission (1 - F(m.l))(1 - F(m.v)), F Schlick; equals (1 - f0)^2 (1 - (1 - m.l)^5)(1 - (1 - m.v)^5):
    light refracted into the facet and back out, each once."""
    return (1.0 - f0) * (1.0 - f0) * pow5_weight(MoL) * pow5_weight(MoV)


@wp.func
def F_facet_dielectric_f0(MoL: float, MoV: float, f0: float):
    """Per-facet transmission (1 - F(m.l))(1 - F(m.v)) with F the exact dielectric Fresnel written with f0
    (Eq. 2): not of the form g(f0) x (an f0-free function), hence kind diffuse_3d (an f0 axis)."""
    return (1.0 - F_dielectric_f0(f0, MoL)) * (1.0 - F_dielectric_f0(f0, MoV))


# --- per-facet transmissions in float64, for the swapped-integral albedo (lutbake.sampling.swapped) ----------
# Every F_facet above is c(f0) T(m.l) T(m.v): Eq. 6 and Schlick with T = 1 - (1 - c)^5 and c(f0) = 21/20 (1 - f0)
# or (1 - f0)^2; the exact dielectric with T = 1 - F(f0, c) and c(f0) = 1.


@wp.func
def T_pow5(c: wp.float64, f0: wp.float64):
    """1 - (1 - c)^5: the transmission shape of Eq. 6 and of 1 - F_Schlick (its f0 factor is in c(f0))."""
    m = wp.float64(1.0) - c
    m2 = m * m
    return wp.float64(1.0) - m2 * m2 * m


@wp.func
def T_dielectric_f0(c: wp.float64, f0: wp.float64):
    """1 - F(f0, c) with F the exact dielectric Fresnel of Eq. 2 (evaluated in float32, as the terms)."""
    return wp.float64(1.0) - wp.float64(F_dielectric_f0(float(f0), float(c)))
