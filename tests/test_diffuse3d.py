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


def test_f0_slices_share_their_nodes_and_keep_their_bits(monkeypatch):
    """The f0 slices of a (n.v, sigma) texel are integrated over one set of nodes (lutbake.sampling.swapped: groups
    of 16, the cosines and f0-free factors once): each value is the texel's own evaluation to the bit, the table is
    the same for any tiling (its single-slice tiles take their siblings), and a group of 17 is cut 16 + 1."""
    from lutbake.integrands.diffuse import diffuse_integrand
    from lutbake.sampling import swapped

    integrand = diffuse_integrand("microfacet", "dielectric_f0")
    nov, alpha = np.repeat([0.05, 0.5, 0.9], 17), np.repeat([0.3, 0.05, 0.7], 17)
    f0 = np.tile(np.linspace(0.0, 0.96, 17), 3)
    grouped = swapped.integrate_swapped(integrand, nov, alpha, f0, order=8, members=swapped.MEMBERS)
    monkeypatch.setattr(
        swapped, "group_rows", lambda key, ok, size: (np.zeros((0, size), np.int32), np.arange(len(key)))
    )
    alone = swapped.integrate_swapped(integrand, nov, alpha, f0, order=8, members=swapped.MEMBERS)
    np.testing.assert_array_equal(grouped, alone)
    monkeypatch.undo()
    from lutbake.config import validate_table
    from lutbake.kinds import lookup_kind

    spec = validate_table({**D3, "f0_size": 4, "f0_range": [0.0, 0.9]}, "<test>", 0)
    whole = lookup_kind("diffuse_3d").plan(spec)  # 60 texels in one tile: the groups form in it
    plan = lookup_kind("diffuse_3d").plan(spec)
    tiles = [plan.run_tile(a, a + 5, "cpu") for a in range(0, plan.n_texels, 5)]  # 5 texels: within a slice
    np.testing.assert_array_equal(np.concatenate(tiles), whole.run_tile(0, whole.n_texels, "cpu"))
