"""Masking-shadowing: Smith's Lambda per NDF, G1, the two Smith G2 forms, and the V-cavity G.

Smith G1(v) = 1 / (1 + Lambda(v)) (Heitz 2014, JCGT 3(2), Eq. 43). G2 takes Lambda values, so any
Smith form composes with any NDF's Lambda. Every function returns 0 for a back-facing direction
(cosine <= COS_EPS); at n.v -> 0, Lambda -> alpha / (2 n.v) and G -> 0 linearly.
"""

import warp as wp

from ..edge import COS_EPS

LAMBDA_INF = wp.constant(1.0e30)


@wp.func
def Lambda_ggx(NoX: float, alpha: float):
    """Smith Lambda for GGX (Heitz 2014, Eq. 72): (-1 + sqrt(1 + alpha^2 tan^2 theta)) / 2,
    written as (sqrt(c^2 + alpha^2 (1 - c^2)) / c - 1) / 2 with c = n.x to avoid tan at grazing."""
    if NoX <= COS_EPS:
        return LAMBDA_INF
    c2 = NoX * NoX
    return 0.5 * (wp.sqrt(c2 + alpha * alpha * (1.0 - c2)) / NoX - 1.0)


@wp.func
def Lambda_beckmann(NoX: float, alpha: float):
    """Smith Lambda for Beckmann (Heitz 2014, Eq. 69), a = 1 / (alpha tan theta):
    (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)). Exact erf, not Walter's rational fit."""
    if NoX <= COS_EPS:
        return LAMBDA_INF
    s = wp.sqrt(wp.max(1.0 - NoX * NoX, 0.0))
    if s <= 0.0:
        return 0.0
    a = NoX / (alpha * s)
    if a > 9.0:  # erfc(9) < 1e-36: Lambda is 0 to float precision
        return 0.0
    return 0.5 * (wp.erf(a) - 1.0) + wp.exp(-a * a) / (2.0 * a * wp.sqrt(wp.pi))


@wp.func
def G1_smith(Lambda_x: float):
    """Smith masking G1 = 1 / (1 + Lambda) (Heitz 2014, Eq. 43)."""
    return 1.0 / (1.0 + Lambda_x)


@wp.func
def G2_smith_height_correlated(Lambda_v: float, Lambda_l: float):
    """Height-correlated Smith G2 = 1 / (1 + Lambda(v) + Lambda(l)) (Heitz 2014, Eq. 99)."""
    return 1.0 / (1.0 + Lambda_v + Lambda_l)


@wp.func
def G2_smith_separable(Lambda_v: float, Lambda_l: float):
    """Separable (uncorrelated) Smith G2 = G1(v) G1(l) (Heitz 2014, Eq. 98)."""
    return 1.0 / ((1.0 + Lambda_v) * (1.0 + Lambda_l))


@wp.func
def G2_v_cavity(NoH: float, NoV: float, NoL: float, VoH: float, LoH: float):
    """Torrance-Sparrow V-cavity (Cook & Torrance 1982; lecture 003):
    G = min(1, 2 (n.h)(n.v) / (v.h), 2 (n.h)(n.l) / (l.h)). 0 for back-facing v.h, l.h or n.h."""
    if VoH <= COS_EPS or LoH <= COS_EPS or NoH <= 0.0:
        return 0.0
    return wp.min(1.0, wp.min(2.0 * NoH * NoV / VoH, 2.0 * NoH * NoL / LoH))


@wp.func
def Lambda_ggx_aniso(v: wp.vec3, alpha_x: float, alpha_y: float):
    """Smith Lambda for anisotropic GGX (Heitz 2014, Eq. 86 with alpha(phi_v)^2 = cos^2 ax^2 + sin^2 ay^2):
    (sqrt(v.z^2 + ax^2 v.x^2 + ay^2 v.y^2) / v.z - 1) / 2; ax = ay = alpha gives Lambda_ggx."""
    if v[2] <= COS_EPS:
        return LAMBDA_INF
    return 0.5 * (wp.sqrt(v[2] * v[2] + alpha_x * alpha_x * v[0] * v[0] + alpha_y * alpha_y * v[1] * v[1]) / v[2] - 1.0)


@wp.func
def V_ashikhmin(NoV: float, NoL: float):
    """Ashikhmin & Premoze 2007 cloth visibility, 1/(4 NoL NoV) folded in (a V_ term, not a G):
    V = 1 / (4 (n.l + n.v - (n.l)(n.v))) (Filament's V_Neubelt / Visibility_Ashikhmin). Finite
    everywhere on the upper hemisphere (1/4 at n.l = 1 or n.v = 1; 1/(4 n.v) at n.l -> 0)."""
    return 1.0 / (4.0 * (NoL + NoV - NoL * NoV))


# Estevez & Kulla 2017, Table 1: the fit's (a, b, c, d, e) at alpha = 1 and at alpha = 0 (KHR_materials_sheen,
# "Sheen visibility"). sheen_l interpolates them in t = (1 - alpha)^2; the constants and their slopes are float64
# (Warp evaluates a literal expression such as 25.3245 - 21.5473 in float32: 1.2e-6 off, which moved Lambda by 1e-6
# relative and the sheen albedo with it, measured against the KHR formula in numpy)
SHEEN_FIT_ALPHA_1 = (21.5473, 3.82987, 0.19823, -1.97760, -4.32054)
SHEEN_FIT_ALPHA_0 = (25.3245, 3.32435, 0.16801, -1.27393, -4.85967)
SheenFit = wp.types.vector(length=5, dtype=wp.float64)
SHEEN_FIT_AT_1 = wp.constant(SheenFit(*SHEEN_FIT_ALPHA_1))
SHEEN_FIT_SLOPE = wp.constant(SheenFit(*(lo - hi for hi, lo in zip(SHEEN_FIT_ALPHA_1, SHEEN_FIT_ALPHA_0))))


@wp.func
def sheen_l(x: wp.float64, alpha: wp.float64):
    """Estevez & Kulla 2017's fit l(x) of the Charlie sheen Lambda (their Table 1, interpolated in
    (1 - alpha)^2), as written in KHR_materials_sheen's "Sheen visibility" and the glTF Sample Viewer's
    lambdaSheenNumericHelper. In float64: l reaches ~17 at x -> 0, and exp(l) would carry float32's rounding of
    l times 17 (measured: 9e-7 relative in the sheen albedo at n.v = 0.017)."""
    one = wp.float64(1.0)
    t = (one - alpha) * (one - alpha)
    k = SHEEN_FIT_AT_1 + SHEEN_FIT_SLOPE * t  # (a, b, c, d, e)
    return k[0] / (one + k[1] * wp.pow(wp.max(x, wp.float64(0.0)), k[2])) + k[3] * x + k[4]


# where lambda_sheen switches formula: Lambda is C1 there, its second derivative jumps (the quadratures that integrate
# V_charlie split their panels along n.l = LAMBDA_SHEEN_SWITCH: lutbake.integrands.specular, SpecularIntegrand.nol_kink)
LAMBDA_SHEEN_SWITCH = 0.5


@wp.func
def lambda_sheen(cos_theta: float, alpha: float):
    """Charlie sheen Lambda: exp(l(cos)) below cos = 0.5, exp(2 l(0.5) - l(1 - cos)) above (Estevez & Kulla 2017),
    evaluated in float64 (sheen_l)."""
    c = wp.float64(wp.abs(cos_theta))
    a = wp.float64(alpha)
    if c < wp.float64(wp.static(LAMBDA_SHEEN_SWITCH)):
        return float(wp.exp(sheen_l(c, a)))
    return float(
        wp.exp(
            wp.float64(2.0) * sheen_l(wp.float64(wp.static(LAMBDA_SHEEN_SWITCH)), a) - sheen_l(wp.float64(1.0) - c, a)
        )
    )


@wp.func
def V_charlie(NoV: float, NoL: float, alpha: float):
    """Charlie sheen visibility (KHR_materials_sheen, Estevez & Kulla 2017), 1/(4 NoL NoV) folded in:
    V = 1 / ((1 + Lambda(n.v) + Lambda(n.l)) 4 (n.v)(n.l)), unclamped (the glTF Sample Viewer clamps V to
    [0, 1]; only NoV, NoL -> 0 can exceed 1, where the Lambdas are ~e^17). 0 for a back-facing n.l or n.v."""
    if NoV <= COS_EPS or NoL <= COS_EPS:
        return 0.0
    return 1.0 / ((1.0 + lambda_sheen(NoV, alpha) + lambda_sheen(NoL, alpha)) * 4.0 * NoV * NoL)


@wp.func
def G2_smith_joint_approx(NoV: float, NoL: float, alpha: float):
    """Unreal Engine 4's ``Vis_SmithJointApprox`` written as a G2 (Karis; Hammon 2017's linear
    approximation of height-correlated Smith for GGX):
    G2 = 4 (n.l)(n.v) Vis = 2 (n.l)(n.v) / ((n.l)((n.v)(1 - alpha) + alpha) + (n.v)((n.l)(1 - alpha) + alpha)).
    0 for a back-facing n.l or n.v."""
    if NoV <= COS_EPS or NoL <= COS_EPS:
        return 0.0
    return 2.0 * NoL * NoV / (NoL * (NoV * (1.0 - alpha) + alpha) + NoV * (NoL * (1.0 - alpha) + alpha))


@wp.func
def G1_schlick_ggx(NoX: float, k: float):
    """Schlick's G1 approximation (Schlick 1994) as Karis writes it for GGX ("Real Shading in Unreal Engine 4", 2013,
    Eq. 4): n.x / ((n.x)(1 - k) + k)."""
    return NoX / (NoX * (1.0 - k) + k)


@wp.func
def G2_schlick_ggx_ibl(NoV: float, NoL: float, alpha: float):
    """Separable Schlick-GGX G2 = G1(v) G1(l) with Karis 2013's IBL choice k = alpha / 2 (no (r + 1)/2 remap), as
    Godot's integrate_dfg.glsl (geometry_smith) and LearnOpenGL's IBL code. 0 for a back-facing n.l or n.v."""
    if NoV <= COS_EPS or NoL <= COS_EPS:
        return 0.0
    k = 0.5 * alpha
    return G1_schlick_ggx(NoV, k) * G1_schlick_ggx(NoL, k)


@wp.func
def Lambda_ggx64(NoX: wp.float64, alpha: wp.float64):
    """Lambda_ggx in float64, for n.x > 0 (the swapped-integral albedo's nodes never reach the horizon)."""
    c2 = NoX * NoX
    return wp.float64(0.5) * (wp.sqrt(c2 + alpha * alpha * (wp.float64(1.0) - c2)) / NoX - wp.float64(1.0))
