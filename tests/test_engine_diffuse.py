"""HDRP's Disney (Burley) and Fabric Lambert diffuse terms against numpy, and the Disney FGD channel of the
unity-hdrp layout against scipy's adaptive quadrature (an independent method)."""

import numpy as np
import pytest
import warp as wp
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
