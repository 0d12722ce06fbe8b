"""HDRP's Disney (Burley) and Fabric Lambert diffuse terms against numpy, and the Disney FGD channel of the
unity-hdrp layout against scipy's adaptive quadrature (an independent method)."""

import numpy as np
import pytest
import warp as wp
from hemisphere_reference import hemisphere_cubature
from scipy import integrate

from lutbake.integrands.engine_diffuse import HDRP_DIFFUSE_OFFSET, disney_fgd
from lutbake.terms.engine_diffuse import Fd_disney_hdrp, Fd_fabric_lambert_hdrp

TERM_RTOL = 1e-6  # float32 Warp term vs float64 numpy
FGD_ATOL = 2e-6  # GL 24 x 24 vs scipy dblquad (epsabs 1e-9), float32 inputs


def disney_numpy(nov, nol, lov, r):
    """Burley 2012 diffuse without 1/pi, as HDRP DisneyDiffuseNoPI (BSDF.hlsl), written out independently."""
    fd90 = 0.5 + 2.0 * r * (0.5 * (1.0 + lov))  # 2 (l.h)^2 = 1 + l.v
    return (1 + (fd90 - 1) * (1 - nol) ** 5) * (1 + (fd90 - 1) * (1 - nov) ** 5) / 1.03571


@wp.kernel
def eval_terms(
    nov: wp.array(dtype=float),
    nol: wp.array(dtype=float),
    lov: wp.array(dtype=float),
    r: wp.array(dtype=float),
    out: wp.array(dtype=float),
    fab: wp.array(dtype=float),
):
    i = wp.tid()
    out[i] = Fd_disney_hdrp(nov[i], nol[i], lov[i], r[i])
    fab[i] = Fd_fabric_lambert_hdrp(r[i] * r[i])


def test_disney_and_fabric_terms_match_numpy():
    rng = np.random.default_rng(5)
    n = 256
    nov, nol, r = rng.uniform(0.01, 1, n), rng.uniform(0.01, 1, n), rng.uniform(0, 1, n)
    phi = rng.uniform(0, np.pi, n)
    lov = np.sqrt(1 - nov**2) * np.sqrt(1 - nol**2) * np.cos(phi) + nov * nol
    arrs = [wp.array(a.astype(np.float32), dtype=float) for a in (nov, nol, lov, r)]
    out, fab = wp.zeros(n, dtype=float), wp.zeros(n, dtype=float)
    wp.launch(eval_terms, dim=n, inputs=arrs + [out, fab])
    np.testing.assert_allclose(out.numpy(), disney_numpy(nov, nol, lov, r), rtol=TERM_RTOL)
    np.testing.assert_allclose(fab.numpy(), 1.0 - 0.5 * r**2, rtol=TERM_RTOL)


def test_disney_back_facing_is_zero():
    arrs = [wp.array(np.array([x], np.float32), dtype=float) for x in (0.5, -0.2, 0.1, 0.5)]
    out, fab = wp.zeros(1, dtype=float), wp.zeros(1, dtype=float)
    wp.launch(eval_terms, dim=1, inputs=arrs + [out, fab])
    assert out.numpy()[0] == 0.0


@pytest.mark.parametrize("nov, r", [(1e-4, 0.0), (0.05, 0.3), (0.5, 0.5), (0.9, 1.0), (0.2, 0.9)])
def test_disney_fgd_equals_scipy_quadrature(nov, r):
    nov32, r32 = float(np.float32(nov)), float(np.float32(r))
    sv = np.sqrt(1 - nov32**2)

    def f(phi, mu):
        lov = sv * np.sqrt(1 - mu * mu) * np.cos(phi) + nov32 * mu
        return disney_numpy(nov32, mu, lov, r32) * mu

    ref = 2.0 / np.pi * integrate.dblquad(f, 0, 1, 0, np.pi, epsabs=1e-9)[0]
    got = disney_fgd(np.array([nov]), np.array([r]))[0]
    np.testing.assert_allclose(got, ref, atol=FGD_ATOL)


def test_disney_fgd_smooth_limit_is_the_product_of_two_schlick_averages():
    # r = 0: fd90 = 0.5 and l.v drops out, so the FGD factorises:
    # (1 - 0.5 (1 - NoV)^5) * 2 ∫ (1 - 0.5 (1 - mu)^5) mu dmu
    nov = 0.3
    inner = 2 * integrate.quad(lambda mu: (1 - 0.5 * (1 - mu) ** 5) * mu, 0, 1)[0]
    ref = (1 - 0.5 * (1 - nov) ** 5) * inner / 1.03571
    np.testing.assert_allclose(disney_fgd(np.array([nov]), np.array([0.0]))[0], ref, atol=FGD_ATOL)


def test_unity_hdrp_preset_layout_and_channel_b():
    import lutbake
    from lutbake.config import load_config, preset_path

    spec = load_config(preset_path("unity-hdrp"), [(None, "size", [8, 8])])[0]
    table, _, _ = lutbake.bake_table(spec)
    y_axis, x_axis = table.axes
    assert (x_axis.name, x_axis.mapping, x_axis.texel) == ("NoV", "square", "endpoint")
    np.testing.assert_allclose(x_axis.values()[1:], (np.arange(1, 8) / 7.0) ** 2, rtol=1e-6)
    nov = np.maximum(np.tile(x_axis.values(), 8), 1e-4)
    r = np.repeat(y_axis.values(), 8)
    np.testing.assert_allclose(table.data[..., 2].ravel(), disney_fgd(nov, r) - HDRP_DIFFUSE_OFFSET, atol=1e-6)
    assert np.all(table.data[..., 1] <= 1.0 + 1e-5) and np.all(table.data[..., 0] <= table.data[..., 1] + 1e-6)


# --- unity-hdrp-charlie: PreIntegratedFGD_CharlieFabricLambert -------------------------------------------------------
# converged Gauss-Legendre (lutbake) vs the graded cubature (tests/hemisphere_reference.py: a finer rule changes it by
# < 1e-14 on these texels, scipy dblquad at epsabs 1e-10 agrees to 3e-10) on the stored (/ 2 pi) scale
CHARLIE_ATOL = 2e-6
CHARLIE_TEXELS = [(2, 0), (2, 5), (4, 1), (5, 7), (7, 0), (7, 3)]  # (row = roughness, column = NoV) of an 8 x 8 bake


def charlie_l_hdrp(x, alpha):
    """HDRP core BSDF.hlsl CharlieL: the Estevez & Kulla 2017 fit, lerp in 1 - (1 - alpha)^2 (written as HDRP does)."""
    s = 1.0 - (1.0 - alpha) ** 2
    a, b, c = 25.3245 + (21.5473 - 25.3245) * s, 3.32435 + (3.82987 - 3.32435) * s, 0.16801 + (0.19823 - 0.16801) * s
    d, e = -1.27393 + (-1.97760 + 1.27393) * s, -4.85967 + (-4.32054 + 4.85967) * s
    return a / (1.0 + b * x**c) + d * x + e


def charlie_dv_numpy(nov, nol, noh, alpha):
    """HDRP D_Charlie(NdotH, alpha) * V_Charlie(NdotL, NdotV, alpha) (BSDF.hlsl), numpy (arrays)."""
    d = (2.0 + 1.0 / alpha) * (1.0 - noh * noh) ** (0.5 / alpha) / (2.0 * np.pi)

    def lam(c):
        return np.where(
            c < 0.5,
            np.exp(charlie_l_hdrp(c, alpha)),
            np.exp(2 * charlie_l_hdrp(0.5, alpha) - charlie_l_hdrp(1 - c, alpha)),
        )

    return d / ((1.0 + lam(nov) + lam(nol)) * 4.0 * nov * nol)


def charlie_fgd_reference(rule, nov, alpha, f0=None):
    """(x, y) = (∫ D V (1 - v.h)^5 (n.l) dω, ∫ D V (n.l) dω) over l in spherical coordinates (mu = n.l, phi), or,
    with ``f0``, ∫ D V F_schlick(f0, v.h) (n.l) dω. Symmetric in phi: 2 ∫_0^pi; graded toward the fit's branch."""

    def integral(weight):
        def dv(mu, noh, voh):
            return charlie_dv_numpy(nov, mu, noh, alpha) * mu * weight(voh)

        return hemisphere_cubature(dv, nov, rule, mu_singular=[0.5])

    if f0 is not None:
        return integral(lambda voh: f0 + (1.0 - f0) * (1.0 - voh) ** 5)
    return integral(lambda voh: (1.0 - voh) ** 5), integral(lambda voh: 1.0)


@pytest.fixture(scope="module")
def hdrp_charlie_table():
    import lutbake
    from lutbake.config import load_config, preset_path

    spec = load_config(preset_path("unity-hdrp-charlie"), [(None, "size", [8, 8])])[0]
    return lutbake.bake_table(spec)[0]


def test_unity_hdrp_charlie_axes_and_fabric_lambert_channel(hdrp_charlie_table):
    y_axis, x_axis = hdrp_charlie_table.axes
    centres = (np.arange(8) + 0.5) / 8  # HDRP Frag: NdotV = texCoord.x, r = texCoord.y at pixel centres
    assert (x_axis.name, x_axis.mapping, x_axis.texel) == ("NoV", "linear", "center")
    assert (y_axis.name, y_axis.texel) == ("perceptual_roughness", "center")
    np.testing.assert_allclose(x_axis.values(), centres, rtol=1e-6)
    np.testing.assert_allclose(y_axis.values(), centres, rtol=1e-6)
    fabric = np.broadcast_to((1.0 - 0.5 * centres**2)[:, None], (8, 8))  # FabricLambertNoPI(alpha = r^2)
    np.testing.assert_allclose(hdrp_charlie_table.data[..., 2], fabric, rtol=TERM_RTOL)


@pytest.mark.parametrize("row, col", CHARLIE_TEXELS)
def test_unity_hdrp_charlie_rg_equal_the_reference_over_2pi(hdrp_charlie_table, graded_rule, row, col):
    nov, r = (col + 0.5) / 8, (row + 0.5) / 8
    x, y = charlie_fgd_reference(graded_rule, nov, r * r)
    np.testing.assert_allclose(hdrp_charlie_table.data[row, col, :2], np.array([x, y]) / (2 * np.pi), atol=CHARLIE_ATOL)


@pytest.mark.parametrize("row, col, f0", [(3, 2, 0.04), (6, 6, 0.5), (7, 1, 1.0)])
def test_unity_hdrp_charlie_runtime_decode_reproduces_the_integral(hdrp_charlie_table, graded_rule, row, col, f0):
    # PreIntegratedFGD.hlsl GetPreIntegratedFGDCharlieAndFabricLambert: specularFGD = lerp(x, y, F0) * 2 pi
    nov, r = (col + 0.5) / 8, (row + 0.5) / 8
    t = hdrp_charlie_table.data[row, col]
    decoded = ((1.0 - f0) * t[0] + f0 * t[1]) * 2.0 * np.pi
    np.testing.assert_allclose(
        decoded, charlie_fgd_reference(graded_rule, nov, r * r, f0), atol=CHARLIE_ATOL * 2 * np.pi
    )
