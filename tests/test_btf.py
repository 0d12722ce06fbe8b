"""Kind ``btf``: layout (sigma parts, phi row blocks), values against the BRDF, reciprocity, the sigma = 0 limit,
the fitted variant, the EXR round trip and the metadata."""

import json

import numpy as np
import pytest

from lutbake.errors import ConfigError
from lutbake.integrands import diffuse as D
from lutbake.io.exr import read_exr, write_exr

BTF = {"name": "b", "kind": "btf", "size": [5, 5], "phi_size": 3, "sigma_size": 2}


@pytest.fixture(scope="module")
def cosines(bake):
    return bake(BTF, parametrisation="cosines", samples=8)


def test_shape_and_axes(cosines):
    assert cosines.data.shape == (2, 15, 5, 1)  # sigma parts, phi blocks x NoV rows, NoL columns
    assert [(a.name, a.dim) for a in cosines.axes] == [
        ("sigma", "z"),
        ("cos_phi", "y_block"),
        ("NoV", "y"),
        ("NoL", "x"),
    ]
    assert json.loads(cosines.attributes["sigma_values"]) == pytest.approx([0.25, 0.75])


def test_texels_are_the_brdf_at_their_directions(cosines):
    sig, cphi, nov, nol = (a.values().astype(np.float64) for a in cosines.axes)
    k, p, iv, il = 1, 2, 3, 0
    cl, cv, cp = nol[il], nov[iv], cphi[p]
    sl, sv, sp = np.sqrt(1 - cl * cl), np.sqrt(1 - cv * cv), np.sqrt(1 - cp * cp)
    f = D.eval_brdf("microfacet", np.array([[sl * cp, sl * sp, cl]]), np.array([[sv, 0, cv]]), sig[k], order=8)
    assert cosines.data[k, p * 5 + iv, il, 0] == pytest.approx(f[0], rel=1e-6)


def test_every_block_is_symmetric_reciprocity(cosines):
    d = cosines.data[..., 0].reshape(2, 3, 5, 5)
    np.testing.assert_allclose(d, d.transpose(0, 1, 3, 2), rtol=1e-5, atol=1e-7)


def test_sigma_0_slice_is_lambert_times_eq6(bake):
    t = bake(
        BTF, parametrisation="angles", sigma_range=[0.0, 0.0], sigma_size=1, f0=0.04, size=[4, 4], phi_size=2, workers=1
    )
    tl, tv = (np.cos(a.values().astype(np.float64)) for a in (t.axes[3], t.axes[2]))
    w = lambda c: 1 - (1 - c) ** 5  # noqa: E731
    ref = 1.05 * 0.96 * w(tv)[:, None] * w(tl)[None, :] / np.pi
    for p in range(2):  # no dependence on phi at sigma = 0
        np.testing.assert_allclose(t.data[0, p * 4 : (p + 1) * 4, :, 0], ref, rtol=2e-4)


def test_fitted_variant_is_eq8_and_differs_from_the_integral(cosines, bake):
    t = bake(BTF, parametrisation="cosines", model="fitted", workers=1)
    assert t.attributes["estimator"] == "closed_form" and "error_estimate" not in t.attributes
    rel = np.abs(t.data - cosines.data) / cosines.data.max()
    assert 1e-3 < rel.max() < 1.0  # close (the fit), not equal


def test_exr_round_trip_has_a_part_per_sigma_slice(cosines, tmp_path):
    p = write_exr(cosines, tmp_path / "b.exr")
    data, attrs = read_exr(p)
    np.testing.assert_array_equal(data, cosines.data)
    axes = json.loads(attrs["axes"])
    assert [a["dim"] for a in axes] == ["z", "y_block", "y", "x"] and "row blocks" in axes[1]["image"]
    assert attrs["parametrisation"] == "cosines" and float(attrs["error_estimate"]) < 1e-4


def test_too_many_texels_is_rejected(spec):
    with pytest.raises(ConfigError, match="phi_size"):
        spec(BTF, size=[1024, 1024], phi_size=1024, sigma_size=64)


def test_explicit_sigma_values_make_a_listed_axis(tmp_path, bake):
    t = bake(BTF, model="fitted", sigma_values=[0.0, 0.3, 0.35], workers=1)
    assert t.data.shape == (3, 15, 5, 1)
    assert t.axes[0].mapping == "listed"
    np.testing.assert_allclose(t.axes[0].values(), [0.0, 0.3, 0.35], rtol=1e-7)
    data, attrs = read_exr(write_exr(t, tmp_path / "b.exr"))
    ax = json.loads(attrs["axes"])[0]
    assert ax["mapping"] == "listed" and ax["values"] == pytest.approx([0.0, 0.3, 0.35])
    assert json.loads(attrs["sigma_values"]) == pytest.approx([0.0, 0.3, 0.35])


@pytest.mark.parametrize(
    "bad, fragment",
    [
        ([0.3, 0.2], "increasing"),
        ([0.1, 1.5], "<= 1"),
        ([], "list of 1"),
        ([0.1, "x"], "list of 1"),
        (0.5, "list of 1"),
        ([0.1, float("nan")], "finite"),
    ],
)
def test_bad_sigma_values_are_rejected(bad, fragment, spec):
    with pytest.raises(ConfigError, match=fragment):
        spec(BTF, sigma_values=bad)
