"""Fresnel reflectance terms (Gotanda 2014 course notes, Sec. 2 and Eqs. 2-3; docs/notation.md).
``cos_theta`` is the cosine between the direction and the microfacet normal (v.h for a specular BRDF); every term
returns f0 at cos = 1 and 1 at cos = 0."""

import warp as wp


@wp.func
def F_schlick(f0: float, cos_theta: float):
    """Schlick 1994: F = f0 + (1 - f0)(1 - cos)^5 (Gotanda 2014 course notes, Sec. 2)."""
    return f0 + (1.0 - f0) * Fc_schlick(cos_theta)


@wp.func
def Fc_schlick(cos_theta: float):
    """The Schlick weight (1 - cos)^5, clamped to [0, 1]: the split-sum's 'bias' factor."""
    m = wp.clamp(1.0 - cos_theta, 0.0, 1.0)
    m2 = m * m
    return m2 * m2 * m


@wp.func
def F_dielectric(eta: float, cos_theta: float):
    """Exact unpolarised Fresnel reflectance of a dielectric of relative index eta >= 1
    (Walter et al. 2007, Eq. 22): g = sqrt(eta^2 - 1 + c^2),
    F = 1/2 ((g-c)/(g+c))^2 (1 + ((c(g+c) - 1) / (c(g-c) + 1))^2)."""
    c = wp.clamp(cos_theta, 0.0, 1.0)
    g = wp.sqrt(wp.max(eta * eta - 1.0 + c * c, 0.0))
    if g + c <= 0.0:
        return 1.0
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    return 0.5 * a * a * (1.0 + b * b)


@wp.func
def F_dielectric_f0(f0: float, cos_theta: float):
    """Gotanda 2014 course notes, Eq. 2: the exact dielectric Fresnel written with f0, s = sqrt(f0):
    F = 1/2 {[((s+1)c + (s-1)a) / ((s+1)c - (s-1)a)]^2 + [((s-1)c + (s+1)a) / ((s-1)c - (s+1)a)]^2},
    a = sqrt(1 - (s-1)^2 (1-c^2) / (s+1)^2). Equals F_dielectric with eta = (1+s)/(1-s).
    a is evaluated as sqrt(4 s + (s-1)^2 c^2) / (s+1) (the same, since (s+1)^2 - (s-1)^2 = 4s): the
    printed form cancels in float32 at grazing c and returned 1 instead of 0 for f0 = 0.
    Domain f0 in [0, 1): at f0 -> 1 (eta -> inf) it returns 1."""
    s = wp.sqrt(wp.clamp(f0, 0.0, 1.0))
    c = wp.clamp(cos_theta, 0.0, 1.0)
    sp = s + 1.0
    sm = s - 1.0
    a = wp.sqrt(4.0 * s + sm * sm * c * c) / sp
    d1 = sp * c - sm * a
    d2 = sm * c - sp * a
    if d1 == 0.0 or d2 == 0.0:
        return 1.0
    r1 = (sp * c + sm * a) / d1
    r2 = (sm * c + sp * a) / d2
    return 0.5 * (r1 * r1 + r2 * r2)


@wp.func
def F_schlick_sg(f0: float, cos_theta: float):
    """Spherical-Gaussian approximation of Schlick's weight (Lagarde 2012, "Spherical Gaussian
    approximation for Blinn-Phong, Phong and Fresnel"; Karis 2013, UE4 course notes; Gotanda 2014
    slides, "Better model for Fresnel?"): F = f0 + (1 - f0) 2^((-5.55473 c - 6.98316) c), c = v.h.
    Domain c in [0, 1] (clamped). At c = 0 it returns 1; at c = 1 it returns f0 + (1 - f0) 2^-12.5
    (not exactly f0: 1.7e-4 above it)."""
    c = wp.clamp(cos_theta, 0.0, 1.0)
    return f0 + (1.0 - f0) * wp.pow(2.0, (-5.55473 * c - 6.98316) * c)


@wp.func
def F_improved_sg(f0: float, cos_theta: float):
    """Gotanda 2014 course notes, Eq. 3, "improved spherical Gaussian", fitted to eta = 1.5:
    F = f0 + (1 - f0) 2^(-9.60232 c^8 - 8.58092 c), c = cos theta clamped to [0, 1].
    At c = 0 it returns 1; at c = 1, f0 + (1 - f0) 2^-18.18 (3.4e-6 above f0)."""
    c = wp.clamp(cos_theta, 0.0, 1.0)
    c2 = c * c
    c4 = c2 * c2
    return f0 + (1.0 - f0) * wp.pow(2.0, -9.60232 * c4 * c4 - 8.58092 * c)


@wp.func
def F_conductor(n: float, k: float, cos_theta: float):
    """Exact unpolarised Fresnel reflectance of an interface from vacuum into a medium of complex
    index n + ik (Born & Wolf, Principles of Optics, Sec. 14.2; written as in Lagarde 2013, "Memo on
    Fresnel equations", conductor form), with c = cos theta, s2 = 1 - c^2:
        t0 = n^2 - k^2 - s2,  a2b2 = sqrt(t0^2 + 4 n^2 k^2),  a = sqrt((a2b2 + t0) / 2)
        Rs = (a2b2 + c^2 - 2 a c) / (a2b2 + c^2 + 2 a c)
        Rp = Rs (c^2 a2b2 + s2^2 - 2 a c s2) / (c^2 a2b2 + s2^2 + 2 a c s2),   F = (Rs + Rp) / 2.
    k = 0 gives the dielectric F_dielectric(n, c) (and total internal reflection, F = 1, for n < 1
    beyond the critical angle). Domain: n > 0, k >= 0, c in [0, 1] (clamped). At c = 0 it returns 1;
    the one 0/0 (n = 1, k = 0, c = 0) returns 1.
    Where t0 < 0 (k > n: every metal here), a2b2 + t0 cancels (silver's t0 ~ -20 against a2b2 + t0 ~ 5e-3: F off by
    up to 2.1e-6 in float32); there a = n k sqrt(2 / (a2b2 - t0)), the same since (a2b2 + t0)(a2b2 - t0) = 4 n^2 k^2
    (float32 error 2.1e-6 -> ~2e-7 for silver, as for the other metals)."""
    c = wp.clamp(cos_theta, 0.0, 1.0)
    c2 = c * c
    s2 = 1.0 - c2
    t0 = n * n - k * k - s2
    a2b2 = wp.sqrt(t0 * t0 + 4.0 * n * n * k * k)
    a = wp.sqrt(wp.max(0.5 * (a2b2 + t0), 0.0))
    if t0 < 0.0:
        a = n * k * wp.sqrt(2.0 / (a2b2 - t0))
    t1 = a2b2 + c2
    t2 = 2.0 * a * c
    if t1 + t2 <= 0.0:
        return 1.0
    rs = (t1 - t2) / (t1 + t2)
    t3 = c2 * a2b2 + s2 * s2
    t4 = t2 * s2
    if t3 + t4 <= 0.0:
        return 1.0
    rp = rs * (t3 - t4) / (t3 + t4)
    return 0.5 * (rs + rp)


@wp.func
def F_lazanyi(n: float, k: float, a: float, alpha: float, cos_theta: float):
    """Lazanyi & Szirmay-Kalos 2005, "Fresnel term approximations for metals" (WSCG short papers,
    pp. 77-80; cited by Gotanda 2014 course notes, ref. [9]): Schlick's formula rescaled for a complex
    index, minus a term compensating its residual error,
        F = ((n-1)^2 + 4 n (1-c)^5 + k^2) / ((n+1)^2 + k^2) - a c (1-c)^alpha
    (the form as reproduced by Hoffman 2019, "Fresnel equations considered harmful", Sec. 3).
    The first term is Schlick with f0 = ((n-1)^2 + k^2)/((n+1)^2 + k^2) (since 1 - f0 = 4n/((n+1)^2+k^2));
    ``a`` is fitted per wavelength against the exact curve (lutbake.metals.fit_lazanyi_a), and
    ``alpha`` is a fixed exponent (LAZANYI_ALPHA = 6). Domain c in [0, 1] (clamped); returns 1 at c = 0
    and f0 at c = 1, as Schlick does."""
    c = wp.clamp(cos_theta, 0.0, 1.0)
    m = 1.0 - c
    m2 = m * m
    m5 = m2 * m2 * m
    den = (n + 1.0) * (n + 1.0) + k * k
    return ((n - 1.0) * (n - 1.0) + 4.0 * n * m5 + k * k) / den - a * c * wp.pow(m, alpha)
