"""Verified interpolation between texels (lutbake.sampling.interpolation): every interpolated texel's recorded
estimate bounds its error against a converged bake of every texel; the stencils are exact on polynomials; smooth
masks keep interpolation off edge policies; the table is the same bits however its tiles are cut."""

from dataclasses import dataclass

import numpy as np
import pytest

from lutbake.axes import Axis
from lutbake.kinds import lookup_kind
from lutbake.runtime.executor import execute_tiles
from lutbake.sampling import interpolation
from lutbake.sampling.interpolation import COARSE, INTEGRATED, INTERPOLATED, VARIANTS, axis_stencils
from lutbake.sampling.plan import Grid

REFERENCE_NOISE = 5.0e-8  # the float32 terms' rounding, as tests/test_tolerance.py


@pytest.mark.parametrize("n", [64, 67, 256])
def test_every_stencil_reproduces_polynomials_of_its_degree(n):
    s = axis_stencils(n)
    assert s.coarse[0] == 0 and s.coarse[-1] == n - 1 and np.all(np.diff(s.coarse) <= interpolation.STRIDE)
    x = np.arange(n, dtype=np.float64) / n
    for name, (_, count) in VARIANTS.items():
        for degree in range(count):
            f = (x - 0.3) ** degree
            got = np.sum(s.w[name] * f[s.coarse][s.idx[name]], axis=1)
            assert np.allclose(got[s.valid], f[s.valid], atol=1e-12), (name, degree)
    # the shifted stencils need 4 coarse nodes below and above: the first and last 3 gaps are integrated
    edge = slice(1, 3 * interpolation.STRIDE)
    assert not (s.valid[edge] & ~s.is_coarse[edge]).any() and s.valid[3 * interpolation.STRIDE + 1]
    assert s.valid[s.coarse].all()


@dataclass(frozen=True)
class FunctionEstimator:
    """A stand-in adaptive estimator: f(nov, alpha) in closed form with an estimate of 0 (no Warp)."""

    f: object
    absolute: float = 1e-6
    relative: float = 0.0
    name: str = "closed_form"

    def evaluate_with_error(self, integrand, inputs, device):
        v = self.f(inputs["nov"].astype(np.float64), inputs["alpha"].astype(np.float64))
        return v, np.zeros_like(v)


def _f(nov, alpha):
    """Smooth, with a kink along nov = 0.6 (|x|) and a peak of width 0.3 at alpha = 0.3."""
    return np.stack([np.exp(-nov) * np.cos(3 * alpha), np.abs(nov - 0.6) + 0.09 / (0.09 + (alpha - 0.3) ** 2)], 1)


def _closed_form_run(smooth, tile, n=256):
    """Every tile of an n^2 table of _f (tiles of ``tile`` texels) and _f at every texel."""
    axes = [Axis("alpha", "y", n, 0.0, 1.0), Axis("NoV", "x", n, 0.0, 1.0)]
    nov, alpha = np.meshgrid(axes[1].values(), axes[0].values())
    grid = Grid(axes, {"nov": nov.ravel(), "alpha": alpha.ravel()}, smooth=smooth(nov, alpha).ravel())

    def integrate(est, idx, device):
        return est.evaluate_with_error(None, grid.rows(idx), device)

    vi = interpolation.VerifiedInterpolation(grid, FunctionEstimator(_f), integrate, 2)
    out = np.concatenate([vi.run_tile(s, min(s + tile, n * n), "cpu") for s in range(0, n * n, tile)])
    return out, _f(nov.ravel().astype(np.float64), alpha.ravel().astype(np.float64)), grid


def everywhere(nov, alpha):
    return np.ones_like(nov, bool)


@pytest.mark.parametrize("tile", [256 * 16, 1000])
def test_closed_form_estimates_bound_errors_and_tiles_do_not_matter(tile):
    out, exact, grid = _closed_form_run(everywhere, tile)
    values, est, flag = out[:, :2], out[:, 2:4], out[:, 4]
    interp = flag == INTERPOLATED
    assert 0.3 < interp.mean() < 0.95, interp.mean()  # the kink and the peak integrated, most of the rest interpolated
    err = np.abs(values - exact)
    assert np.all(err[interp] <= est[interp])
    assert np.all(est[interp] <= 1e-6)
    assert np.all(err[~interp] == 0.0)  # integrated and coarse texels: the estimator's own values
    # no texel whose stencil straddles the kink (nov = 0.6: |x|) is kept
    nov = grid.inputs["nov"]
    assert not np.any(interp & (np.abs(nov - 0.6) < 0.5 / 256))
    whole, _, _ = _closed_form_run(everywhere, 256 * 256)
    assert np.array_equal(out, whole)  # the same bits for any tiles


def test_closed_form_smooth_mask_keeps_stencils_off_edge_texels():
    out, _, grid = _closed_form_run(lambda nov, alpha: alpha >= 0.1, 256 * 16)
    flag = out[:, 4].reshape(256, 256)
    alpha = grid.inputs["alpha"].reshape(256, 256)[:, 0]
    first = int(np.argmax(alpha >= 0.1))  # the first smooth row (26)
    rows = np.flatnonzero((flag == INTERPOLATED).any(axis=1))
    s = axis_stencils(256)
    lowest = np.where(s.is_coarse[rows], rows, s.coarse[np.clip(s.span[rows, 0], 0, None)])
    assert rows.size and lowest.min() >= first  # no stencil reaches a texel under the edge policy
    assert rows.min() == s.coarse[s.coarse >= first][0]  # the first smooth coarse row interpolates along x


@pytest.fixture(scope="module")
def gltf_256(spec):
    """A glTF-layout dfg table at 256^2 (PNG16 tolerance): interpolated (values, estimates, flags) and every texel
    integrated to 1e-8 (the reference)."""
    keys = dict(kind="dfg", size=[256, 256], format="png16", roughness="perceptual")
    table_spec = spec(**keys)
    data = execute_tiles(lookup_kind("dfg").plan(table_spec))
    ref_spec = spec(**keys, interpolation="off", tolerance=1e-8)
    ref = execute_tiles(lookup_kind("dfg").plan(ref_spec))
    return data, ref


def test_dfg_interpolated_estimates_bound_errors_on_every_texel(gltf_256):
    data, ref = gltf_256
    values, est, flag = data[:, :2], data[:, 2:4], data[:, 4]
    err = np.abs(values - ref[:, :2])
    interp = flag == INTERPOLATED
    print(
        f"interpolated {interp.mean():.3f}, coarse {(flag == COARSE).mean():.3f}, integrated "
        f"{(flag == INTEGRATED).mean():.3f}; max error {err.max():.3e}, worst error / estimate "
        f"{np.max(err[interp] / est[interp]):.3f}"
    )
    assert interp.mean() > 0.7
    assert np.all(err <= est + ref[:, 2:4] + REFERENCE_NOISE)
    assert np.all(est <= 0.25 / 65535)


def test_dfg_interpolation_records_its_method(bake):
    table = bake(kind="dfg", size=[128, 128])
    assert "interpolated from" in table.attributes["error_estimate_method"]
    assert "lutbake.sampling.interpolation" in table.attributes["interpolation"]
    small = bake(kind="dfg", size=[64, 128])  # an axis under MIN_AXIS: every texel integrated
    assert "interpolated" not in small.attributes["error_estimate_method"]
    off = bake(kind="dfg", size=[128, 128], interpolation="off")
    assert "interpolated" not in off.attributes["error_estimate_method"]
    assert np.abs(off.data - table.data).max() <= 2.0e-6  # both within 1e-6 of the truth
