"""Kind ltc_aniso (lutbake.kinds.ltc_aniso): a tiny bake of both parametrisations, the texture layout's shape, the
symmetries (alpha_x <-> alpha_y with phi -> pi/2 - phi, theta = 0 independent of phi), the isotropic slice against
lutbake's isotropic fit, the bits for any worker count, the paper's .npy and ``lutbake inspect``."""

import dataclasses
import json

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake.api import bake
from lutbake.cli import main
from lutbake.io.readers import read_table
from lutbake.ltc import aniso, fit, lobes
from lutbake.ltc.magnitude import magnitude_fresnel

N = 3  # texels per axis: 81 per texture, 42 fitted
FIT_SAMPLES = 8  # the metric's grid: small, fast; the identities hold at any size
SAMPLES = 4096  # Sobol' points per anisotropic texel
MAG_SYMMETRY_ATOL = 5e-3  # two QMC estimates of one integral (the swap mirrors the sampler's points): 4096 points
IDENTITY_RTOL = 2e-3  # as tests/test_ltc_aniso.py: the same optimum within Nelder-Mead's stopping test
MATRIX_ATOL = 2e-2
DIAGONAL_ATOL = 5e-5  # the isotropic fit's own asymmetry (Nelder-Mead stops with m00 != m11 at theta = 0)
S = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def baked(tmp_path, parametrisation="alphax_alphay", workers=1, fmt="exr", name="la", fit="l3"):
    cfg = tmp_path / f"{name}.toml"
    cfg.write_text(
        f'[[table]]\nname = "{name}"\nkind = "ltc_aniso"\nparametrisation = "{parametrisation}"\nsize = {N}\n'
        f'fit_samples = {FIT_SAMPLES}\nsamples = {SAMPLES}\nformat = "{fmt}"\nfit = "{fit}"\n'
    )
    bake(cfg, tmp_path / "out", workers=workers)
    ext = ".exr" if fmt == "exr" else ".npy"
    return tmp_path / "out" / f"{name}{ext}"


def unpack(data: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(M (N, N, N, N, 3, 3), t2's (magnitude, fresnel, fit_error) (N, N, N, N, 3)) of the table's data."""
    ch = np.asarray(data, np.float64).reshape(3, N, N, N, N, 4).transpose(1, 2, 3, 4, 0, 5).reshape(N, N, N, N, 12)
    return ch[..., :9].reshape(N, N, N, N, 3, 3), ch[..., 9:]


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("ltc_aniso")
    path = baked(tmp)
    return {"path": path, "xy": read_table(path), "tmp": tmp}


def test_layout_is_three_3d_textures_and_finite(tables):
    t = tables["xy"]
    assert t.data.shape == (3, N * N * N, N, 4)
    assert np.all(np.isfinite(t.data))
    m, extra = unpack(t.data)
    np.testing.assert_allclose(np.linalg.norm(m[..., :, 2], axis=-1), 1.0, rtol=1e-6)  # |M e_z| = 1, float32
    assert np.all(extra[..., 0] > 0.0) and np.all(extra[..., 1] > 0.0)
    attrs = t.attrs
    assert t.kind == "ltc_aniso" and "layer = b + 3 a" in attrs["ltc_aniso_layer"]
    assert "ltc_aniso.glsl" in attrs["ltc_aniso_shader"]
    assert json.loads(attrs["ltc_aniso_magnitude_spread"])["max_abs"] < MAG_SYMMETRY_ATOL


def test_symmetries(tables):
    m, extra = unpack(tables["xy"].data)
    for i in range(N):
        for j in range(N):
            # (alpha_x, alpha_y, phi) and (alpha_y, alpha_x, pi/2 - phi): S M S (the lower triangle is filled so; the
            # diagonal is the isotropic fit turned by R_z(phi): S M S up to the fit's stopping test, e.g. theta = 0's
            # diag(m00, m11, 1) with m00 = m11 to 1.7e-5)
            mirrored = (S @ m[i, j][:, ::-1] @ S).astype(np.float32)
            if i != j:
                np.testing.assert_array_equal(m[j, i], mirrored)
            else:
                np.testing.assert_allclose(m[j, i], mirrored, atol=DIAGONAL_ATOL)
            # the magnitudes are integrated at every texel: the same integral, two QMC estimates
            np.testing.assert_allclose(extra[j, i, ..., :2], extra[i, j, :, ::-1, :2], atol=MAG_SYMMETRY_ATOL)
    np.testing.assert_array_equal(m[:, :, 0], np.broadcast_to(m[:, :, 0, :1], m[:, :, 0].shape))  # theta = 0


@pytest.mark.parametrize("frame", ["free"])
def test_isotropic_slice_is_lutbakes_isotropic_fit(tables, frame):
    m, extra = unpack(tables["xy"].data)
    g = aniso.Grid4("alphax_alphay", (N,) * 4)
    ax, _ = g.alphas()
    _, _, theta, phi = g.axes()
    i, k, l = (x.ravel() for x in np.meshgrid(np.arange(N), np.arange(1, N), np.arange(N), indexing="ij"))
    nov, alpha = np.cos(theta[k]).astype(np.float32), ax[i, i]
    mag, fres = magnitude_fresnel("ggx", nov, alpha, None)
    np.testing.assert_array_equal(extra[i, i, k, l, 0], mag.astype(np.float32))  # the exact rule, bit for bit
    np.testing.assert_array_equal(extra[i, i, k, l, 1], fres.astype(np.float32))
    lb = dataclasses.replace(lobes.LOBES["ggx"], free_frame=frame == "free")
    iso = fit.Problem(lb, nov, alpha, mag, FIT_SAMPLES)
    t = np.arange(len(nov))
    q, e = fit.fit_from(iso, t, fit.analytic_guesses(iso, t), fit.COARSE_STEPS)
    want = aniso.canonical(aniso.rotate_z(iso.matrices(t, q), phi[l]))
    np.testing.assert_allclose(m[i, i, k, l], want, atol=MATRIX_ATOL)
    np.testing.assert_allclose(extra[i, i, k, l, 2], iso.relative(t, e), rtol=IDENTITY_RTOL, atol=1e-6)


def test_bits_do_not_depend_on_the_worker_count(tables, tmp_path):
    two = read_table(baked(tmp_path, workers=2))
    assert np.array_equal(two.data, tables["xy"].data)


def test_alpha_anisotropy_table_and_the_papers_npy(tables):
    tmp = tables["tmp"]
    t = read_table(baked(tmp, "alpha_anisotropy", name="al"))
    m, extra = unpack(t.data)
    xy, xy_extra = unpack(tables["xy"].data)
    # lambda = 1 is alpha_y = alpha_x: the alphax_alphay table's diagonal (each texel's fit reads its own inputs)
    np.testing.assert_array_equal(m[:, N - 1], xy[np.arange(N), np.arange(N)])
    np.testing.assert_array_equal(extra[:, N - 1], xy_extra[np.arange(N), np.arange(N)])
    # a = 0: alpha_x = alpha_y = 1e-4 on every lambda
    np.testing.assert_array_equal(m[0], np.broadcast_to(m[0, :1], m[0].shape))
    paper = np.load(baked(tmp, fmt="ltc_aniso_npy", name="la_paper"))
    assert paper.shape == (N, N, N, N, 3, 3) and paper.dtype == np.float32
    np.testing.assert_array_equal(paper, xy.astype(np.float32))


def test_inspect_reads_it(tables):
    r = CliRunner().invoke(main, ["inspect", str(tables["path"])])
    assert r.exit_code == 0, r.output
    assert "kind: ltc_aniso" in r.output and "layer: y_block" in r.output and "fit_error_median" in r.output


def test_shaded_fit_keeps_the_magnitude_and_the_symmetries(tables):
    t = read_table(baked(tables["tmp"], name="la_shaded", fit="shaded"))
    m, extra = unpack(t.data)
    xy, xy_extra = unpack(tables["xy"].data)
    assert np.all(np.isfinite(t.data)) and "then shaded" in t.attrs["ltc_aniso_fit"]
    np.testing.assert_array_equal(extra[..., :2], xy_extra[..., :2])  # magnitude and fresnel: the exact channels
    assert not np.array_equal(m, xy)  # refined
    np.testing.assert_allclose(np.linalg.norm(m[..., :, 2], axis=-1), 1.0, rtol=1e-6)
    for i in range(N):
        for j in range(i):
            np.testing.assert_array_equal(m[j, i], (S @ m[i, j][:, ::-1] @ S).astype(np.float32))
