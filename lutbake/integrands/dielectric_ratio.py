"""OpenPBR's ideal-dielectric reflection ratio x(eta, alpha): the share of the multiple-scattering energy that its
``DielectricMicrofacetMultipleScatteringLobe`` (adobe/openpbr-bsdf, impl/openpbr_microfacet_multiple_scattering_lobes.h)
sends back to the view's side. That lobe restores E_c = 1 - (E_R + E_T) of the single-scattering interface and splits it

    f_ms(i -> o) = x(eta) E_c(eta, mu_i) E_c(eta, mu_o) / (pi E_c,avg(eta))                o on the view's side
    f_ms(i -> o) = (1 - x(eta)) E_c(eta, mu_i) E_c(1/eta, |mu_o|) / (pi E_c,avg(1/eta))      o on the other side,

so energy conservation holds for any x and the transmission lobe is symmetric iff

    (1 - x(eta)) E_c,avg(eta) = (1 - x(1/eta)) E_c,avg(1/eta)                              (reciprocity, no eta^2).

The source ships x without its generator ("a custom Monte Carlo integration tool"). The shipped array is reproduced,
with the shipped averages as input, within the worst-case effect of the arrays' UNORM16 rounding at every texel with
alpha > 0 and eta != 1 (max 6.5e-5 at alpha index >= 16; docs/glass-layouts.md) by this closed form in the two averages
and the hemispherical Fresnel average
F_avg of Kulla & Conty 2017 ("Revisiting physically based shading at Imageworks", SIGGRAPH course, slide 18; the fit
OpenPBR's openpbr_average_fresnel implements): for the two sides s, s' of the interface (eta_s' = 1/eta_s) put

    P_s = (1 - F_avg(eta_s)) E_c,avg(eta_s)       (what side s would transmit if it split its E_c by F_avg);

the side with the smaller P_s splits its energy in the ratio F_avg(eta_s) E_c,avg(eta_s) : P_s',

    x_s = F_avg(eta_s) E_c,avg(eta_s) / (F_avg(eta_s) E_c,avg(eta_s) + P_s'),

and the other side follows from the reciprocity relation. Both branches agree where P_s = P_s' (x = F_avg on both
sides there), so x is continuous. A random walk on the microsurface (Heitz et al. 2016) does not give this array
(measured max 0.58, mean 0.17 off; docs/glass-layouts.md).
"""

from __future__ import annotations

import numpy as np

# averages below this carry no ratio information (lutbake's quadrature error is ~7e-7; at alpha = 0 E_c,avg is 0 up to
# float32 rounding): both sides are clamped to it, as openpbr_clamp_average_energy_complement_above_zero clamps (1e-12)
EC_AVG_FLOOR = 1.0e-6
METADATA = (
    "x = the multiple-scattering lobe's reflected share (OpenPBR_IdealDielectricReflectionRatio): with "
    "P = (1 - F_avg(eta)) E_c,avg(eta) per side (F_avg: Kulla-Conty 2017 fit), the side with the smaller P takes "
    "x = F_avg E_c,avg / (F_avg E_c,avg + P_other), the other side (1 - x) E_c,avg = (1 - x_other) E_c,avg_other "
    f"(symmetric transmission); E_c,avg clamped >= {EC_AVG_FLOOR:g} (alpha = 0: no multiple scattering, never read by "
    "OpenPBR, whose lobe needs alpha >= 0.0016); eta = 1 rows: F_avg(1) = 0.002669 on both sides, x = 0.002669"
)


def average_fresnel(eta) -> np.ndarray:
    """Kulla & Conty 2017 (slide 18) fit of F_avg = 2 ∫ F(mu, eta) mu dmu, as adobe/openpbr-bsdf's
    openpbr_average_fresnel (impl/openpbr_lobe_utils.h): (eta - 1)/(4.08567 + 1.00071 eta) for eta > 1, a cubic in
    eta otherwise (eta = 1 takes the cubic: 0.002669)."""
    e = np.asarray(eta, np.float64)
    above = (e - 1.0) / (4.08567 + 1.00071 * e)
    below = 0.997118 + 0.1014 * e - 0.965241 * e * e - 0.130607 * e * e * e
    return np.where(e > 1.0, above, below)


def reflection_ratio(ec_avg, ec_avg_mirror, eta) -> np.ndarray:
    """x(eta) from E_c,avg(eta) (``ec_avg``) and E_c,avg(1/eta) (``ec_avg_mirror``), elementwise (module docstring)."""
    e_s = np.maximum(np.asarray(ec_avg, np.float64), EC_AVG_FLOOR)
    e_m = np.maximum(np.asarray(ec_avg_mirror, np.float64), EC_AVG_FLOOR)
    eta = np.asarray(eta, np.float64)
    f_s, f_m = average_fresnel(eta), average_fresnel(1.0 / eta)
    p_s, p_m = (1.0 - f_s) * e_s, (1.0 - f_m) * e_m
    direct = f_s * e_s / (f_s * e_s + p_m)  # this side splits first
    x_m = f_m * e_m / (f_m * e_m + p_s)  # the mirror side splits first; this side by reciprocity
    return np.where(p_s <= p_m, direct, 1.0 - (1.0 - x_m) * e_m / e_s)


def reciprocity_residual(x, ec_avg, x_mirror, ec_avg_mirror) -> np.ndarray:
    """(1 - x(eta)) E_c,avg(eta) - (1 - x(1/eta)) E_c,avg(1/eta): 0 for a symmetric transmission lobe."""
    return (1.0 - np.asarray(x, np.float64)) * np.asarray(ec_avg, np.float64) - (
        1.0 - np.asarray(x_mirror, np.float64)
    ) * np.asarray(ec_avg_mirror, np.float64)
