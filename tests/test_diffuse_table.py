"""Kind ``diffuse`` (AmbientBRDF, NoV x sigma): albedo invariants, the sigma = 0 limit, f0 factoring."""

import numpy as np
import pytest

from lutbake.errors import ConfigError

LIMIT_ATOL = 2e-4  # sigma = 0 row of the microfacet table vs (1 - f0)(1 - (1 - NoV)^5)


DIFFUSE = {"name": "d", "kind": "diffuse", "size": [6, 4]}


def test_lambert_albedo_is_one(bake):
    t = bake(DIFFUSE, model="lambert", workers=1)
    assert t.data.shape == (4, 6, 1)
    np.testing.assert_allclose(t.data, 1.0, atol=1e-6)


def test_oren_nayar_row_at_sigma_0_is_lambert(bake):
    t = bake(DIFFUSE, model="oren_nayar", texel="endpoint", size=[5, 3], workers=1)
    np.testing.assert_allclose(t.data[0, :, 0], 1.0, atol=1e-6)
    # the qualitative model is not energy conserving: at grazing view its albedo exceeds 1 (1.013 at sigma = 0.5)
    assert np.all(t.data > 0) and t.data[1, 0, 0] > 1.0


@pytest.fixture(scope="module")
def microfacet(bake):
    return bake(DIFFUSE, model="microfacet", texel="endpoint", size=[5, 4])


def test_microfacet_sigma_0_row_is_lambert_times_eq6_albedo(microfacet):
    nov = microfacet.axes[1].values().astype(np.float64)
    # column 0 (NoV = NOV_MIN = 1e-4) is left out: the limit needs alpha << NoV, and alpha = ALPHA_MIN = 1e-4 there
    # ∫ 21/20 (1 - (1 - NoL)^5) NoL dω_l / pi = 20/21 x 21/20 = 1: E = (1 - f0)(1 - (1 - NoV)^5)
    np.testing.assert_allclose(microfacet.data[0, 1:, 0], 1 - (1 - nov[1:]) ** 5, atol=LIMIT_ATOL)


def test_microfacet_albedo_is_at_most_one_and_positive(microfacet):
    assert np.all(microfacet.data <= 1.0 + 1e-6)
    assert np.all(microfacet.data[:, 1:] > 0.0)


def test_microfacet_f0_factors_out(microfacet, bake):
    t = bake(DIFFUSE, model="microfacet", texel="endpoint", size=[5, 4], f0=0.04, workers=1)
    np.testing.assert_allclose(t.data, 0.96 * microfacet.data, rtol=1e-5, atol=1e-7)
    assert t.attributes["f0_factor"] == "(1 - f0)"


@pytest.mark.parametrize(
    "kv, fragment",
    [
        ({"model": "phong"}, "lambert"),
        ({"f0": 1.5}, "<="),
        ({"sigma_to_alpha": "cube"}, "sigma_squared"),
        ({"samples": 1}, ">= 2"),
    ],
)
def test_bad_diffuse_keys_are_rejected(kv, fragment, spec):
    with pytest.raises(ConfigError, match=fragment):
        spec(DIFFUSE, **kv)


def test_swapped_albedo_matches_the_nested_rule():
    """The table's integrator (m outside, l inside: lutbake.sampling.swapped) against the direct nested
    rule (l outside, Eq. 4's m-integral inside: integrands.diffuse.albedo_gl), grazing and small-sigma texels
    included."""
    from lutbake.axes import sigma_alpha
    from lutbake.edge import effective_alpha
    from lutbake.integrands import diffuse as D

    nov = np.array([0.05, 0.2, 0.5, 0.9, 1.0, 0.3], np.float32)
    sigma = np.array([0.05, 0.5, 0.3, 1.0, 0.1, 0.02], np.float32)
    nested = D.albedo_gl("microfacet", nov, sigma, 0.04, "eq6", "sigma", order=12)
    swapped = D.albedo_swapped(nov, effective_alpha(sigma_alpha(sigma, "sigma"), False), 0.04, "eq6")
    np.testing.assert_allclose(swapped, nested, atol=5e-5)


def test_microfacet_table_records_its_error_estimate(microfacet):
    assert float(microfacet.attributes["error_estimate"]) < 1e-5
    assert "probe texels" in microfacet.attributes["error_estimate_method"]


def test_grazing_small_sigma_corner_is_converged(bake):
    """The corner the old nested rule missed by 2.9e-3 (NoV = sigma = 1/128): the default orders against order 32."""
    from lutbake.integrands import diffuse as D

    t = bake(DIFFUSE, model="microfacet", size=[4, 4], nov_range=[0.0, 0.0625], sigma_range=[0.0, 0.0625], workers=1)
    nov = np.tile(t.axes[1].values(), 4).astype(np.float64)
    alpha = np.repeat(t.axes[0].values(), 4).astype(np.float64)
    ref = D.albedo_swapped(nov, alpha, orders=np.full((16, 3), 32))
    np.testing.assert_allclose(t.data[..., 0].reshape(-1), ref, atol=1e-6)
