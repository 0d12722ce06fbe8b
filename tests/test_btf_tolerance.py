"""Kind ``btf`` to a tolerance: the adaptive m-integral's per-texel error estimate bounds the measured error.

The estimate of a texel (lutbake.sampling.facets.fd_microfacet_adaptive_for) is the sum over its u panels of
|Q(order k) - Q(order k-1)| plus the float32 rounding allowance; it is held against the independent numpy
integrator of tests/test_diffuse_terms.py (theta_m x phi_m, own coordinates, graded rule; converged to < 4e-12
relative) at random texels of the 16 x 32^3 grid and at the hard ones: light and view at neighbouring polar angles
(l ~ v, where the clamps' onsets u_l and u_v nearly coincide), both grazing, one grazing, and the smallest sigma.
"""

import numpy as np
import pytest
from test_diffuse_terms import ref_microfacet

from lutbake.axes import sigma_alpha
from lutbake.edge import effective_alpha
from lutbake.integrands.diffuse import diffuse_integrand
from lutbake.kinds import btf
from lutbake.sampling.diffuse import eval_points_adaptive

# what the numpy reference does not resolve: its own convergence (< 4e-12) and its float64 terms against lutbake's
# float32 ones, already inside the estimate's rounding allowance (FACET_ROUNDING): nothing more than float64 noise
REFERENCE_NOISE = 1.0e-12
TOLERANCES = [(0.0, 1.0e-5), (0.0, 1.0e-4), (1.0e-7, 1.0e-5)]  # (absolute, relative); the last: absolute below 1e-2
N = 32  # the 16 x 32^3 benchmark grid


@pytest.fixture(scope="module")
def texels():
    """(l, v, alpha) of 12 random texels of the 16 x 32^3 angles grid and 18 hard ones (module docstring)."""
    o = {"size": [N, N], "phi_size": N, "sigma_size": 16, "sigma_range": [0.0, 1.0], "sigma_values": None}
    o.update(texel="center", sigma_to_alpha="sigma", parametrisation="angles")
    l, v, sigma = btf.directions(btf.axes_for(o), "angles")
    alpha = effective_alpha(sigma_alpha(sigma.astype(np.float32), "sigma"), False)
    idx = lambda s, p, iv, il: ((s * N + p) * N + iv) * N + il  # noqa: E731
    rng = np.random.default_rng(13)
    pick = list(rng.integers(0, len(l), 12))
    for s in (0, 5, 15):
        pick += [idx(s, 0, 20, 21), idx(s, 3, 29, 30), idx(s, 1, 9, 10)]  # l ~ v, small phi
        pick += [idx(s, 31, 31, 31), idx(s, 0, 31, 30), idx(s, 16, 0, 31)]  # both grazing (back, forward), one
    pick = np.array(pick)
    return l[pick], v[pick], alpha[pick]


@pytest.fixture(scope="module")
def numpy_references(texels, graded_rule):
    l, v, alpha = texels
    return np.array(
        [
            ref_microfacet(l[i].astype(np.float64), v[i].astype(np.float64), np.float64(alpha[i]), 0.0, graded_rule)
            for i in range(len(l))
        ]
    )


@pytest.mark.parametrize("tol", TOLERANCES)
def test_error_estimate_bounds_error_against_numpy_reference(texels, numpy_references, tol):
    l, v, alpha = texels
    got, est = eval_points_adaptive(diffuse_integrand("microfacet", "eq6"), l, v, alpha, 0.0, tol)
    got, est = got[:, 0], est[:, 0]
    err = np.abs(got - numpy_references)
    print(f"tol {tol}: max relative error {np.max(err / numpy_references):.3e}, max estimate {np.max(est / got):.3e}")
    assert np.all(err <= est + REFERENCE_NOISE), (err, est)
    assert np.all(est <= np.maximum(tol[0], tol[1] * np.abs(got)))  # every texel met its tolerance


def test_bake_records_tolerance_and_is_reciprocal(bake):
    t = bake({"name": "b", "kind": "btf", "size": [6, 6], "phi_size": 3, "sigma_size": 2}, workers=2)
    attrs = t.attributes
    assert attrs["tolerance"] == "max(0, 1e-05 |v|) per value"
    assert 0.0 < float(attrs["error_estimate"]) <= 1.0e-5
    d = t.data[..., 0].reshape(2, 3, 6, 6)
    np.testing.assert_array_equal(d, d.transpose(0, 1, 3, 2))  # a texel and its reciprocal: one integral


def test_tile_cuts_do_not_change_the_values(spec):
    """Reciprocal pairs are integrated once per tile: any cut of the tiles still gives the same bits."""
    plan = btf.plan(spec({"name": "b", "kind": "btf", "size": [5, 5], "phi_size": 2, "sigma_size": 1}))
    plan.prepare("cpu")
    n = plan.n_texels
    whole = plan.run_tile(0, n, "cpu")
    cut = np.concatenate([plan.run_tile(s, min(s + 7, n), "cpu") for s in range(0, n, 7)])
    np.testing.assert_array_equal(cut, whole)
    assert plan.tile_texels == 25 * 21  # whole (phi, sigma) blocks of 5 x 5 texels, at least 512
