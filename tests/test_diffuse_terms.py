"""Diffuse terms (lutbake.terms.diffuse) against independent numpy references; the microfacet diffuse
BRDF (Eq. 4) against a numpy reference integrator, its sigma = 0 limit and reciprocity."""

import numpy as np
import pytest
import warp as wp

from lutbake.integrands import diffuse as tdiff
from lutbake.terms import diffuse

TERM_RTOL = 2e-5  # float32 terms vs float64 numpy
INNER_RTOL = 1e-6  # microfacet quadrature (order 16) vs the converged numpy reference: measured 2.5e-7
LIMIT_RTOL = 2e-4  # sigma -> 0 limit (alpha = ALPHA_MIN) vs Lambert x Eq. 6
RECIP_RTOL = 1e-5


@wp.kernel(enable_backward=False)
def closed_forms(
    NoL: wp.array(dtype=float),
    NoV: wp.array(dtype=float),
    LoV: wp.array(dtype=float),
    sigma: wp.array(dtype=float),
    f0: wp.array(dtype=float),
    rho: wp.array(dtype=float),
    out: wp.array2d(dtype=float),
):
    i = wp.tid()
    a, b, c, s, f, r = NoL[i], NoV[i], LoV[i], sigma[i], f0[i], rho[i]
    out[i, 0] = diffuse.Fd_lambert(r)
    out[i, 1] = diffuse.Fd_oren_nayar(r, a, b, c, s)
    out[i, 2] = diffuse.Fd_oren_nayar_improved(r, a, b, c, s)
    out[i, 3] = diffuse.Fd_oren_nayar_fresnel(r, a, b, c, s, f)
    out[i, 4] = diffuse.Fd_gotanda_fitted(r, a, b, c, s, f)
    out[i, 5] = diffuse.Fd_gotanda_fitted_slides(r, a, b, c, s, f)
    out[i, 6] = diffuse.F_diff(a, b, f)
    out[i, 7] = diffuse.F_facet_schlick(a, b, f)


def run_closed(NoL, NoV, LoV, sigma, f0, rho):
    args = [
        np.ascontiguousarray(np.broadcast_to(np.asarray(x, np.float32), np.shape(NoL)))
        for x in (NoL, NoV, LoV, sigma, f0, rho)
    ]
    out = wp.zeros((len(args[0]), 8), dtype=float, device="cpu")
    wp.launch(closed_forms, dim=len(args[0]), inputs=[wp.array(a, dtype=float) for a in args] + [out], device="cpu")
    return out.numpy().astype(np.float64)


# ---- numpy references, written from the seed's formulas with angles where the seed uses angles ----


def ref_on_classic(rho, tl, tv, phi, sigma):
    A = 1 - 0.5 * sigma**2 / (sigma**2 + 0.57)
    B = 0.45 * sigma**2 / (sigma**2 + 0.09)
    al, be = np.maximum(tl, tv), np.minimum(tl, tv)
    return rho / np.pi * (A + B * np.maximum(0, np.cos(phi)) * np.sin(al) * np.tan(be))


def ref_on_improved_radiance(rho, nl, nv, el, sigma):
    s = el - nv * nl
    A = 1 - 0.5 * sigma**2 / (sigma**2 + 0.65)
    B = 0.45 * sigma**2 / (sigma**2 + 0.09)
    return np.where(s >= 0, rho / np.pi * (nl * A + B * s * np.minimum(1, nl / nv)), rho / np.pi * (nl * A + B * s))


def ref_fdiff(nl, nv, f0):
    return 21 / 20 * (1 - f0) * (1 - (1 - nl) ** 5) * (1 - (1 - nv) ** 5)


def ref_on_fresnel_radiance(rho, nl, nv, el, sigma, f0):
    s = el - nv * nl
    A = 1 - 0.5 * sigma**2 / (sigma**2 + 0.65)
    B = 0.45 * sigma**2 / (sigma**2 + 0.09)
    Fd = ref_fdiff(nl, nv, 0.0)  # (1 - f0) counted once, outside
    return rho / np.pi * (1 - f0) * (Fd * nl * A + B * s * np.minimum(1, nl / nv))


def ref_fitted_radiance(nl, nv, el, sg, f0, slides=False):
    k = sg**2 + 1.36053
    second = (1 - (1 - nv) ** (5 - 4 * sg**2)) / k if slides else 1 - (1 - nv) ** (5 - 4 * sg**2) / k
    Fr = (
        (1 - (0.542026 * sg**2 + 0.303573 * sg) / k)
        * second
        * ((-0.733996 * sg**3 + 1.50912 * sg**2 - 1.16402 * sg) * (1 - nv) ** (1 + 1 / (39 * sg**4 + 1)) + 1)
    )
    Lm = (np.maximum(1 - 2 * sg, 0) * (1 - (1 - nl) ** 5) + np.minimum(2 * sg, 1)) * (
        (1 - 0.5 * sg) * nl + 0.5 * sg * nl**2
    )
    Vd = (
        sg**2
        / ((sg**2 + 0.09) * (1.31072 + 0.995584 * nv))
        * (1 - (1 - nl) ** ((1 - 0.3726732 * nv**2) / (0.188566 + 0.388410 * nv)))
    )
    s = el - nv * nl
    Bp = np.where(s < 0, 1.4 * nv * nl * s, s)
    return 21 / (20 * np.pi) * (1 - f0) * (Fr * Lm + Vd * Bp)


@pytest.fixture(scope="module")
def cases():
    rng = np.random.default_rng(3)
    n = 512
    tl, tv = rng.uniform(0.02, 1.55, n), rng.uniform(0.02, 1.55, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    sigma, f0, rho = rng.uniform(0, 1, n), rng.uniform(0, 0.2, n), rng.uniform(0.1, 1, n)
    nl, nv = np.cos(tl), np.cos(tv)
    el = np.sin(tl) * np.sin(tv) * np.cos(phi) + nl * nv
    out = run_closed(nl, nv, el, sigma, f0, rho)
    return dict(tl=tl, tv=tv, phi=phi, sigma=sigma, f0=f0, rho=rho, nl=nl, nv=nv, el=el, out=out)


def test_Fd_lambert_is_rho_over_pi(cases):
    np.testing.assert_allclose(cases["out"][:, 0], cases["rho"] / np.pi, rtol=TERM_RTOL)


def test_Fd_oren_nayar_matches_angle_form(cases):
    c = cases
    ref = ref_on_classic(c["rho"], c["tl"], c["tv"], c["phi"], c["sigma"])
    np.testing.assert_allclose(c["out"][:, 1], ref, rtol=1e-4, atol=1e-6)


def test_Fd_oren_nayar_improved_is_eq5_over_nl(cases):
    c = cases
    ref = np.maximum(ref_on_improved_radiance(c["rho"], c["nl"], c["nv"], c["el"], c["sigma"]), 0) / c["nl"]
    np.testing.assert_allclose(c["out"][:, 2], ref, rtol=1e-4, atol=1e-6)


def test_Fd_oren_nayar_fresnel_is_eq7_over_nl(cases):
    c = cases
    ref = np.maximum(ref_on_fresnel_radiance(c["rho"], c["nl"], c["nv"], c["el"], c["sigma"], c["f0"]), 0) / c["nl"]
    np.testing.assert_allclose(c["out"][:, 3], ref, rtol=1e-4, atol=1e-6)


@pytest.mark.parametrize("col, slides", [(4, False), (5, True)])
def test_Fd_gotanda_fitted_is_eq8_over_nl(cases, col, slides):
    c = cases
    ref = c["rho"] * ref_fitted_radiance(c["nl"], c["nv"], c["el"], c["sigma"], c["f0"], slides) / c["nl"]
    np.testing.assert_allclose(c["out"][:, col], ref, rtol=1e-4, atol=1e-6)


def test_F_diff_and_facet_schlick(cases):
    c = cases
    np.testing.assert_allclose(c["out"][:, 6], ref_fdiff(c["nl"], c["nv"], c["f0"]), rtol=TERM_RTOL, atol=1e-7)
    schlick = lambda x: c["f0"] + (1 - c["f0"]) * (1 - x) ** 5  # noqa: E731
    np.testing.assert_allclose(c["out"][:, 7], (1 - schlick(c["nl"])) * (1 - schlick(c["nv"])), rtol=1e-4, atol=1e-7)


def test_oren_nayar_at_sigma_0_is_lambert(cases):
    c = cases
    out = run_closed(c["nl"], c["nv"], c["el"], 0.0, c["f0"], c["rho"])
    np.testing.assert_allclose(out[:, 1], c["rho"] / np.pi, rtol=TERM_RTOL)
    np.testing.assert_allclose(out[:, 2], c["rho"] / np.pi, rtol=TERM_RTOL)
    # Eq. 7 at sigma = 0 is Lambert x Eq. 6 ((1 - f0) once)
    np.testing.assert_allclose(out[:, 3], c["rho"] / np.pi * ref_fdiff(c["nl"], c["nv"], c["f0"]), rtol=1e-4)


def test_terms_are_zero_below_the_horizon():
    out = run_closed(np.array([0.0, 0.5, -0.3]), np.array([0.5, 0.0, 0.5]), np.array([0.1, 0.1, 0.1]), 0.5, 0.04, 1.0)
    assert np.all(out[:, 1:6] == 0.0)


# ---- the microfacet diffuse BRDF (Eq. 4) ----


def ggx(cos_m, alpha):
    c2 = cos_m**2
    return alpha**2 / (np.pi * (c2 * alpha**2 + 1 - c2) ** 2)


def lambda_ggx(c, alpha):
    return 0.5 * (np.sqrt(c**2 + alpha**2 * (1 - c**2)) / c - 1)


def ref_microfacet(l, v, alpha, f0, graded_rule, facet="eq6", order=16):
    """Eq. 4 over the microfacet normal m in (theta_m, phi_m). The clamps <m.l>, <m.v> vanish outside one
    arc of phi_m each; for every theta_m node the rule in phi_m is Gauss-Legendre on the pieces between
    those arcs' ends (the integrand is analytic on each piece, zero on some), and in theta_m a graded
    Gauss-Legendre rule toward pi/2 - theta_l and pi/2 - theta_v, where an arc opens (a square-root edge).

    Converged: order 30 with finer grading changes it by < 4e-12 relative on PAIRS, and the GL x 2048-point
    periodic trapezoid rule this test used before (600 theta nodes per panel) agrees to < 1e-10."""
    nl, nv = l[2], v[2]
    th, w_th = graded_rule(0.0, np.pi / 2, [0.0, np.pi / 2 - np.arccos(nl), np.pi / 2 - np.arccos(nv), np.pi / 2])
    ends = [np.zeros_like(th), np.full_like(th, 2 * np.pi)]
    for d in (l, v):  # m.d = 0 where cos(phi_m - phi_d) = -cot(theta_m) cot(theta_d): the arc's two ends
        with np.errstate(divide="ignore", invalid="ignore"):
            c = -np.cos(th) * d[2] / (np.sin(th) * np.hypot(d[0], d[1]))
        half = np.arccos(np.clip(np.nan_to_num(c, nan=-2.0, posinf=2.0, neginf=-2.0), -1, 1))
        phi_d = np.arctan2(d[1], d[0])
        ends += [np.mod(phi_d + half, 2 * np.pi), np.mod(phi_d - half, 2 * np.pi)]
    cuts = np.sort(np.stack(ends, 1), axis=1)[:, :, None]  # (theta node, 6 ends, 1)
    x, w = np.polynomial.legendre.leggauss(order)
    lo, hi = cuts[:, :-1], cuts[:, 1:]  # 5 pieces of [0, 2 pi) per theta node
    phi, w_phi = (lo + hi) / 2 + (hi - lo) / 2 * x, (hi - lo) / 2 * w
    t = th[:, None, None]
    m = np.stack([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.broadcast_to(np.cos(t), phi.shape)], -1)
    ml, mv = np.maximum(m @ l, 0), np.maximum(m @ v, 0)
    tr = lambda c: 1 - (1 - c) ** 5  # noqa: E731
    F = 1.05 * (1 - f0) * tr(ml) * tr(mv) if facet == "eq6" else (1 - f0) ** 2 * tr(ml) * tr(mv)
    g = ml * mv * ggx(np.cos(t), alpha) * F * np.sin(t)
    total = np.einsum("i,ijk->", w_th, g * w_phi)
    G2 = 1 / (1 + lambda_ggx(nl, alpha) + lambda_ggx(nv, alpha))
    return G2 * total / (np.pi * nl * nv)


def unit(theta, phi):
    return np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])


PAIRS = [(0.3, 0.0, 0.5, 0.0), (1.2, 2.5, 0.4, 0.0), (1.45, 0.0, 1.45, 0.0), (0.7, 3.1, 1.3, 0.0), (1.0, 1.0, 0.2, 0.0)]


@pytest.mark.parametrize("alpha", [0.25, 1.0])
def test_microfacet_inner_integral_matches_numpy_reference(alpha, graded_rule):
    l = np.array([unit(tl, pl) for tl, pl, _, _ in PAIRS])
    v = np.array([unit(tv, pv) for _, _, tv, pv in PAIRS])
    got = tdiff.eval_brdf("microfacet", l, v, alpha, f0=0.04, sigma_to_alpha="sigma", order=16)
    ref = [
        ref_microfacet(
            l[i].astype(np.float32).astype(np.float64),
            v[i].astype(np.float32).astype(np.float64),
            np.float32(alpha),
            0.04,
            graded_rule,
        )
        for i in range(len(l))
    ]
    np.testing.assert_allclose(got, ref, rtol=INNER_RTOL)


def test_microfacet_at_sigma_0_is_lambert_times_eq6():
    rng = np.random.default_rng(5)
    n = 256
    tl, tv, pl = rng.uniform(0, 1.55, n), rng.uniform(0, 1.55, n), rng.uniform(0, 2 * np.pi, n)
    l = np.stack([unit(a, b) for a, b in zip(tl, pl)])
    v = np.stack([unit(a, 0.0) for a in tv])
    got = tdiff.eval_brdf("microfacet", l, v, 0.0, f0=0.04, order=8)
    l32, v32 = l.astype(np.float32), v.astype(np.float32)
    np.testing.assert_allclose(
        got, ref_fdiff(l32[:, 2].astype(float), v32[:, 2].astype(float), 0.04) / np.pi, rtol=LIMIT_RTOL
    )


def test_microfacet_is_reciprocal():
    rng = np.random.default_rng(6)
    n = 128
    l = np.stack([unit(a, b) for a, b in zip(rng.uniform(0, 1.5, n), rng.uniform(0, 2 * np.pi, n))])
    v = np.stack([unit(a, b) for a, b in zip(rng.uniform(0, 1.5, n), rng.uniform(0, 2 * np.pi, n))])
    s = rng.uniform(0, 1, n)
    f_lv = tdiff.eval_brdf("microfacet", l, v, s, f0=0.04, order=8)
    f_vl = tdiff.eval_brdf("microfacet", v, l, s, f0=0.04, order=8)
    np.testing.assert_allclose(f_lv, f_vl, rtol=RECIP_RTOL)


def test_fitted_model_matches_integrated_at_sigma_0_normal_view():
    from lutbake.commands.figures import FIGURES, curves

    fig = FIGURES[0]  # Fig. 11a: n.e = 1, sigma = 0
    assert (fig.fixed_cos, fig.sigma) == (1.0, 0.0)
    theta = np.linspace(0.0, 1.5, 16)
    c = curves(fig, theta, ("microfacet", "fitted"), order=8)
    np.testing.assert_allclose(c["fitted"], c["microfacet"], rtol=LIMIT_RTOL, atol=1e-6)
