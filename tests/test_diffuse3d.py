"""Kind ``diffuse_3d`` (NoV x sigma x f0): factoring forms reduce to the 2D table x g(f0); the exact dielectric
form against the nested rule; the EXR layout (a part per f0 slice)."""

import numpy as np
import pytest

from lutbake.io.exr import read_exr, write_exr

D3 = {"name": "d3", "kind": "diffuse_3d", "size": [5, 3]}


@pytest.fixture(scope="module")
def eq6_3d(bake):
    return bake(D3, facet_fresnel="eq6", f0_size=3)


def test_factoring_form_slices_are_the_2d_table_times_its_factor(eq6_3d, bake):
    t2 = bake(D3, kind="diffuse", facet_fresnel="eq6", workers=1)
    f0 = eq6_3d.axes[0].values().astype(np.float64)
    assert eq6_3d.data.shape == (3, 3, 5, 1)
    for k, f in enumerate(f0):
        np.testing.assert_allclose(eq6_3d.data[k], t2.data * (1.0 - f), rtol=2e-6, atol=1e-7)


def test_fitted_slices_are_the_2d_fitted_table_times_1_minus_f0(bake):
    t3 = bake(D3, model="fitted", f0_size=2, samples=8, workers=1)
    t2 = bake(D3, kind="diffuse", model="fitted", samples=8, workers=1)
    for k, f in enumerate(t3.axes[0].values().astype(np.float64)):
        np.testing.assert_allclose(t3.data[k], t2.data * (1.0 - f), rtol=2e-6, atol=1e-7)


def test_dielectric_form_matches_the_nested_rule_and_does_not_factor(bake):
    from lutbake.integrands import diffuse as D

    t = bake(D3, f0_size=2, f0_range=[0.04, 0.5], texel="endpoint")
    assert t.attributes["factoring_form"].startswith("none")
    nov = t.axes[2].values()[[1, 3]]
    sigma = t.axes[1].values()[[1, 2]]
    for k, f0 in enumerate((0.04, 0.5)):
        nested = D.albedo_gl("microfacet", nov, sigma, f0, "dielectric_f0", "sigma", order=10)
        np.testing.assert_allclose(t.data[k, [1, 2], [1, 3], 0], nested, atol=1e-4)
    # not (1 - f0) or (1 - f0)^2 times the f0 = 0.04 slice
    ratio = t.data[1, 1:, 1:, 0] / t.data[0, 1:, 1:, 0]
    assert np.ptp(ratio) > 1e-3


def test_exr_has_a_part_per_f0_slice(eq6_3d, tmp_path):
    p = write_exr(eq6_3d, tmp_path / "d3.exr")
    data, attrs = read_exr(p)
    assert data.shape == (3, 3, 5, 1)
    np.testing.assert_allclose(data, eq6_3d.data)
    assert attrs["kind"] == "diffuse_3d" and "f0" in attrs["axes"]
