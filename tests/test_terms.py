"""Every ``@wp.func`` term against an independent numpy/scipy reference written here, plus edge sweeps.

The references use the textbook forms (tan-based NDFs, Lambda from tan, scipy's erf, Fresnel from Snell's
law), not the terms' rearrangements, and run in float64 on the float32-rounded inputs the terms see.
"""

from typing import Any

import numpy as np
import pytest
from scipy.special import erf

from lutbake.edge import ALPHA_MIN, COS_EPS
from lutbake.validate.probe import BRDF_PAIRS, TERM_NAMES, evaluate_brdfs, evaluate_terms

# Tolerances: the terms compute in float32 (unit roundoff 6e-8).
D_RTOL = 1.0e-6
D_BECKMANN_RTOL_PER_EXPONENT = (
    2.0e-7  # exp(-x): x = tan^2/alpha^2 takes ~3 float32 roundings (3 x 6e-8 relative), amplified by x
)
D_BECKMANN_ATOL = 1.0e-30  # exp(-x) underflows float32 (denormals below 1.2e-38)
LAMBDA_RTOL = 2.0e-6
LAMBDA_ATOL = 3.0e-7  # Lambda ~ 0 near normal view: (sqrt(...)/c - 1) and (erf(a) - 1) cancel in float32
G_RTOL = 2.0e-6
G_ATOL = 3.0e-7
F_ATOL = 1.0e-6
BRDF_RTOL = 2.0e-5  # the whole product, incl. the half vector from float32 l + v
BRDF_ATOL = 1.0e-30  # Beckmann's exp(-tan^2/alpha^2) underflows float32 (denormals below 1.2e-38)

ALPHAS = np.array([ALPHA_MIN, 1.0e-3, 0.01, 0.05, 0.1, 0.3, 0.5, 0.8, 1.0])
ETAS = np.array([1.0, 1.05, 1.2, 1.33, 1.5, 2.0, 2.4, 4.0, 10.0])
F0S = np.array([0.0, 1.0e-4, 0.02, 0.04, 0.1, 0.25, 0.5, 0.75, 0.9])


def f32(x):
    """The float32 value the term sees, as float64."""
    return np.asarray(x, dtype=np.float32).astype(np.float64)


def hemisphere_cosines(n=64):
    """Cosines from grazing to normal, denser near both ends."""
    t = np.linspace(0.0, 1.0, n)
    return np.unique(np.concatenate([np.sin(0.5 * np.pi * t) ** 2, [1.0e-4, 1.0e-3, 0.01]]))[1:]  # > 0


def half_vectors(n=257, seed=1):
    """h over the hemisphere: polar angles from the pole (log-spaced) to the horizon, random azimuth."""
    rng = np.random.default_rng(seed)
    theta = np.concatenate([[0.0], np.geomspace(1e-6, np.pi / 2 - 1e-3, n - 1)])
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=-1)


# --- numpy references ------------------------------------------------------------------------------


def tan2_of(h):
    h = f32(h)
    return (h[..., 0] ** 2 + h[..., 1] ** 2) / h[..., 2] ** 2


def ref_D_ggx(h, alpha):
    """Walter et al. 2007, Eq. 33: alpha^2 / (pi cos^4 (alpha^2 + tan^2)^2)."""
    c = f32(h)[..., 2]
    a2 = f32(alpha) ** 2
    return a2 / (np.pi * c**4 * (a2 + tan2_of(h)) ** 2)


def ref_D_beckmann(h, alpha):
    """Walter et al. 2007, Eq. 25: exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4)."""
    c = f32(h)[..., 2]
    a2 = f32(alpha) ** 2
    return np.exp(-tan2_of(h) / a2) / (np.pi * a2 * c**4)


def ref_Lambda_ggx(c, alpha):
    """Heitz 2014, Eq. 72: (-1 + sqrt(1 + alpha^2 tan^2)) / 2."""
    c = f32(c)
    tan2 = (1.0 - c * c) / (c * c)
    return 0.5 * (-1.0 + np.sqrt(1.0 + f32(alpha) ** 2 * tan2))


def ref_Lambda_beckmann(c, alpha):
    """Heitz 2014, Eq. 69, a = 1 / (alpha tan): (erf(a) - 1)/2 + exp(-a^2) / (2 a sqrt(pi)), scipy's erf."""
    c = f32(c)
    tan = np.sqrt(1.0 - c * c) / c
    with np.errstate(divide="ignore"):
        a = 1.0 / (f32(alpha) * tan)
        lam = 0.5 * (erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * np.sqrt(np.pi))
    return np.where(np.isfinite(a), lam, 0.0)


def ref_D_blinn_phong(h, alpha):
    """Normalized Blinn-Phong (s + 2)/(2 pi) cos^s, s = 2/alpha^2 - 2 (Walter et al. 2007, Eq. 30 and Sec. 5.2);
    cos^s as (cos^2)^(s/2) with cos^2 = 1 / (1 + tan^2)."""
    a2 = f32(alpha) ** 2
    s = 2.0 / a2 - 2.0
    return (s + 2.0) / (2.0 * np.pi) * (1.0 + tan2_of(h)) ** (-s / 2.0)


REF_D = {"ggx": ref_D_ggx, "beckmann": ref_D_beckmann, "blinn_phong": ref_D_blinn_phong}
REF_LAMBDA = {"ggx": ref_Lambda_ggx, "beckmann": ref_Lambda_beckmann}


def ref_G2_smith_joint_approx(nov, nol, alpha):
    """UE4 Vis_SmithJointApprox (Karis 2014 notes; Hammon 2017) times 4 (n.l)(n.v):
    Vis = 0.5 / (n.l (n.v (1 - a) + a) + n.v (n.l (1 - a) + a))."""
    a = f32(alpha)
    vis = 0.5 / (nol * (nov * (1.0 - a) + a) + nov * (nol * (1.0 - a) + a))
    return 4.0 * nol * nov * vis


def ref_G2_schlick_ggx_ibl(nov, nol, alpha):
    """Godot integrate_dfg.glsl geometry_smith: Schlick G1 = n.x / (n.x (1 - k) + k), k = alpha / 2, product."""
    k = f32(alpha) / 2.0
    return nov / (nov * (1.0 - k) + k) * nol / (nol * (1.0 - k) + k)


def ref_G2(ndf, masking, nov, nol, noh, voh, alpha):
    if masking == "schlick_ggx_ibl":
        return ref_G2_schlick_ggx_ibl(nov, nol, alpha)
    if masking == "v_cavity":
        return ref_G2_v_cavity(noh, nov, nol, voh, voh)
    if masking == "smith_joint_approx":
        return ref_G2_smith_joint_approx(nov, nol, alpha)
    lv, ll = REF_LAMBDA[ndf](nov, alpha), REF_LAMBDA[ndf](nol, alpha)
    if masking == "smith_height_correlated":
        return 1.0 / (1.0 + lv + ll)
    if masking == "smith_separable":
        return 1.0 / (1.0 + lv) / (1.0 + ll)
    assert masking == "v_cavity"
    return ref_G2_v_cavity(noh, nov, nol, voh, voh)


def ref_G2_v_cavity(noh, nov, nol, voh, loh):
    """Cook & Torrance 1982: min(1, 2 (n.h)(n.v)/(v.h), 2 (n.h)(n.l)/(l.h))."""
    noh, nov, nol, voh, loh = (f32(x) for x in (noh, nov, nol, voh, loh))
    return np.minimum(1.0, np.minimum(2.0 * noh * nov / voh, 2.0 * noh * nol / loh))


def ref_F_dielectric(eta, cos_i):
    """Textbook Fresnel equations for light from index 1 onto index eta >= 1, Snell's law for the
    transmitted angle: r_s = (cos_i - eta cos_t)/(cos_i + eta cos_t), r_p = (eta cos_i - cos_t)/(eta cos_i + cos_t),
    F = (r_s^2 + r_p^2)/2. cos_t^2 = 1 - sin_t^2 = 1 - (1 - cos_i^2)/eta^2 is evaluated as (eta^2 - 1 + cos_i^2)/eta^2
    (no cancellation at grazing). At cos_i = 0 the limit 1 (for eta = 1, 0/0: the terms' convention, 1)."""
    eta, cos_i = np.broadcast_arrays(f32(eta), f32(cos_i))
    cos_t = np.sqrt(eta**2 - 1.0 + cos_i**2) / eta
    with np.errstate(invalid="ignore"):
        rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
        rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    return np.where(cos_i > 0.0, 0.5 * (rs**2 + rp**2), 1.0)


# --- NDFs ------------------------------------------------------------------------------------------------


def test_D_ggx_matches_numpy():
    h, alpha = half_vectors()[:, None, :], ALPHAS[None, :]
    got = evaluate_terms(h=h, alpha=alpha)["D_ggx"].astype(np.float64)
    np.testing.assert_allclose(got, ref_D_ggx(h, alpha), rtol=D_RTOL, atol=0.0)


def test_D_beckmann_matches_numpy():
    h, alpha = half_vectors()[:, None, :], ALPHAS[None, :]
    got = evaluate_terms(h=h, alpha=alpha)["D_beckmann"].astype(np.float64)
    want = ref_D_beckmann(h, alpha)
    # exp(-x) with x = tan^2/alpha^2 rounded in float32: relative error ~ x * eps (x <= ~104 before underflow)
    rtol = D_RTOL + D_BECKMANN_RTOL_PER_EXPONENT * np.minimum(tan2_of(h) / f32(alpha) ** 2, 110.0)
    err = np.abs(got - want)
    ok = err <= rtol * want + D_BECKMANN_ATOL
    assert np.all(ok), f"max relative error {np.max(err[~ok] / want[~ok]):.3e}"


def test_D_blinn_phong_matches_numpy():
    """Relative error ~ eps times the exponent x = (s/2) log(1 + tan^2), as for Beckmann's exp(-x)."""
    h, alpha = half_vectors()[:, None, :], ALPHAS[None, :]
    got = evaluate_terms(h=h, alpha=alpha)["D_blinn_phong"].astype(np.float64)
    want = ref_D_blinn_phong(h, alpha)
    x = (1.0 / f32(alpha) ** 2 - 1.0) * np.log1p(tan2_of(h))
    rtol = D_RTOL + D_BECKMANN_RTOL_PER_EXPONENT * np.minimum(x, 110.0)
    err = np.abs(got - want)
    ok = err <= rtol * want + D_BECKMANN_ATOL
    assert np.all(ok), f"max relative error {np.max(err[~ok] / want[~ok]):.3e}"


def test_blinn_phong_is_close_to_beckmann_at_small_alpha():
    """s = 2/alpha^2 - 2 is the mapping under which (n.h)^s ~ exp(-tan^2/alpha^2) (Walter et al. 2007, Sec. 5.2)."""
    theta = np.linspace(0.0, 2.0 * 0.05, 50)  # within 2 alpha of the pole: cos^4 and tan^4 alpha^-2 terms ~2% each
    h = np.stack([np.sin(theta), 0 * theta, np.cos(theta)], axis=-1)
    t = evaluate_terms(h=h, alpha=0.05)
    np.testing.assert_allclose(t["D_blinn_phong"], t["D_beckmann"], rtol=0.05)


@pytest.mark.parametrize("ndf", ["ggx", "beckmann", "blinn_phong"])
def test_D_is_zero_for_back_facing_normals(ndf):
    h = np.array([[0.0, 0.0, -1.0], [0.6, 0.0, -0.8], [1.0, 0.0, 0.0]])
    got = evaluate_terms(h=h, alpha=0.5)[f"D_{ndf}"]
    assert np.all(got[:2] == 0.0)
    assert np.all(np.isfinite(got))


@pytest.mark.parametrize("ndf", ["ggx", "beckmann", "blinn_phong"])
def test_D_peak_value_is_one_over_pi_alpha2(ndf):
    got = evaluate_terms(h=(0.0, 0.0, 1.0), alpha=ALPHAS)[f"D_{ndf}"]
    np.testing.assert_allclose(got, 1.0 / (np.pi * f32(ALPHAS) ** 2), rtol=D_RTOL)


# --- masking-shadowing ---------------------------------------------------------------------------------------


def test_Lambda_ggx_matches_numpy():
    c = hemisphere_cosines()[:, None]
    got = evaluate_terms(nov=c, alpha=ALPHAS[None, :])["Lambda_ggx"].astype(np.float64)
    np.testing.assert_allclose(got, ref_Lambda_ggx(c, ALPHAS[None, :]), rtol=LAMBDA_RTOL, atol=LAMBDA_ATOL)


def test_Lambda_beckmann_matches_scipy_erf():
    c = hemisphere_cosines()[:, None]
    got = evaluate_terms(nov=c, alpha=ALPHAS[None, :])["Lambda_beckmann"].astype(np.float64)
    np.testing.assert_allclose(got, ref_Lambda_beckmann(c, ALPHAS[None, :]), rtol=LAMBDA_RTOL, atol=LAMBDA_ATOL)


@pytest.mark.parametrize("ndf", ["ggx", "beckmann"])
def test_Lambda_grazing_asymptote_is_alpha_over_2_cos(ndf):
    """As n.v -> 0, Lambda_ggx -> alpha / (2 n.v) and Lambda_beckmann -> alpha / (2 sqrt(pi) n.v) (leading terms;
    both minus 1/2)."""
    c = np.array([1e-5, 3e-5, 1e-4])
    alpha = 0.5
    got = evaluate_terms(nov=c, alpha=alpha)[f"Lambda_{ndf}"].astype(np.float64)
    want = alpha / (2.0 * c) if ndf == "ggx" else alpha / (2.0 * c * np.sqrt(np.pi))
    np.testing.assert_allclose(got, want, rtol=2e-3)


@pytest.mark.parametrize("ndf", ["ggx", "beckmann"])
def test_G1_smith_matches_numpy(ndf):
    c = hemisphere_cosines()[:, None]
    got = evaluate_terms(nov=c, alpha=ALPHAS[None, :])[f"G1_smith_{ndf}"].astype(np.float64)
    np.testing.assert_allclose(got, 1.0 / (1.0 + REF_LAMBDA[ndf](c, ALPHAS[None, :])), rtol=G_RTOL, atol=G_ATOL)


@pytest.mark.parametrize("ndf,masking", [p for p in BRDF_PAIRS if p[1] != "v_cavity"])
def test_G2_smith_matches_numpy(ndf, masking):
    c = hemisphere_cosines(24)
    nov, nol, alpha = np.meshgrid(c, c, ALPHAS, indexing="ij")
    got = evaluate_terms(nov=nov, nol=nol, alpha=alpha)[f"G2[{ndf},{masking}]"].astype(np.float64)
    want = ref_G2(ndf, masking, nov, nol, None, None, alpha)
    np.testing.assert_allclose(got, want, rtol=G_RTOL, atol=G_ATOL)


def random_pairs(n, seed, min_cos=1e-3):
    """Unit l, v in the upper hemisphere and their half vector, in float64."""
    rng = np.random.default_rng(seed)

    def dirs():
        c = rng.uniform(min_cos, 1.0, n)
        phi = rng.uniform(0.0, 2.0 * np.pi, n)
        s = np.sqrt(1.0 - c * c)
        return np.stack([s * np.cos(phi), s * np.sin(phi), c], axis=-1)

    l, v = dirs(), dirs()
    h = (l + v) / np.linalg.norm(l + v, axis=-1, keepdims=True)
    return l, v, h


def test_G2_v_cavity_matches_numpy():
    l, v, h = random_pairs(2000, seed=2)
    noh, nov, nol = h[:, 2], v[:, 2], l[:, 2]
    voh, loh = np.sum(v * h, axis=-1), np.sum(l * h, axis=-1)
    got = evaluate_terms(h=h, nov=nov, nol=nol, voh=voh, loh=loh)["G2_v_cavity"].astype(np.float64)
    np.testing.assert_allclose(got, ref_G2_v_cavity(noh, nov, nol, voh, loh), rtol=G_RTOL, atol=G_ATOL)
    # the composed G2 of the table kernels passes v.h for l.h (equal for a half vector)
    got2 = evaluate_terms(h=h, nov=nov, nol=nol, voh=voh, alpha=0.3)["G2[ggx,v_cavity]"].astype(np.float64)
    np.testing.assert_allclose(got2, ref_G2_v_cavity(noh, nov, nol, voh, voh), rtol=G_RTOL, atol=G_ATOL)


def test_G2_v_cavity_is_zero_for_back_facing_microfacet():
    got = evaluate_terms(h=(0.0, 0.0, 1.0), nov=0.5, nol=0.5, voh=[-0.5, 0.0, 0.5], loh=[0.5, 0.5, -0.5])["G2_v_cavity"]
    np.testing.assert_array_equal(got, [0.0, 0.0, 0.0])


@pytest.mark.parametrize("ndf", ["ggx", "beckmann"])
def test_masking_vanishes_for_back_facing_and_grazing_directions(ndf):
    c = np.array([-0.5, 0.0, 1e-8, COS_EPS])
    t = evaluate_terms(nov=c, nol=0.7, alpha=0.5)
    assert np.all(t[f"Lambda_{ndf}"] >= 1e29)
    np.testing.assert_allclose(t[f"G1_smith_{ndf}"], 0.0, atol=1e-29)
    for m in ("smith_height_correlated", "smith_separable"):
        np.testing.assert_allclose(t[f"G2[{ndf},{m}]"], 0.0, atol=1e-29)


# --- Fresnel -----------------------------------------------------------------------------------------------------

COSINES = np.concatenate([[0.0, 1e-8, 1e-4], np.linspace(0.0, 1.0, 101)[1:]])


def test_F_schlick_matches_numpy():
    f0, c = F0S[:, None], COSINES[None, :]
    got = evaluate_terms(f0=f0, cos_theta=c)["F_schlick"].astype(np.float64)
    np.testing.assert_allclose(got, f32(f0) + (1.0 - f32(f0)) * (1.0 - f32(c)) ** 5, rtol=0.0, atol=F_ATOL)


def test_Fc_schlick_matches_numpy_and_clamps():
    c = np.concatenate([COSINES, [-0.5, 1.5]])
    got = evaluate_terms(cos_theta=c)["Fc_schlick"].astype(np.float64)
    np.testing.assert_allclose(got, np.clip(1.0 - f32(c), 0.0, 1.0) ** 5, rtol=0.0, atol=F_ATOL)


def test_F_dielectric_matches_snell_fresnel():
    eta, c = ETAS[:, None], COSINES[None, :]
    got = evaluate_terms(eta=eta, cos_theta=c)["F_dielectric"].astype(np.float64)
    np.testing.assert_allclose(got, ref_F_dielectric(eta, c), rtol=0.0, atol=F_ATOL)


def test_F_dielectric_landmarks():
    """Normal incidence ((eta-1)/(eta+1))^2 (glass 1.5 -> 0.04); grazing 1; Brewster's angle r_p = 0."""
    t = evaluate_terms(eta=[1.5, 1.5, 1.33], cos_theta=[1.0, 0.0, 1.0])["F_dielectric"]
    np.testing.assert_allclose(t, [0.04, 1.0, (0.33 / 2.33) ** 2], rtol=1e-6)
    eta = 1.5
    cos_b = np.cos(np.arctan(eta))
    cos_t = np.sqrt(1.0 - (1.0 - cos_b**2) / eta**2)
    rs = (cos_b - eta * cos_t) / (cos_b + eta * cos_t)
    got = evaluate_terms(eta=eta, cos_theta=cos_b)["F_dielectric"]
    np.testing.assert_allclose(got, 0.5 * rs**2, rtol=1e-5)


def test_F_dielectric_f0_matches_snell_fresnel():
    """Gotanda 2014, Eq. 2 against the textbook Fresnel with eta = (1 + sqrt f0)/(1 - sqrt f0), f0 > 0
    (f0 = 0 below)."""
    f0, c = F0S[F0S > 0.0, None], COSINES[None, :]
    got = evaluate_terms(f0=f0, cos_theta=c)["F_dielectric_f0"].astype(np.float64)
    s = np.sqrt(f32(f0))
    np.testing.assert_allclose(got, ref_F_dielectric((1.0 + s) / (1.0 - s), c), rtol=0.0, atol=F_ATOL)
    np.testing.assert_allclose(got[:, -1], f32(f0[:, 0]), rtol=1e-5, atol=F_ATOL)  # c = 1: f0


def test_F_dielectric_f0_of_zero_is_zero_above_grazing():
    """f0 = 0 is eta = 1, an index-matched interface: no reflection for any c > 0."""
    got = evaluate_terms(f0=0.0, cos_theta=COSINES[COSINES > 0.0])["F_dielectric_f0"]
    np.testing.assert_allclose(got, 0.0, atol=F_ATOL)


def test_F_dielectric_f0_of_one_is_one():
    got = evaluate_terms(f0=1.0, cos_theta=COSINES)["F_dielectric_f0"]
    np.testing.assert_allclose(got, 1.0, atol=F_ATOL)


# --- the assembled BRDF -----------------------------------------------------------------------------------------


@pytest.mark.parametrize("ndf,masking", BRDF_PAIRS)
def test_specular_brdf_matches_numpy(ndf, masking):
    """f = D G2 F_schlick / (4 (n.l)(n.v)) (Gotanda 2014, Eq. 1) from the numpy references."""
    l, v, h = random_pairs(2000, seed=3, min_cos=0.05)
    rng = np.random.default_rng(4)
    alpha = rng.uniform(0.2, 1.0, len(l)) ** 2
    f0 = rng.uniform(0.0, 1.0, len(l))
    l, v = f32(l), f32(v)
    h = (l + v) / np.linalg.norm(l + v, axis=-1, keepdims=True)
    voh = np.sum(v * h, axis=-1)
    nov, nol = v[:, 2], l[:, 2]
    F = f32(f0) + (1.0 - f32(f0)) * (1.0 - voh) ** 5
    want = REF_D[ndf](h, alpha) * ref_G2(ndf, masking, nov, nol, h[:, 2], voh, alpha) * F / (4.0 * nol * nov)
    got = evaluate_brdfs(l, v, alpha, f0)[(ndf, masking)].astype(np.float64)
    np.testing.assert_allclose(got, want, rtol=BRDF_RTOL, atol=BRDF_ATOL)


# --- edge sweeps: no NaN, no Inf, values in range ---------------------------------------------------------------

EDGE_H = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 1e-8], [0.6, 0.0, 0.8]])
EDGE_COS = np.array([0.0, 1e-8, 1.0])


def edge_sweep(alphas):
    grids = np.meshgrid(
        np.arange(len(EDGE_H)),
        np.asarray(alphas),
        EDGE_COS,
        EDGE_COS,
        EDGE_COS,
        EDGE_COS,
        np.array([0.0, 1.0]),
        np.array([1.0, 1.5]),
        EDGE_COS,
        indexing="ij",
    )
    hi, alpha, nov, nol, voh, loh, f0, eta, c = (g.ravel() for g in grids)
    h = EDGE_H[hi]
    return h, evaluate_terms(h=h, alpha=alpha, nov=nov, nol=nol, voh=voh, loh=loh, f0=f0, eta=eta, cos_theta=c)


def test_terms_are_finite_on_edge_sweep():
    """n.v, n.l, v.h, l.h, cos in {0, 1e-8, 1}, alpha in {ALPHA_MIN, 1}, f0 in {0, 1}, h at pole/horizon/below."""
    h, t = edge_sweep([ALPHA_MIN, 1.0])
    assert set(t) == set(TERM_NAMES)
    for name, x in t.items():
        assert np.all(np.isfinite(x)), name
    # G in [0, 1] and F in [0, 1]; G2_v_cavity only for n.h >= 0, its domain (D = 0 below the horizon):
    # it is min(1, 2 (n.h)(n.v)/(v.h), ...) and goes negative for a back-facing microfacet normal
    upper = h[:, 2] >= 0.0
    for name in TERM_NAMES:
        if name.startswith(("G", "F")):
            x = t[name][upper] if "v_cavity" in name else t[name]
            assert np.all((x >= 0.0) & (x <= 1.0 + 1e-6)), name
        else:
            assert np.all(t[name] >= 0.0), name


def test_terms_other_than_D_are_finite_at_alpha_zero():
    """alpha = 0 is outside D's domain (a Dirac delta; edge.ALPHA_MIN clamps every axis), but masking and
    Fresnel stay finite there: Lambda = 0 for a smooth surface."""
    _, t = edge_sweep([0.0])
    for name, x in t.items():
        if not name.startswith("D_"):
            assert np.all(np.isfinite(x)), name
    np.testing.assert_array_equal(t["Lambda_ggx"][t["Lambda_ggx"] < 1e29], 0.0)
    np.testing.assert_array_equal(t["Lambda_beckmann"][t["Lambda_beckmann"] < 1e29], 0.0)


@pytest.mark.parametrize("ndf,masking", BRDF_PAIRS)
def test_specular_brdf_is_finite_on_edge_sweep(ndf, masking):
    d = np.array(
        [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 1e-8],
            [-1.0, 0.0, 1e-8],
            [0.0, 0.0, -1.0],
            [0.6, 0.0, 0.8],
            [-0.6, 0.0, 0.8],
        ]
    )
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    li, vi, ai, fi = np.meshgrid(np.arange(len(d)), np.arange(len(d)), np.arange(2), np.arange(2), indexing="ij")
    f = evaluate_brdfs(
        d[li.ravel()], d[vi.ravel()], np.array([ALPHA_MIN, 1.0])[ai.ravel()], np.array([0.0, 1.0])[fi.ravel()]
    )[(ndf, masking)]
    assert np.all(np.isfinite(f)) and np.all(f >= 0.0)


def test_G2_v_cavity_is_zero_below_the_surface():
    """A microfacet normal with n.h < 0 neither masks nor shadows: G = 0, never negative."""
    got = evaluate_terms(h=(0.6, 0.0, -0.8), nov=0.5, nol=0.5, voh=0.5, loh=0.5)["G2_v_cavity"]
    np.testing.assert_array_equal(got, 0.0)


# --------------------------------------------------------------- the scaled Bessel I0 and the AS frame mean


def test_bessel_i0e_matches_scipy():
    import warp as wp
    from scipy.special import i0e

    from lutbake.terms.ndf import bessel_i0e

    @wp.kernel
    def run(x: wp.array(dtype=wp.float64), out: wp.array(dtype=wp.float64)):
        i = wp.tid()
        out[i] = bessel_i0e(x[i])

    x = np.concatenate([[0.0, 7.999999, 8.0, 8.000001], np.logspace(-8, 9, 400), -np.logspace(-3, 3, 20)])
    out = wp.zeros(len(x), dtype=wp.float64, device="cpu")
    wp.launch(run, dim=len(x), inputs=[wp.array(x, dtype=wp.float64, device="cpu"), out], device="cpu")
    np.testing.assert_allclose(out.numpy(), i0e(x), rtol=1e-14)


def test_ashikhmin_shirley_frame_mean_is_the_numpy_mean_over_orientations():
    """averaged_weight_ashikhmin_shirley (closed form, I0) against the mean of the lobe's p_h (n.l) / max(n.l, n.v) over
    4096 frame orientations beta in [0, pi), in float64 numpy (Ashikhmin & Shirley 2000's p_h written out)."""
    import warp as wp

    from lutbake.integrands.anisotropic import averaged_weight_ashikhmin_shirley

    @wp.kernel
    def run(h: wp.array(dtype=wp.vec3), l: wp.array(dtype=wp.vec3), v: wp.vec3, amin: float, amax: float, out: Any):
        i = wp.tid()
        out[i] = averaged_weight_ashikhmin_shirley(v, h[i], l[i], wp.dot(v, h[i]), amin, amax)

    rng = np.random.default_rng(7)
    theta = rng.uniform(0.0, 0.6, 64)
    psi = rng.uniform(0.0, 2 * np.pi, 64)
    h = np.stack([np.sin(theta) * np.cos(psi), np.sin(theta) * np.sin(psi), np.cos(theta)], 1).astype(np.float32)
    nov = 0.7
    v = np.array([np.sqrt(1 - nov**2), 0.0, nov], np.float32)
    l = (2 * (h @ v)[:, None] * h - v).astype(np.float32)  # reflect(v, h), as the kernel sees it
    beta = (np.arange(4096) + 0.5) * np.pi / 4096
    for amin, amax in [(0.05, 0.05), (0.05, 0.4), (0.01, 1.0), (0.2, 0.6)]:
        out = wp.zeros(len(h), dtype=wp.vec2, device="cpu")
        inputs = [wp.array(h, dtype=wp.vec3, device="cpu"), wp.array(l, dtype=wp.vec3, device="cpu"), wp.vec3(*v)]
        inputs += [amin, amax, out]
        wp.launch(run, dim=len(h), inputs=inputs, device="cpu")
        nu, nv = (max(2.0 / float(np.float32(a)) ** 2 - 2.0, 0.0) for a in (amax, amin))
        hd = h.astype(np.float64)
        ht = hd[:, :1] * np.cos(beta) + hd[:, 1:2] * np.sin(beta)  # h along the frame's T at each beta
        hb = hd[:, 1:2] * np.cos(beta) - hd[:, :1] * np.sin(beta)
        x = hd[:, 0] ** 2 + hd[:, 1] ** 2
        # log(n.h) of the unit vector through the float32 h's tangential part, as the kernel (ndf.log_cos64): the
        # float32 h is unit only to ~6e-8, which log(h.z) would carry, times exponents of ~1e3, into the lobe
        ph = np.exp((nu * ht**2 + nv * hb**2) * (0.5 * np.log1p(-x) / x)[:, None]).mean(axis=1)
        ph *= np.sqrt((nu + 1) * (nv + 1)) / (2 * np.pi)
        lz = l[:, 2].astype(np.float64)
        want = ph * lz / np.maximum(lz, float(v[2]))
        got = out.numpy()
        np.testing.assert_allclose(got[:, 0], want, rtol=1e-6, atol=1e-12 * want.max())  # float32 scale, l
        assert np.array_equal(got[:, 0], got[:, 1])  # exact: no azimuth-rule estimate
