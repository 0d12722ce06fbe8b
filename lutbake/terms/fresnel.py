"""Fresnel reflectance terms. ``cos_theta`` is the cosine between the direction and the
microfacet normal (v.h for a specular BRDF); every term returns f0 at cos = 1 and 1 at cos = 0."""
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
