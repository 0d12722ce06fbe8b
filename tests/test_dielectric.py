"""The rough dielectric BSDF (Walter et al. 2007) and its energy tables (kinds dielectric / dielectric_avg):
terms against numpy, tables against the independent integral over the outgoing sphere (tests/dielectric_reference.py),
the analytic limits, reciprocity, the second estimator, and the engine layouts' grids."""

import functools

import dielectric_reference as ref
import numpy as np
import pytest

from lutbake.config import validate_table
from lutbake.edge import ALPHA_MIN, NOV_MIN
from lutbake.integrands.dielectric import integrate
from lutbake.kinds import dielectric as kd
from lutbake.kinds import lookup_kind
from lutbake.layouts import lookup_layout
from lutbake.layouts.base import ior_values
from lutbake.sampling.dielectric_avg import mu_starts
from lutbake.sampling.dielectric_layout import GLASS_SAMPLES, kernel_tolerance
from lutbake.validate import dielectric as vd

REFERENCE_ATOL = 1.0e-6  # |table - numpy reference| per channel, every texel below
QMC_ATOL = 5.0e-5  # |GL - sobol_vndf 2^16|
SMOOTH_ATOL = vd.SMOOTH_LIMIT_TOL
TERM_RTOL = 2.0e-5  # Warp float32 f_r / f_t vs numpy float64, well-conditioned pairs

# (NoV, alpha, eta): random texels and edges (grazing, TIR-dominated, at the critical angle, high roughness,
# small alpha)
RANDOM = [
    tuple(x)
    for x in np.column_stack(
        [
            np.random.default_rng(15).uniform(0.1, 1.0, 2),
            np.random.default_rng(16).uniform(0.05, 0.8, 2),
            np.random.default_rng(17).uniform(0.5, 2.2, 2),
        ]
    )
]
EDGES = [
    (0.02, 0.2, 0.67),
    (float(np.sqrt(1 - 0.75**2)), 0.1, 0.75),
    (0.05, 1.0, 1.5),
    (0.9, 0.03, 1.33),
    (0.999, 0.5, 2.5),
]


def spec(**kw):
    return validate_table({"name": "t", **kw}, "<test>", 0)


def f32(*xs):
    return (np.asarray(x, np.float32) for x in xs)


@functools.cache
def ref_energies(nov: float, alpha: float, eta: float) -> tuple:
    """The reference (E_R, E_T) of a texel, computed once per texel (the honesty test below asks for these too)."""
    return ref.energies(nov, alpha, eta)


@pytest.mark.parametrize("texel", RANDOM + EDGES)
def test_energies_match_numpy_integral_over_the_outgoing_sphere(texel):
    nov, alpha, eta = f32(*texel)
    e = integrate(
        ("ggx", "smith_separable", "exact", "gauss_legendre"),
        *(np.atleast_1d(x) for x in (nov, alpha, eta)),
        GLASS_SAMPLES["gauss_legendre"],
        0,
    )[0]
    er, et = ref_energies(float(nov), float(alpha), float(eta))
    np.testing.assert_allclose(e, [er, et, er + et], rtol=0, atol=REFERENCE_ATOL)


@pytest.mark.parametrize(
    "ndf,masking,texel",
    [("ggx", "smith_height_correlated", (0.4, 0.3, 0.8)), ("beckmann", "smith_separable", (0.6, 0.2, 1.5))],
)
def test_other_terms_match_numpy_integral(ndf, masking, texel):
    nov, alpha, eta = (np.atleast_1d(x) for x in f32(*texel))
    e = integrate((ndf, masking, "exact", "gauss_legendre"), nov, alpha, eta, GLASS_SAMPLES["gauss_legendre"], 0)[0]
    er, et = ref.energies(float(nov[0]), float(alpha[0]), float(eta[0]), ndf, masking)
    np.testing.assert_allclose(e[:2], [er, et], rtol=0, atol=REFERENCE_ATOL)


@pytest.mark.parametrize("texel", [(0.5, 0.3, 1.5), (0.3, 0.2, 0.75)])
def test_eevee_channels_match_numpy_integral(texel):
    """EEVEE's Schlick split-sum channels (scale, bias, transmission factor) against the reference's own weights."""
    nov, alpha, eta = (np.atleast_1d(x) for x in f32(*texel))
    e = integrate(
        ("ggx", "smith_separable", "eevee", "gauss_legendre"), nov, alpha, eta, GLASS_SAMPLES["gauss_legendre"], 0
    )[0]
    np.testing.assert_allclose(
        e, ref.energies(float(nov[0]), float(alpha[0]), float(eta[0]), fresnel="eevee"), rtol=0, atol=REFERENCE_ATOL
    )


def test_bsdf_terms_match_numpy():
    """f_r and f_t of the Warp terms (validate.dielectric.evaluate_bsdf) against the reference's numpy BSDF."""
    rng = np.random.default_rng(3)
    n = 512
    i, o = vd.random_directions(rng, n), vd.random_directions(rng, n, upper=bool(0))
    o[: n // 2] *= np.array([1.0, 1.0, -1.0])  # half reflection pairs
    alpha, eta = rng.uniform(0.05, 1.0, n), rng.choice(np.array(vd.ETAS), n)
    got = vd.evaluate_bsdf(i, o, alpha, eta)
    want = np.array([sum(ref.bsdf(i[k], o[k], alpha[k], eta[k])) for k in range(n)])
    ok = vd._well_conditioned(i, o, eta) & (want > 1e-6 * want.max())
    np.testing.assert_allclose(got[ok], want[ok], rtol=TERM_RTOL, atol=0)
    assert ok.sum() > n // 2


def test_smooth_limit_is_fresnel_including_total_internal_reflection():
    worst, where = vd.smooth_limit()
    assert worst <= SMOOTH_ATOL, where
    # the TIR branch explicitly: inside glass (eta = 1/1.5), views past the critical angle reflect everything
    mu = np.array([0.1, 0.3, 0.6], np.float32)  # cos theta_c = 0.745
    e = integrate(
        ("ggx", "smith_separable", "exact", "gauss_legendre"),
        mu,
        *f32([ALPHA_MIN] * 3, [1 / 1.5] * 3),
        GLASS_SAMPLES["gauss_legendre"],
        0,
    )
    np.testing.assert_allclose(e[:, :2], np.tile([1.0, 0.0], (3, 1)), rtol=0, atol=SMOOTH_ATOL)
    # alpha = 0 (lutbake.edge): the closed-form mirror limit, both estimators, exactly F and 1 - F
    mu = np.array([0.1, 0.5, 0.9, 0.5], np.float32)
    eta = np.array([1.5, 1.5, 1 / 1.5, 1 / 1.5], np.float32)
    F = vd.fresnel_np(eta, mu)
    for est in ("gauss_legendre", "sobol_vndf"):
        e = integrate(("ggx", "smith_separable", "exact", est), mu, np.zeros(4, np.float32), eta)
        want_t = np.where(mu < np.sqrt(np.maximum(1 - eta**2.0, 0.0)), 0.0, 1 - F)
        np.testing.assert_allclose(e, np.stack([F, want_t, F + want_t], 1), rtol=0, atol=1e-6, err_msg=est)


def test_index_matched_interface_has_no_reflection_and_the_smith_transmittance():
    """eta = 1: E_R = 0, E_T = G2(mu, mu)/G1(mu) (-> 1 as alpha -> 0), continuous from both sides. Below 1 the TIR
    cone v.h < sqrt(1 - eta^2) opens like sqrt(1 - eta): E(1 - 1e-3) is 8e-3 off at mu = 0.2, E(1 - 1e-6)
    within 4e-4."""
    r = vd.dielectric_index_matched()
    assert r.passed, str(r)
    mu, alpha = f32([0.2, 0.5, 0.9], [0.3, 0.3, 0.3])
    at = {}
    for eta in (1.0 - 1e-6, 1.0, 1.0 + 1e-6):
        at[eta] = integrate(
            ("ggx", "smith_separable", "exact", "gauss_legendre"),
            mu,
            alpha,
            *f32([eta] * 3),
            GLASS_SAMPLES["gauss_legendre"],
            0,
        )
    np.testing.assert_allclose(at[1.0 - 1e-6][:, 2], at[1.0][:, 2], atol=1e-3)
    np.testing.assert_allclose(at[1.0 + 1e-6][:, 2], at[1.0][:, 2], atol=1e-3)
    smooth = integrate(
        ("ggx", "smith_separable", "exact", "gauss_legendre"),
        mu,
        *f32([ALPHA_MIN] * 3, [1.0] * 3),
        GLASS_SAMPLES["gauss_legendre"],
        0,
    )
    np.testing.assert_allclose(smooth[:, 1], 1.0, atol=1e-6)


def test_reciprocity_of_f_r_and_generalised_reciprocity_of_f_t():
    for m in ("smith_separable", "smith_height_correlated"):
        r, t, _ = vd.reciprocity_errors(m)
        assert r <= vd.RECIPROCITY_RTOL and t <= vd.RECIPROCITY_RTOL, (m, r, t)


def test_energy_is_at_most_one_and_loss_is_largest_at_high_roughness_and_grazing():
    """E_R + E_T <= 1; for every eta the largest loss is at alpha = 1, and at the most grazing views for eta >= 0.67.
    Measured exception: inside a dense medium (eta = 0.5) grazing views are totally reflected with little loss, and the
    largest loss is at normal view (0.676 at mu = 1, alpha = 1). The loss is not monotone in alpha everywhere (at
    mu = 0.05, eta = 2.5 it dips by 0.006 from alpha = 0.05 to 0.2)."""
    M, A, E = vd.energy_grid()
    e = vd._integrate(M, A, E)
    s = e[:, 0] + e[:, 1]
    assert s.max() <= 1.0 + vd.ENERGY_TOL
    mus, alphas = np.unique(M), np.unique(A)
    loss = (1.0 - s).reshape(len(mus), len(alphas), len(vd.ETAS))
    for k, eta in enumerate(vd.ETAS):
        i, j = np.unravel_index(np.argmax(loss[:, :, k]), loss.shape[:2])
        assert alphas[j] == alphas.max(), eta
        assert mus[i] <= 0.05 or eta < 0.67, eta


def test_estimators_agree():
    r = vd.dielectric_estimators_agree()
    assert r.measured <= QMC_ATOL, str(r)


def test_eevee_grids_follow_the_generator():
    """eevee_lut_comp.glsl main(): coordinate = gid / (extent - 1); btdf x: f0 = clamp(x^2), ior = (1 + f0)/(1 - f0);
    bsdf x: ior = clamp(sqrt(x)); y centred on the critical angle; z = roughness, alpha = z^2."""
    axes, nov, alpha, eta, _ = kd.texel_grid(spec(kind="dielectric", layout="eevee_btdf").options)
    assert [a.count for a in axes] == [16, 64, 64]
    x = np.arange(64) / 63
    np.testing.assert_allclose(eta[:64], (1 + np.clip(x * x, 1e-4, 0.9999)) / (1 - np.clip(x * x, 1e-4, 0.9999)))
    np.testing.assert_allclose(np.sqrt((eta[1:63] - 1) / (eta[1:63] + 1)), x[1:63], rtol=1e-12)
    np.testing.assert_allclose(nov[::64][:64], np.clip(1 - x * x, 1e-4, 0.9999))
    np.testing.assert_allclose(alpha[:: 64 * 64], (np.arange(16) / 15) ** 2, rtol=1e-6)  # 0: the mirror limit
    axes, nov, alpha, eta, _ = kd.texel_grid(spec(kind="dielectric", layout="eevee_bsdf").options)
    eta2, nov2 = eta[: 64 * 64].reshape(64, 64), nov[: 64 * 64].reshape(64, 64)
    np.testing.assert_allclose(eta2[0], np.clip(np.sqrt(x), 1e-4, 0.9999))
    c = np.sqrt(1 - eta2**2)
    y = ((nov2 - c) / np.where(nov2 > c, 1 - c, c)) * 0.5 + 0.5  # EEVEE's lookup (bsdf_lut) inverts the generator
    inside = (nov2 > 1e-4) & (nov2 < 0.9999)
    np.testing.assert_allclose(y[inside], np.broadcast_to(x[:, None], (64, 64))[inside], atol=1e-12)


def test_openpbr_grid_and_layout():
    axes, nov, alpha, eta, _ = kd.texel_grid(spec(kind="dielectric", layout="openpbr").options)
    assert [a.name for a in axes] == ["ior", "perceptual_roughness", "NoV"] and [a.count for a in axes] == [32] * 3
    e = eta[:: 32 * 32]
    i = np.arange(32)
    # openpbr_ior_to_exact_index inverted
    idx = np.where(e < 1, 15 - 15 * (1 / e - 1) / 1.5, 16 + 15 * (e - 1) / 1.5)
    np.testing.assert_allclose(idx[:15], i[:15], atol=1e-9)
    np.testing.assert_allclose(idx[16:], i[16:], atol=1e-9)
    assert e[15] == e[16] == 1.0
    np.testing.assert_allclose(np.sqrt(alpha[: 32 * 32 : 32]), i / 31, rtol=1e-6)
    np.testing.assert_allclose(nov[:32], np.maximum(i / 31, NOV_MIN), rtol=1e-6)


OPENPBR_ATOL = 3.0e-3  # its Monte Carlo noise (measured max 2.1e-3 over cos > 0, eta != 1) + UNORM16


def test_openpbr_tables_match_shipped_arrays_within_their_monte_carlo_noise():
    """A strided subset of the 32^3 tables against adobe/openpbr-bsdf's arrays (tests/data, UNORM16 / 65535)."""
    shipped = np.load("tests/data/openpbr_energy_tables.npz")
    plan = lookup_kind("dielectric").plan(spec(kind="dielectric", layout="openpbr"))
    rows = [(z, y) for z in (2, 9, 20, 28) for y in (3, 12, 24, 31)]
    for z, y in rows:
        start = (z * 32 + y) * 32
        got = plan.run_tile(start + 1, start + 32, "cpu")  # cos > 0 (cos = 0 is clamped to NOV_MIN here)
        for c, name in enumerate(["ideal_dielectric_energy_complement", "opaque_dielectric_energy_complement"]):
            np.testing.assert_allclose(got[:, c], shipped[name][z, y, 1:] / 65535.0, rtol=0, atol=OPENPBR_ATOL)
        np.testing.assert_allclose(
            got[:, 2], shipped["ideal_metal_energy_complement"][y, 1:] / 65535.0, rtol=0, atol=OPENPBR_ATOL
        )


UNORM16_STEP = 1.0 / 65535.0
# x(1/eta) predicted from x(eta) through lutbake's averages: the shipped averages' Monte Carlo noise (max 4.2e-4)
# divided by E_c,avg(1/eta) >= 0.03 at alpha index >= 16 (measured max 7.0e-4)
OPENPBR_RATIO_ATOL = 2.0e-3


OPENPBR_PAIRS_K = (1, 5, 10, 15)  # IOR rows 15 - k (eta < 1) and 16 + k (eta > 1) = 1 / each other
RATIO_A0 = 16  # alpha index >= 16


@functools.lru_cache(maxsize=1)
def openpbr_avg_rows() -> dict:
    """{IOR row z: (16, 4) dielectric_avg openpbr channels at alpha index >= RATIO_A0} for the rows of OPENPBR_PAIRS_K
    (each tile computes its mirror row's averages itself: the ratio channel needs them)."""
    plan = lookup_kind("dielectric_avg").plan(spec(kind="dielectric_avg", layout="openpbr"))
    zs = [z for k in OPENPBR_PAIRS_K for z in (15 - k, 16 + k)]
    return {z: plan.run_tile(z * 32 + RATIO_A0, z * 32 + 32, "cpu") for z in zs}


def test_openpbr_reflection_ratio_is_tied_to_the_averages_by_the_lobes_reciprocity():
    """OpenPBR's multiple-scattering lobe (impl/openpbr_microfacet_multiple_scattering_lobes.h) transmits
    (1 - x(eta)) E_c(eta, mu_i) E_c(1/eta, mu_o) / (pi E_c,avg(1/eta)) from side i and (1 - x(1/eta)) E_c(1/eta, mu_o)
    E_c(eta, mu_i) / (pi E_c,avg(eta)) back: it is symmetric iff (1 - x(eta)) E_c,avg(eta) = (1 - x(1/eta))
    E_c,avg(1/eta). The shipped ratio obeys that to UNORM16 precision, so its eta < 1 half follows from its eta > 1
    half and the averages (lutbake's included); the closed form fixing the other half is tested below."""
    shipped = np.load("tests/data/openpbr_energy_tables.npz")
    x = shipped["ideal_dielectric_reflection_ratio"] / 65535.0
    ec_shipped = shipped["ideal_dielectric_avg_energy_complement"] / 65535.0
    k = np.arange(1, 16)
    inside, outside = 15 - k, 16 + k  # eta_in = 1 / eta_out: OpenPBR's IOR axis is symmetric about 15.5
    residual = (1 - x[outside]) * ec_shipped[outside] - (1 - x[inside]) * ec_shipped[inside]
    np.testing.assert_allclose(residual, 0.0, rtol=0, atol=UNORM16_STEP)
    rows = openpbr_avg_rows()  # alpha index >= 16 (alpha >= 0.27): E_c,avg >= 0.03, the division is well conditioned
    for k in OPENPBR_PAIRS_K:
        ec_out, ec_in = rows[16 + k][:, 0], rows[15 - k][:, 0]
        predicted = 1 - (1 - x[16 + k, RATIO_A0:]) * ec_out / ec_in
        np.testing.assert_allclose(predicted, x[15 - k, RATIO_A0:], rtol=0, atol=OPENPBR_RATIO_ATOL)


# lutbake's ratio channel vs the shipped one at alpha index >= 16: the shipped averages' Monte Carlo noise (max 4.2e-4)
# divided by E_c,avg (measured max 6.9e-4 over every eta != 1 row)
RATIO_BAKED_ATOL = 1.0e-3
OPENPBR_ETA_ONE_ROWS = (15, 16)  # both eta = 1: the shipped rows are degenerate there (docs/glass-layouts.md)


def kulla_conty_ratio(ec, ec_mirror, eta):
    """The reflection ratio transcribed independently (scalar, explicit branches) from docs/glass-layouts.md."""

    def f_avg(e):  # Kulla & Conty 2017, slide 18 (OpenPBR's openpbr_average_fresnel)
        return (e - 1) / (4.08567 + 1.00071 * e) if e > 1 else 0.997118 + 0.1014 * e - 0.965241 * e**2 - 0.130607 * e**3

    f, fm = f_avg(eta), f_avg(1 / eta)
    if (1 - f) * ec <= (1 - fm) * ec_mirror:  # this side transmits less under an F_avg split: it splits first
        return f * ec / (f * ec + (1 - fm) * ec_mirror)
    xm = fm * ec_mirror / (fm * ec_mirror + (1 - f) * ec)
    return 1 - (1 - xm) * ec_mirror / ec  # reciprocity: (1 - x) E_c,avg equal on both sides


def test_openpbr_reflection_ratio_closed_form_reproduces_the_shipped_array():
    """Fed OpenPBR's own (shipped) averages, the Kulla-Conty split reproduces OpenPBR_IdealDielectricReflectionRatio
    to its UNORM16 rounding at every texel of every eta != 1 row (alpha > 0), in the module and in an independent
    scalar transcription."""
    from lutbake.integrands.dielectric_ratio import reflection_ratio

    shipped = np.load("tests/data/openpbr_energy_tables.npz")
    x = shipped["ideal_dielectric_reflection_ratio"] / 65535.0
    ec = shipped["ideal_dielectric_avg_energy_complement"] / 65535.0
    etas = ior_values(32, 0.4, 2.5, "endpoint", "symmetric")
    rows = [z for z in range(32) if z not in OPENPBR_ETA_ONE_ROWS]
    got = reflection_ratio(ec[rows], ec[[31 - z for z in rows]], etas[rows, None])
    scalar = np.array([[kulla_conty_ratio(ec[z, a], ec[31 - z, a], etas[z]) for a in range(8, 32)] for z in rows])
    np.testing.assert_allclose(got[:, 8:], scalar, rtol=0, atol=1e-12)
    # both arrays are UNORM16-rounded (half a step each): the ratio's worst-case rounding error, propagated through the
    # closed form, bounds the difference at every texel with E_c,avg > 0 (measured: at most 0.94 of the bound)
    h = 0.5 * UNORM16_STEP
    e, em, eta = ec[rows], ec[[31 - z for z in rows]], etas[rows, None]
    bound = (
        h
        + np.abs(reflection_ratio(e + h, em, eta) - reflection_ratio(e - h, em, eta)) / 2
        + np.abs(reflection_ratio(e, em + h, eta) - reflection_ratio(e, em - h, eta)) / 2
    )
    assert np.all(np.abs(got - x[rows])[:, 1:] <= bound[:, 1:])  # alpha index 0: E_c,avg = 0, never read by OpenPBR


def test_openpbr_reflection_ratio_channel_matches_the_shipped_array_and_any_tiling():
    """The dielectric_avg openpbr layout's 4th channel at the IOR rows of OPENPBR_PAIRS_K (eta = 1/1.1 ... 1/2.5 and
    1.1 ... 2.5), alpha index >= 16, against the shipped array; a tile's texels do not depend on the tile (each tile
    computes its mirror row itself)."""
    shipped = np.load("tests/data/openpbr_energy_tables.npz")
    x = shipped["ideal_dielectric_reflection_ratio"] / 65535.0
    plan = lookup_kind("dielectric_avg").plan(spec(kind="dielectric_avg", layout="openpbr"))
    assert list(plan.channels)[3] == "ideal_dielectric_reflection_ratio" and plan.n_channels == 4
    rows = openpbr_avg_rows()
    for z, got in rows.items():
        np.testing.assert_allclose(got[:, 3], x[z, RATIO_A0:], rtol=0, atol=RATIO_BAKED_ATOL)
    z = 16 + OPENPBR_PAIRS_K[1]
    np.testing.assert_array_equal(plan.run_tile(z * 32 + 24, z * 32 + 32, "cpu"), rows[z][24 - RATIO_A0 :])


def test_bake_energy_kind_and_average_consistency():
    from lutbake.api import bake_table

    t, _, _ = bake_table(spec(kind="dielectric", size=[6, 4], ior_size=3, ior_range=[0.7, 1.6]))
    assert t.data.shape == (3, 4, 6, 3) and list(t.channels) == ["e_r", "e_t", "e_sum"]
    np.testing.assert_allclose(t.data[..., 2], t.data[..., 0] + t.data[..., 1], atol=1e-6)
    a, _, _ = bake_table(
        spec(kind="dielectric_avg", roughness_size=3, ior_size=2, ior_range=[0.7, 1.6], mu_order=12),
    )
    assert a.data.shape == (2, 3, 3) and np.all(np.isfinite(a.data))  # IOR rows (0.925, 1.375) x roughness columns
    # E_avg of a smooth interface is the Fresnel average: 1 - F_avg transmitted, outside and inside (TIR) alike
    s, _, _ = bake_table(
        spec(
            kind="dielectric_avg",
            roughness="alpha",
            roughness_size=1,
            roughness_range=[0, 0],
            ior_size=2,
            ior_range=[1 / 1.5, 1.5],
            texel="endpoint",
        )
    )
    mu, w = np.polynomial.legendre.leggauss(400)
    for k, eta in enumerate([1 / 1.5, 1.5]):
        edges = np.unique([0, 0.2, np.sqrt(max(1 - eta * eta, 0)), 1])
        f_avg = sum(
            np.sum((b - a_) / 2 * w * 2 * m * vd.fresnel_np(eta, m))
            for a_, b in zip(edges[:-1], edges[1:])
            for m in [a_ + (b - a_) * (mu + 1) / 2]
        )
        np.testing.assert_allclose(s.data[k, 0, :2], [f_avg, 1 - f_avg], atol=5e-5)


def test_bad_configs_name_the_key():
    with pytest.raises(Exception, match="ior_mapping"):
        spec(kind="dielectric", ior_mapping="symmetric", ior_size=5, ior_range=[0.5, 2.0])
    with pytest.raises(Exception, match="layout"):
        spec(kind="dielectric", layout="openpbr", masking="smith_height_correlated")
    with pytest.raises(Exception, match="masking"):
        spec(kind="dielectric", masking="v_cavity")


def test_openpbr_header_writes_its_arrays_as_unorm16(tmp_path):
    import re

    from lutbake.io.formats import write_table
    from lutbake.table import Table

    rng = np.random.default_rng(5)
    channels = kd.CHANNELS["openpbr"]
    data = rng.uniform(0, 1, (32, 32, 32, 3)).astype(np.float32)
    path = write_table(Table("opbr", "dielectric", data, [], channels, ""), tmp_path, "openpbr_h")
    text = path.read_text()
    for name, want in [
        ("IdealDielectricEnergyComplement", data[..., 0]),
        ("OpaqueDielectricEnergyComplement", data[..., 1]),
        ("IdealMetalEnergyComplement", data[16, ..., 2]),
    ]:
        body = re.search(rf"OpenPBR_{name}_Array\[(\d+)\] = {{[^\n]*\n(.*?)}};", text, re.S)
        codes = np.array([int(x) for x in re.findall(r"\d+", body.group(2))])
        assert int(body.group(1)) == want.size == codes.size
        np.testing.assert_array_equal(codes, np.rint(want.ravel().astype(np.float64) * 65535))
    avg = rng.uniform(0, 1, (32, 32, 4)).astype(np.float32)
    text = write_table(
        Table("opbr_avg", "dielectric_avg", avg, [], kd.AVG_CHANNELS["openpbr"], ""), tmp_path, "openpbr_h"
    )
    arrays = dict(re.findall(r"OpenPBR_(\w+)_Array\[(\d+)\]", text.read_text()))
    assert arrays == {
        "IdealDielectricAverageEnergyComplement": "1024",
        "OpaqueDielectricAverageEnergyComplement": "1024",
        "IdealMetalAverageEnergyComplement": "32",
        "IdealDielectricReflectionRatio": "1024",  # the seventh array
    }
    body = re.search(r"OpenPBR_IdealDielectricReflectionRatio_Array\[1024\] = {[^\n]*\n(.*?)};", text.read_text(), re.S)
    codes = np.array([int(x) for x in re.findall(r"\d+", body.group(1))])
    np.testing.assert_array_equal(codes, np.rint(avg[..., 3].ravel().astype(np.float64) * 65535))
    with pytest.raises(Exception, match="format"):
        spec(kind="dielectric", format="openpbr_h")


# the adaptive quadrature (kind dielectric's default, lutbake.sampling.dielectric.DielectricAdaptive): every per-texel
# error estimate bounds the error against (a) the same kernel at a fixed high order and (b) the numpy integral over the
# outgoing sphere, on texels where quadratures struggle: grazing n.v, small alpha, eta near 1, eta < 1 near the
# critical angle, eta > 1, random
HONESTY_TEXELS = (
    EDGES
    + RANDOM
    + [
        (0.002, 0.3, 1.5),  # grazing
        (0.7, 0.002, 1.33),  # small alpha
        (0.5, 0.04, 0.49),  # stagnating convergence (orders 8 and 12 agree, both off by 6e-7)
        (0.6, 0.25, 1.02),  # eta near 1 (above)
        (0.8, 0.4, 0.98),  # eta near 1 (below)
        (float(np.sqrt(1 - 0.6**2)) + 0.01, 0.05, 0.6),  # just outside the critical angle
        (float(np.sqrt(1 - 0.6**2)) - 0.01, 0.05, 0.6),  # just inside (total internal reflection)
        (0.3, 0.6, 2.5),
        (1.0e-4, 0.07111, 1.0629),  # EEVEE's clamped grazing row (not honest from orders (6, 12), see below)
        (0.24, 0.042, 0.49),  # orders 8 and 12 agree there, both off by ~6e-7 (lutbake.sampling.dielectric)
        (0.172, 0.041, 0.435),  # orders 6 and 11 of one panel agree to 9.6e-8, both 1.5e-6 off (the same)
        (0.5599, 0.2844, 0.4714),  # K_11 and G_5 agree, K_11 1.35e-6 off (the same)
    ]
)
# EEVEE btdf's grazing row with only its transmission channel driving the ladder (kinds.dielectric.kernel_tolerance)
EEVEE_GRAZING = [(1.0e-4, a, e) for a in (0.0044, 0.07111, 0.16, 0.36, 1.0) for e in (1.0629, 1.25, 1.7563, 2.1438)]
HONESTY_TOLERANCES = (1.0e-5, 1.0e-6, 1.0e-7)
HIGH_ORDER = 64  # the converged reference (a): orders 48, 64 and 96 agree to ~5e-9 on such texels
NUMPY_TOLERANCES = (1.0e-5, 1.0e-6)  # (b): the numpy integral is good to ~1e-7, too coarse for 1e-7
NUMPY_ACCURACY = 1.0e-7  # its own error, allowed on top of the estimate (measured: |numpy - order 96| <= 8.2e-8)
TERMS_FLOOR = 1.0e-7  # the estimate's float32 rounding part, relative (hemisphere_kernels.TERMS_ROUNDING)


@functools.lru_cache(maxsize=None)
def adaptive_at(tol: float):
    from lutbake.integrands.dielectric import dielectric_integrand
    from lutbake.sampling.dielectric import DielectricAdaptive

    nov, alpha, eta = (np.asarray(c, np.float32) for c in zip(*HONESTY_TEXELS))
    integrand = dielectric_integrand("ggx", "smith_separable", "exact")
    inputs = {"nov": nov, "alpha": integrand.alpha_input(alpha), "param": eta}
    return DielectricAdaptive((tol,) * 3, (0.0,) * 3).evaluate_with_error(integrand, inputs, "cpu")


def honesty_ratio(err: np.ndarray, est: np.ndarray) -> float:
    return float(np.max(err / est))


@pytest.mark.parametrize("tol", HONESTY_TOLERANCES)
def test_adaptive_estimate_bounds_the_error_against_a_high_order(tol):
    nov, alpha, eta = (np.asarray(c, np.float32) for c in zip(*HONESTY_TEXELS))
    high = integrate(("ggx", "smith_separable", "exact", "gauss_legendre"), nov, alpha, eta, 3 * HIGH_ORDER**2)
    values, est = adaptive_at(tol)
    np.testing.assert_array_less(np.abs(values - high), est)  # every estimate bounds its error
    np.testing.assert_array_less(est, tol + TERMS_FLOOR * np.abs(values))  # and reached the tolerance (+ the floor)
    print(f"tol {tol:.0e}: worst error / estimate {honesty_ratio(np.abs(values - high), est):.3f}")


@functools.lru_cache(maxsize=None)
def numpy_energies():
    """At the float32 texels the kernel integrates (adaptive_at). The float64 ones moved the integral by up to 3.9e-7:
    |value - numpy| took 0.91 of the NUMPY_ACCURACY allowance on top of the estimate at tolerance 1e-6; at these every
    |value - numpy| is within its estimate alone."""
    return np.array([ref_energies(*(float(np.float32(x)) for x in t)) for t in HONESTY_TEXELS])


@pytest.mark.parametrize("tol", NUMPY_TOLERANCES)
def test_adaptive_estimate_bounds_the_error_against_the_numpy_integral(tol):
    er_et = numpy_energies()
    want = np.column_stack([er_et, er_et.sum(axis=1)])
    values, est = adaptive_at(tol)
    np.testing.assert_array_less(np.abs(values - want), est + NUMPY_ACCURACY)
    print(f"tol {tol:.0e}: worst error / estimate vs numpy {honesty_ratio(np.abs(values - want), est):.3f}")


def test_adaptive_estimate_of_eevee_btdf_grazing_row_bounds_the_error():
    from lutbake.integrands.dielectric import dielectric_integrand
    from lutbake.sampling.dielectric import DielectricAdaptive
    from lutbake.tolerance import Tolerance

    nov, alpha, eta = (np.asarray(c, np.float32) for c in zip(*EEVEE_GRAZING))
    integrand = dielectric_integrand("ggx", "smith_separable", "eevee", 1)
    inputs = {"nov": nov, "alpha": integrand.alpha_input(alpha), "param": eta}
    tol = 1.0e-6
    values, est = DielectricAdaptive(
        *kernel_tolerance(lookup_layout("dielectric", "eevee_btdf"), Tolerance(tol, 0.0))
    ).evaluate_with_error(integrand, inputs, "cpu")
    high = integrate(("ggx", "smith_separable", "eevee", "gauss_legendre"), nov, alpha, eta, 3 * HIGH_ORDER**2)
    err = np.abs(values[:, 2] - high[:, 2])
    np.testing.assert_array_less(err, est[:, 2])
    np.testing.assert_array_less(est[:, 2], tol + TERMS_FLOOR * np.abs(values[:, 2]))
    print(f"eevee_btdf grazing: worst error / estimate {honesty_ratio(err, est[:, 2]):.3f}")


def test_adaptive_first_pair_is_the_merged_fixed_rules():
    """With a tolerance no texel misses, every panel stops at the ladder's first pair (orders 8 and 16): the value is
    the fixed-order rule of order 16 on the same merged panels (DielectricGaussLegendre with merged = True, one
    accumulator instead of a sum per panel: equal to rounding), and the estimate is the sum over panels of
    |Q_16 - Q_8| plus the terms' floor, so at least |I_16 - I_8| of the whole texel."""
    from lutbake.integrands.dielectric import dielectric_integrand
    from lutbake.sampling import dielectric as sd

    assert sd.DIELECTRIC_ORDERS[:2] == (8, 16)
    nov, alpha, eta = (np.asarray(c, np.float32) for c in zip(*HONESTY_TEXELS))
    integrand = dielectric_integrand("ggx", "smith_separable", "exact")
    inputs = {"nov": nov, "alpha": integrand.alpha_input(alpha), "param": eta}
    values, est = sd.DielectricAdaptive((1.0,) * 3, (0.0,) * 3).evaluate_with_error(integrand, inputs, "cpu")
    q8, q16 = (sd.DielectricGaussLegendre(3 * n * n, merged=True).evaluate(integrand, inputs, "cpu") for n in (8, 16))
    np.testing.assert_allclose(values, q16, rtol=0, atol=1e-14)
    quadrature = est - TERMS_FLOOR * np.abs(values)
    assert np.all(quadrature >= np.abs(q16 - q8) * (1.0 - 1e-9))  # (rounding of est - floor |v|)
    # the merge drops some texel's NDF-peak breakpoints (a fixed-order table keeps them all)
    assert np.any(q16 != integrate(("ggx", "smith_separable", "exact", "gauss_legendre"), nov, alpha, eta, 3 * 16**2))


@pytest.mark.parametrize(
    "texel",
    [
        (0.9999, 0.017778, 1.0e-4),  # EEVEE bsdf's clamped eta column: a transmitting cone 5e-9 wide in v.h
        (0.9999, 0.017778, 0.003),
        (0.99241, 0.0044444, 0.126),  # the view at the critical angle, smallest roughness
        (1.0e-4, 0.017778, 1.0002),  # EEVEE btdf's grazing row, clamped eta column
    ],
)
def test_small_eta_and_critical_angle_match_numpy(texel):
    """v.h and the refraction in float64 (lutbake.integrands.dielectric g64): float32's v.h, amplified by 1/eta^2
    next to total internal reflection, and v's float32 components (unit to ~1e-8) left these 1e-6 to 4e-5 off."""
    nov, alpha, eta = (np.atleast_1d(x) for x in f32(*texel))
    e = integrate(("ggx", "smith_separable", "eevee", "gauss_legendre"), nov, alpha, eta, 3 * HIGH_ORDER**2)[0]
    want = ref.energies(float(nov[0]), float(alpha[0]), float(eta[0]), fresnel="eevee")
    np.testing.assert_allclose(e, want, rtol=0, atol=NUMPY_ACCURACY)  # measured: within 5.9e-8 (float32 D, G)


def test_avg_mu_starts_grade_towards_the_critical_angle():
    """Inside the glass the first mu panels end at 0, 0.2, eta, cos theta_c, 1 and at cos theta_c +- alpha 4^k below
    0.25 (the ~alpha-wide total-internal-reflection transition); outside it, or at the mirror limit, no grading."""
    eta, alpha = 0.6, 0.01
    c = np.sqrt(1 - eta * eta)
    graded = [c + s * alpha * 4.0**k for k in range(3) for s in (-1, 1)]  # 0.01, 0.04, 0.16
    np.testing.assert_allclose(mu_starts(eta, alpha), np.sort([0.0, 0.2, eta, c, 1.0, *graded]), rtol=1e-12)
    np.testing.assert_allclose(mu_starts(eta, 0.0), [0.0, 0.2, eta, c, 1.0], rtol=1e-12)
    np.testing.assert_array_equal(mu_starts(1.5, alpha), [0.0, 0.2, 1.0])


def _mu_rule(panels: int = 10, order: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights on [0, 1]: ``panels`` uniform panels of Gauss-Legendre order ``order``."""
    x, w = np.polynomial.legendre.leggauss(order)
    return ((np.arange(panels)[:, None] + (x + 1) / 2) / panels).ravel(), np.tile(w / (2 * panels), panels)


# the mu references of the dielectric_avg tests below: on their six texels (alpha 0.047 .. 0.71, eta 0.51 and 0.72)
# 2 ∫ E mu dmu by this rule is within 2.4e-9 of 8000 nodes (320 uniform panels of order 24, further edges at E(mu)'s
# kinks mu = eta, cos theta_c +- alpha 2^k and at 1e-4 .. 3e-2 near 0) at the kernel's inner orders 12, 20 and 28
# alike (the float32 E's noise); 5 panels were up to 9.4e-8 off
MU_RULE = _mu_rule()


def test_avg_mu_rule_reaches_the_tolerance():
    """kind dielectric_avg's mu rule bisects each texel's worst panel until the Gauss-Kronrod pair (7, 15) agrees
    within a quarter of the tolerance: inside the glass at small roughness E(mu) crosses the total-internal-reflection
    transition (~alpha wide at cos theta_c) and E_T has further non-analytic points (mu = eta among them), where the
    fixed 16 nodes per panel of before were off by up to 2.0e-4 (OpenPBR's average). Against uniform panels at
    order 24 (same inner rule), every texel is within its recorded mu estimate plus the inner rule's noise between
    node sets (2e-7), and the estimate within its share of the tolerance; against the same panels with the inner rule
    at order 20 (independent of the table's order-12 inner rule), every texel is within the table's recorded
    lutbake:error_estimate (the inner probe plus the largest mu estimate)."""
    from lutbake.api import bake_table

    small = dict(
        kind="dielectric_avg", roughness_size=3, roughness_range=[0.06, 1.0], ior_size=2, ior_range=[0.4, 0.83]
    )
    table, _, _ = bake_table(spec(**small, samples=432))
    plan = lookup_kind("dielectric_avg").plan(spec(**small, samples=432))
    full = plan.run_tile(0, plan.n_texels, "cpu")
    values, mu_err = full[:, :3], full[:, 3:]
    np.testing.assert_array_equal(values.astype(np.float32), table.data.reshape(-1, 3))
    s = spec(**small)
    _, alpha, eta = kd.avg_grid(s.options, s.records["layout"].obj)
    mu, wt = MU_RULE
    key = ("ggx", "smith_separable", "exact_metal", "gauss_legendre")  # the kind's defaults
    for k in range(len(alpha)):
        e = integrate(key, mu, np.full(len(mu), alpha[k]), np.full(len(mu), eta[k]), samples=432)
        ref = 2 * (wt * mu) @ e
        err = np.abs(values[k, :2] - ref[:2])
        assert np.all(err <= mu_err[k, :2] + 2e-7), (k, alpha[k], eta[k], err, mu_err[k])
        e = integrate(key, mu, np.full(len(mu), alpha[k]), np.full(len(mu), eta[k]), samples=1200)
        ref = 2 * (wt * mu) @ e
        err = np.abs(values[k] - [ref[0], ref[1], ref[0] + ref[1]])  # layout energy: E_R, E_T, E_R + E_T
        assert np.all(err <= float(table.attributes["error_estimate"])), (k, alpha[k], eta[k], err)
    # float32's tolerance 1e-6: a quarter per channel for the mu rule, half for B = E_R + E_T
    assert mu_err[:, :2].max() <= 0.25e-6 and mu_err[:, 2].max() <= 0.5e-6
    # the inner probe reuses the first pass's E where this process computed it, else computes it: the same bits
    fresh = lookup_kind("dielectric_avg").plan(spec(**small, samples=432))
    assert fresh.error_estimate(full.ravel(), "cpu") == plan.error_estimate(full.ravel(), "cpu")
    assert float(table.attributes["error_estimate"]) == float(f"{plan.error_estimate(full.ravel(), 'cpu')[0]:.3e}")


def test_avg_inner_order_climbs_to_a_tight_tolerance():
    """Without ``samples``, kind dielectric_avg's inner rule climbs 12, 16, ... until its probe share is within half
    of the target: at tolerance 1e-7 order 12 leaves ~3e-7 (above it, as the fixed order 12 of before recorded), so
    the table takes order 16 (its probe against order 20) and records an estimate within the tolerance; against
    uniform mu panels at inner order 28 (independent of both), every value is within that estimate."""
    from lutbake.api import bake_table

    small = dict(
        kind="dielectric_avg", roughness_size=3, roughness_range=[0.06, 1.0], ior_size=2, ior_range=[0.4, 0.83]
    )
    table, _, _ = bake_table(spec(**small, tolerance=1.0e-7))
    estimate = float(table.attributes["error_estimate"])
    assert estimate <= 1.0e-7
    assert "|order 16 - order 20|" in table.attributes["error_estimate_method"]
    values = table.data.reshape(-1, 3).astype(np.float64)
    s = spec(**small)
    _, alpha, eta = kd.avg_grid(s.options, s.records["layout"].obj)
    mu, wt = MU_RULE
    key = ("ggx", "smith_separable", "exact_metal", "gauss_legendre")
    for k in range(0, len(alpha), 2):  # three of the six texels, both etas
        e = integrate(key, mu, np.full(len(mu), alpha[k]), np.full(len(mu), eta[k]), samples=3 * 28**2)
        ref = 2 * (wt * mu) @ e
        err = np.abs(values[k] - [ref[0], ref[1], ref[0] + ref[1]])
        # float32 storage rounds a value ~0.5 by up to 3e-8 on top of the estimate
        assert np.all(err <= estimate + 3.0e-8), (k, alpha[k], eta[k], err, estimate)


# texels with equal (n.v, alpha) and several eta >= 1 (one row over MEMBERS: two groups), with eta < 1, alpha = 0
# and a lone texel beside them (neither grouped)
SHARED_ROWS = [(0.37, 0.2), (1.0e-4, 0.07111), (0.9, 0.0044)]
SHARED_ETAS = [1.0, 1.0629, 1.33, 1.5, 2.5, 0.7]
SHARED_TEXELS = (
    [(n, a, e) for n, a in SHARED_ROWS for e in SHARED_ETAS]
    + [(0.61, 0.3, 1.0 + 0.05 * k) for k in range(18)]
    + [(0.5, 0.0, 1.5), (0.5, 0.0, 1.7), (0.8, 0.45, 1.2)]
)


def test_member_groups_hold_texels_that_differ_only_in_eta_at_least_one():
    from lutbake.sampling import dielectric as sd

    texel = np.array(SHARED_TEXELS, np.float32)
    groups, singles = sd.member_groups(texel)
    members = groups[groups >= 0]
    assert sorted(np.concatenate([members, singles]).tolist()) == list(range(len(texel)))  # each texel once
    assert groups.shape == (5, sd.MEMBERS)  # 3 rows of 5, the 18-row as 16 + 2
    for row in groups:
        m = texel[row[row >= 0]]
        assert len(m) >= 2 and np.all(m[:, 2] >= 1.0) and np.all(m[:, 1] > 0.0)
        assert np.all(m[:, :2] == m[0, :2])
    assert {tuple(texel[i]) for i in singles} == {tuple(np.float32(x) for x in t) for t in SHARED_TEXELS[-3:]} | {
        tuple(np.float32(x) for x in (n, a, 0.7)) for n, a in SHARED_ROWS
    }


def test_shared_pass_gives_each_texel_its_own_bits(monkeypatch):
    """A group's pass evaluates every node once for all its members (the eta-free part of the integrand once): each
    member's value and estimate are those of the texel alone, to the bit, in the adaptive and the fixed kernel."""
    from lutbake.integrands.dielectric import dielectric_integrand
    from lutbake.sampling import dielectric as sd

    nov, alpha, eta = (np.asarray(c, np.float32) for c in zip(*SHARED_TEXELS))
    integrand = dielectric_integrand("ggx", "smith_separable", "exact")
    inputs = {"nov": nov, "alpha": integrand.alpha_input(alpha), "param": eta}
    adaptive, fixed = sd.DielectricAdaptive((1e-7,) * 3, (0.0,) * 3), sd.DielectricGaussLegendre(3 * 12**2, merged=True)
    grouped = [*adaptive.evaluate_with_error(integrand, inputs, "cpu"), fixed.evaluate(integrand, inputs, "cpu")]
    monkeypatch.setattr(sd, "member_groups", lambda t: (np.zeros((0, sd.MEMBERS), np.int32), np.arange(len(t))))
    alone = [*adaptive.evaluate_with_error(integrand, inputs, "cpu"), fixed.evaluate(integrand, inputs, "cpu")]
    for a, b in zip(grouped, alone):
        np.testing.assert_array_equal(a, b)


def test_sibling_tiles_bake_the_ior_slices_together_and_any_tiling_alike():
    """A tile within one IOR slice (Turquin's and OpenPBR's layout: IOR slowest) is evaluated with the same texels
    of every eta >= 1 slice (sibling_tiles), once per plan; every tiling gives the same bits."""
    from lutbake.sampling.dielectric import sibling_tiles

    s = spec(kind="dielectric", size=[4, 3], ior_size=6, ior_range=[0.7, 1.6], masking="smith_separable")
    slice_n, plan = 12, lookup_kind("dielectric").plan(s)
    eta = np.repeat([0.7, 0.9, 1.0, 1.2, 1.4, 1.6], slice_n)  # slices 2 .. 5 have eta >= 1
    nov = np.tile(np.linspace(0.1, 0.9, slice_n), 6)
    sib = sibling_tiles({"nov": nov, "alpha": np.full(len(eta), 0.1), "param": eta})
    assert sib(0, slice_n) is None  # eta < 1: nothing shared
    assert sib(0, 72) is None  # the tile's own texels form the groups
    np.testing.assert_array_equal(sib(3 * slice_n + 1, 3 * slice_n + 2), [25, 37, 49, 61])  # position 1, 4 slices
    whole = plan.run_tile(0, plan.n_texels, "cpu")
    for cut in (slice_n, 5):
        fresh = lookup_kind("dielectric").plan(s)  # a new memo
        tiles = [fresh.run_tile(a, min(a + cut, fresh.n_texels), "cpu") for a in range(0, fresh.n_texels, cut)]
        np.testing.assert_array_equal(np.concatenate(tiles), whole)
