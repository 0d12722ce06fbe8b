"""Zeltner, Burley & Chiang 2022's volumetric sheen (lutbake.terms.sheen_volume, LTC lobe ``zeltner``) against the
numpy port of tizian/ltc-sheen's sheen_approx.h (tests/sheen_volume_reference.py), its normal-frame LTC fit against
the paper's published tables (tests/data/ltc_sheen_tables.npz), and Babylon.js's shipped fuzz table identified as
one of them (tests/data/babylon_environment_fuzz_brdf.npz)."""

from pathlib import Path

import numpy as np
import pytest
import sheen_volume_reference as ref

from lutbake.ltc import fit
from lutbake.ltc.lobes import LOBES

DATA = Path(__file__).parent / "data"
N = 32
MUS = np.maximum(0.01, np.linspace(0, 1, N))  # the paper's grid (fit_ltc_sheen_*.py)
ALPHAS = np.maximum(0.01, np.linspace(0, 1, N))
TERM_RTOL = 2e-5  # float32 terms (measured 3.2e-6 over 30 (mu, alpha) x 400 directions)
# Babylon's mix() ranges (pbrBRDFFunctions getFuzzBRDFLookup): A, B, R_i
BABYLON_LO = np.array([0.005, -0.18, 0.0])
BABYLON_HI = np.array([0.88, 0.002, 0.75])


@pytest.fixture(scope="module")
def published():
    d = np.load(DATA / "ltc_sheen_tables.npz")
    return {k: d[k] for k in ("volume", "approx")}


def test_terms_match_the_sheen_approx_port():
    """f (n.l) of the lobe, as the fit sees it, equals the C++'s at random directions (both hemispheres)."""
    rng = np.random.default_rng(0)
    mus, alphas = [0.01, 0.1, 0.5, 0.9, 1.0], [0.01, 0.05, 0.2, 0.5, 0.8, 1.0]
    nov = np.repeat(np.float32(mus), len(alphas))
    alpha = np.tile(np.float32(alphas), len(mus))
    p = fit.Problem("zeltner", nov, alpha, np.ones(len(nov)))
    k = 200
    for t in range(len(nov)):
        th, ph = np.arccos(rng.uniform(-0.2, 1.0, k)), rng.uniform(0.0, 2.0 * np.pi, k)
        l = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=1).astype(np.float32)
        got = p.f_cos(np.full(k, t), l)
        want = ref.eval_approx(p.v[t].astype(np.float64), l.astype(np.float64), float(alpha[t]))
        np.testing.assert_allclose(got, want, rtol=TERM_RTOL, atol=1e-30)
        assert np.all(got[l[:, 2] < 0] == 0.0)


def test_normal_frame_matrices_are_zeltners():
    q = np.array([[np.log(1 / 0.4), -0.1], [np.log(2.0), 0.05]])
    inv = np.linalg.inv(fit.normal_frame_matrices(q, np.array([False, True])))
    np.testing.assert_allclose(inv[0], [[0.4, 0, -0.1], [0, 0.4, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(inv[1], [[0.5, 0, 0], [0, 0.5, 0], [0, 0, 1]], atol=1e-15)  # b = 0 at n.v = 1
    assert LOBES["zeltner"].normal_frame and not any(lb.normal_frame for n, lb in LOBES.items() if n != "zeltner")


def test_lobe_albedo_matches_the_ports_quadrature():
    """lutbake.ltc.fit.lobe_albedo (the ltc kind's magnitude of the lobe, Gauss-Legendre) against the port's own
    quadrature, a midpoint rule, at 1024^2 (at 256^2 its own error reaches 1e-5 relative)."""
    idx = [(0, 0), (3, 2), (16, 16), (5, 25), (31, 31)]
    nov = np.float32([MUS[i] for i, _ in idx])
    alpha = np.float32([ALPHAS[j] for _, j in idx])
    got = fit.lobe_albedo(fit.Problem("zeltner", nov, alpha, np.zeros(len(idx))))
    want = [ref.albedo(float(m), float(a), n=1024) for m, a in zip(nov, alpha)]
    np.testing.assert_allclose(got, want, rtol=1e-5)


def test_fit_on_the_papers_grid_is_close_to_the_published_approx_table(published):
    """lutbake's L3 fit (magnitude = albedo) of the approx lobe against the paper's L2 fit (R free) of the same lobe,
    every other texel of rows mu >= 0.03: |dA| median 7.3e-3, p95 3.0e-2, max 5.5e-2; |dB| median 2.9e-3, max 1.2e-2;
    |R - albedo| median 5.9e-3 relative, max 3.4e-2. Row mu = 0.01 (grazing view) is left out: both fits' relative L3
    error there is ~1 (no LTC of this form fits it) and they differ by up to 0.95 in A."""
    nov, alpha = np.repeat(np.float32(MUS), N), np.tile(np.float32(ALPHAS), N)
    p = fit.Problem("zeltner", nov, alpha, np.zeros(N * N))
    p = fit.Problem("zeltner", nov, alpha, fit.lobe_albedo(p))
    rows, cols = np.arange(1, N, 2), np.arange(0, N, 2)  # every other texel (each is fitted independently)
    idx = (rows[:, None] * N + cols[None, :]).ravel()
    m, _ = fit.fit_texels(p, idx, N, fit.coarse_pass(p, N, N))
    inv = np.linalg.inv(m)
    ours = np.stack([inv[:, 0, 0] / inv[:, 2, 2], inv[:, 0, 2] / inv[:, 2, 2], p.magnitude[idx]], axis=1)
    d = np.abs(ours - published["approx"].reshape(-1, 3)[idx]).reshape(len(rows), len(cols), 3)
    print("|dA| median, p95, max", np.median(d[..., 0]), np.quantile(d[..., 0], 0.95), d[..., 0].max())
    print("|dB| median, max", np.median(d[..., 1]), d[..., 1].max())
    assert np.median(d[..., 0]) < 0.01 and np.quantile(d[..., 0], 0.95) < 0.04 and d[..., 0].max() < 0.08
    assert np.median(d[..., 1]) < 0.005 and d[..., 1].max() < 0.03
    rel = d[..., 2] / np.maximum(published["approx"][1::2, ::2, 2], 1e-3)
    print("R relative median, max abs", np.median(rel), d[..., 2].max())
    assert np.median(rel) < 0.01 and d[..., 2].max() < 0.05


def test_babylon_fuzz_png_is_the_volume_fit_coded_linearly(published):
    """Babylon's environmentFuzzBRDFTexture is the paper's *volume* table (the random walk's fit), rows = mu (the
    PNG's first row mu = 0.01), columns = alpha, each channel coded linearly between the table's own extremes:
    code = round(255 (x - min) / (max - min)) exactly at 100 / 99.5 / 99.9 % of texels (A / B / R), within 0.51
    codes at all. Read through getFuzzBRDFLookup's rounded mix() ranges that is the fit to 6.3e-3 / 1.7e-3 / 1.7e-3;
    the approx table and the transposed or flipped orientations are off by 0.2-0.9. Babylon decodes the PNG as RGBD
    though (pow(code / 255, 2.2)), so the values its shader mixes are up to 0.25 off in A (R: 0.21)."""
    shipped = np.load(DATA / "babylon_environment_fuzz_brdf.npz")
    codes = shipped["codes"][..., :3].astype(np.float64)
    volume = published["volume"]
    lo, hi = volume.min(axis=(0, 1)), volume.max(axis=(0, 1))
    coded = 255.0 * (volume - lo) / (hi - lo)
    assert np.all(np.abs(codes - coded) < 0.51)
    assert np.all(np.mean(codes == np.round(coded), axis=(0, 1)) >= [1.0, 0.995, 0.999])
    read = BABYLON_LO + codes / 255.0 * (BABYLON_HI - BABYLON_LO)  # the shader's mix() of the linear codes
    assert np.all(np.abs(read - volume).max(axis=(0, 1)) < [7e-3, 2e-3, 2e-3])
    for other in (published["approx"], volume.transpose(1, 0, 2), volume[::-1]):
        assert np.abs(read - other).max() > 0.2
    as_shaded = BABYLON_LO + (BABYLON_HI - BABYLON_LO) * shipped["table"]  # Babylon's fromRGBD decode, then mix()
    assert 0.2 < np.abs(as_shaded - volume)[..., 0].max() < 0.3
