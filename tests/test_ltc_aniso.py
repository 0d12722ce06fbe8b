"""Anisotropic GGX LTC (lutbake.ltc.aniso): the isotropic slice is lutbake's isotropic fit, the symmetries, bits
for any worker count, the published table's layout and the host reconstruction."""

import dataclasses
import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from lutbake.ltc import aniso, fit, lobes
from lutbake.ltc.magnitude import magnitude_fresnel

DATA = Path(__file__).parent / "data"
N_GRID = 12  # the metric's grid: small, fast; the identity holds at any size
IDENTITY_RTOL = 2e-3  # relative fit errors of the two problems: same optimum within Nelder-Mead's stopping test
MATRIX_ATOL = 2e-2  # |M| = 1 scale: same minimum of a flat objective


@pytest.mark.parametrize("frame", ["average", "free"])
def test_isotropic_slice_is_lutbakes_isotropic_fit(frame):
    nov = np.array([0.9, 0.6, 0.25], np.float32)
    alpha = np.array([0.3, 0.5, 0.2], np.float32)
    mag, _ = magnitude_fresnel("ggx", nov, alpha, None)
    lb = lobes.LOBES["ggx"] if frame == "average" else dataclasses.replace(lobes.LOBES["ggx"], free_frame=True)
    iso = fit.Problem(lb, nov, alpha, mag, N_GRID)
    t = np.arange(3)
    q, e = fit.fit_from(iso, t, fit.analytic_guesses(iso, t), fit.COARSE_STEPS)
    m_iso = aniso.canonical(iso.matrices(t, q))
    for phi in (0.0, 0.7):  # any azimuth: the isotropic lobe does not see the tangent
        m, e_an, rel = aniso.fit_tile(nov, alpha, alpha, np.full(3, phi), mag, N_GRID, "cpu", frame)
        np.testing.assert_allclose(rel, iso.relative(t, e), rtol=IDENTITY_RTOL)
        np.testing.assert_allclose(aniso.canonical(m), m_iso, atol=MATRIX_ATOL)


def test_swapping_the_roughnesses_mirrors_the_lobe():
    """(alpha_x, alpha_y, phi) and (alpha_y, alpha_x, pi/2 - phi) are the same lobe reflected by S = swap(x, y): a
    matrix's error at one is S M S's at the other."""
    g = aniso.Grid4("alphax_alphay", (3, 3, 3, 3))
    mag = np.ones(g.n)
    m = aniso.canonical(np.array([[[0.7, 0.1, -0.3], [0.05, 0.4, -0.2], [0.1, 0.15, 0.9]]]))
    s = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    a = np.ravel_multi_index((2, 1, 1, 0), g.n)
    b = np.ravel_multi_index((1, 2, 1, 2), g.n)
    ea = aniso.relative_error_of(g, mag, m, np.array([a]), N_GRID)
    eb = aniso.relative_error_of(g, mag, s @ m @ s, np.array([b]), N_GRID)
    np.testing.assert_allclose(ea, eb, rtol=1e-4)


def test_table_bits_do_not_depend_on_the_worker_count(monkeypatch):
    monkeypatch.setattr(aniso, "TILE", 5)
    g = aniso.Grid4("alphax_alphay", (2, 2, 2, 3))
    mag = np.full(g.n, 0.9)
    one = aniso.fit_table(g, mag, N_GRID, workers=1)
    two = aniso.fit_table(g, mag, N_GRID, workers=2)
    assert np.array_equal(one[0], two[0]) and np.array_equal(one[1], two[1])
    assert np.all(np.isfinite(one[0])) and np.all(np.isfinite(one[1]))
    np.testing.assert_allclose(np.linalg.norm(one[0][..., :, 2], axis=-1), 1.0, rtol=1e-12)


def test_published_tables_are_the_recorded_files():
    note = json.loads((DATA / "ltc_aniso_published.json").read_text())
    for name, rec in note["source"]["files"].items():
        raw = (DATA / name).read_bytes()
        assert hashlib.sha256(raw).hexdigest() == rec["sha256"]
        m = np.load(DATA / name)
        assert m.shape == (8, 8, 8, 8, 3, 3)
        np.testing.assert_allclose(np.linalg.norm(m[..., :, 2], axis=-1), 1.0, atol=1e-6)


def test_lookup_returns_the_texels_and_reflects_the_other_quadrants():
    g = aniso.Grid4("alphax_alphay", (8, 8, 8, 8))
    m = np.load(DATA / "ltc_aniso_alphax_alphay_theta_phi.npy").astype(np.float64)
    a, b, theta, phi = g.axes()
    got, _ = aniso.lookup(m, g, a[5], b[2], theta[3], phi[6])
    np.testing.assert_allclose(got[0], m[5, 2, 3, 6], atol=1e-12)
    mirrored, _ = aniso.lookup(m, g, a[5], b[2], theta[3], np.pi - phi[6])
    np.testing.assert_allclose(mirrored[0], np.diag([-1.0, 1.0, 1.0]) @ m[5, 2, 3, 6], atol=1e-12)
    tex = aniso.texture_layout(m, np.ones(g.n), np.zeros(g.n), np.zeros(g.n))
    assert tex.shape == (3, 64, 8, 8, 4)
    np.testing.assert_array_equal(tex[1, 2 + 8 * 5, 3, 6, 2], np.float32(m[5, 2, 3, 6, 2, 0]))
