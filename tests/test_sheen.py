"""KHR_materials_sheen tables: dfg layouts `charlie` (the glTF Sample Viewer's lut_charlie) and `sheen_albedo`
(the spec's albedo-scaling E), and the presets gltf-charlie / gltf-sheen-e.

The baked channels are checked against an independent converged quadrature over l in numpy (the terms
written out again from the KHR spec's GLSL, not lutbake's @wp.funcs): conftest.integrate_charlie."""

import numpy as np
import pytest

from lutbake.config import load_config, presets
from lutbake.errors import ConfigError
from lutbake.validate.checks import CHECKS

# Baked channel vs the converged graded reference (conftest.integrate_charlie), relative: lutbake's own
# quadrature error plus float32 storage. Measured worst over the texels below: 7.3e-6 (charlie, sheen E
# with Ashikhmin V), 6.0e-6 (sheen E with the Charlie V); the clamped layouts 1.4e-5 / 2.4e-5 (the kink of
# min(V, 1) lies inside a panel of the table's Gauss-Legendre rule; the reference has a panel break there).
CHANNEL_RTOL = 2e-5
CLAMPED_RTOL = 5e-5  # was 1e-4 against a 3000x3000 midpoint rule (itself within 1e-6 of the reference there)

TEXELS = [(0, 0), (0, 5), (5, 0), (16, 16), (31, 0), (31, 31), (10, 25)]  # (row = alpha, column = NoV) of 32²


@pytest.fixture(scope="module")
def sheen_e(bake_preset):
    return bake_preset("gltf-sheen-e", "size=[32, 32]")


@pytest.fixture(scope="module")
def charlie(bake_preset):
    return bake_preset("gltf-charlie", "size=[32, 32]")


def test_presets_exist_with_the_viewer_axes(charlie, sheen_e):
    assert {"gltf-charlie", "gltf-sheen-e"} <= set(presets())
    for (spec, table), nch in ((charlie, 3), (sheen_e, 2)):
        rough, nov = table.axes
        assert table.data.shape == (32, 32, nch)
        assert (rough.name, rough.dim, nov.name, nov.dim) == ("alpha", "y", "NoV", "x")
        centres = (np.arange(32) + 0.5) / 32
        np.testing.assert_allclose(nov.values(), centres, rtol=1e-6)
        np.testing.assert_allclose(rough.values(), centres, rtol=1e-6)  # y = sheenRoughness = alpha, row 0 smooth
        np.testing.assert_allclose(rough.alpha(), centres, rtol=1e-6)
        assert spec.options["format"] == "exr" and spec.options["estimator"] == "gauss_legendre"
    assert np.all(charlie[1].data[..., :2] == 0)  # the viewer's lut_charlie: value in .b


@pytest.mark.parametrize(
    "preset, channel, visibility", [("charlie", 2, "ashikhmin"), ("sheen_e", 0, "charlie"), ("sheen_e", 1, "ashikhmin")]
)
def test_channel_agrees_with_an_independent_quadrature(request, charlie_reference, preset, channel, visibility):
    """lut_charlie .b = ∫ D_charlie V_Ashikhmin (n.l); sheen E = the same with the spec's Charlie visibility
    (channel 0) and with Ashikhmin's (channel 1)."""
    _, table = request.getfixturevalue(preset)
    rough, nov = table.axes
    for y, x in TEXELS:
        a, c = float(rough.alpha()[y]), float(nov.values()[x])
        np.testing.assert_allclose(table.data[y, x, channel], charlie_reference(a, c, visibility), rtol=CHANNEL_RTOL)


def test_sheen_albedo_le_one_except_the_grazing_smooth_corner(bake_preset):
    """With the spec's Charlie visibility E <= 1 except where n.v < 0.04 and alpha < 0.06 (the preset's 64² grid):
    there the unclamped Lambda fit lets V exceed 1 (E reaches 2.19 at n.v = alpha = 1/128). With Ashikhmin's
    visibility E exceeds 1 over a larger corner (3.68 at most), as the spec warns (not energy conserving)."""
    _, table = bake_preset("gltf-sheen-e")
    rough, nov = table.axes
    E = table.data[..., 0]
    corner = (rough.alpha()[:, None] < 0.06) & (nov.values()[None, :] < 0.04)
    assert E[~corner].max() <= 1.0, E[~corner].max()
    assert 1.0 < E[corner].max() < 2.3  # documented, not hidden: measured 2.193
    assert table.data[..., 1].max() > 1.0
    assert np.all(E >= 0)


def test_sheen_layouts_reject_qmc_and_other_terms(tmp_path):
    p = tmp_path / "s.toml"
    for layout in ("charlie", "sheen_albedo"):
        for extra, key in (
            ('estimator = "sobol_vndf"', "estimator"),
            ('estimator = "hammersley_ndf"', "estimator"),
            ('ndf = "beckmann"', "layout"),
            ('model = "blinn_phong"', "layout"),
        ):
            p.write_text(f'[[table]]\nname = "s"\nkind = "dfg"\nlayout = "{layout}"\n{extra}\n')
            with pytest.raises(ConfigError) as e:
                load_config(p)
            assert key in str(e.value)
            if key == "estimator":
                assert "gauss_legendre" in str(e.value) and "Charlie" in str(e.value)


def test_charlie_projected_area_check_passes():
    r = CHECKS["ndf_projected_area_is_one[charlie]"]()
    assert r.passed, r


def test_clamped_layouts_are_the_viewers_integrand(bake_preset, charlie_reference):
    """*_clamped clamp V to [0, 1] as the viewer's V_Ashikhmin / V_Sheen: against the reference with the same
    clamp, and never above the unclamped tables (at alpha = 0.5, NoV = 0.1 the clamp removes 2.7 %)."""
    _, clamped = bake_preset("gltf-charlie", "size=[16, 16]", "layout=charlie_clamped")
    _, plain = bake_preset("gltf-charlie", "size=[16, 16]")
    _, e_clamped = bake_preset("gltf-sheen-e", "size=[16, 16]", "layout=sheen_albedo_clamped")
    assert np.all(clamped.data <= plain.data + 1e-7)
    assert clamped.data[0, 0, 2] < 0.8 * plain.data[0, 0, 2]  # the smooth grazing corner: measured -24 % at 16²
    rough, nov = clamped.axes
    for y, x in [(0, 0), (8, 1), (15, 15)]:
        a, c = float(rough.alpha()[y]), float(nov.values()[x])
        want_charlie = charlie_reference(a, c, "ashikhmin", clamp=True)
        np.testing.assert_allclose(clamped.data[y, x, 2], want_charlie, rtol=CLAMPED_RTOL)
        np.testing.assert_allclose(
            e_clamped.data[y, x, 0], charlie_reference(a, c, "charlie", clamp=True), rtol=CLAMPED_RTOL
        )
    assert e_clamped.data[..., 0].max() <= 1.0  # the clamp also removes the corner's E > 1 (measured max below)


def test_charlie_visibility_estimates_bound_their_errors(charlie_reference):
    """To a tolerance, the sheen lobe with Charlie's V (HDRP's CharlieFabricLambert FGD, the spec's E): every texel's
    error estimate bounds its error against the independent reference. Estevez & Kulla's Lambda switches formula at
    n.l = 0.5 (C1 only) and has a cusp at l = n; before the panels split there (lutbake.sampling.horizon.kink_band),
    452 of the 64² HDRP table's 12288 values exceeded their estimates, by up to 1.1e-5 (estimates ~1e-6)."""
    from lutbake.integrands.specular import specular_integrand
    from lutbake.sampling.hemisphere import AdaptiveGaussLegendre

    nov, r = (g.ravel() for g in np.meshgrid(np.linspace(0.1, 0.95, 7), np.linspace(0.15, 0.99, 7)))
    alpha = (r * r).astype(np.float32)  # HDRP's alpha = r², the range where the unsplit panels failed
    integrand = specular_integrand("ggx", "none", "sheen_albedo")
    inputs = {"nov": nov.astype(np.float32), "alpha": integrand.alpha_input(alpha), "param": np.zeros_like(alpha)}
    value, estimate = AdaptiveGaussLegendre(1e-6, 0.0).evaluate_with_error(integrand, inputs, "cpu")
    ref = np.array([charlie_reference(float(a), float(n), "charlie") for a, n in zip(alpha, inputs["nov"])])
    err = np.abs(value[:, 0] - ref)
    # every texel reaches the tolerance (D_charlie's power in float64: no 1 / (2 alpha) rounding floor), and every
    # estimate carries the float32 terms' TERMS_ROUNDING
    assert np.all(estimate[:, 0] <= 1e-6) and np.all(estimate[:, 0] >= 1e-7 * np.abs(value[:, 0]))
    np.testing.assert_array_less(err, estimate[:, 0] + 5e-8)  # 5e-8: the float32 terms' noise beyond TERMS_ROUNDING


# the worst texels of the make luts Charlie tables (estimate / tolerance before D_charlie's power went to float64:
# 3.6e3 and 30): (layout, channel, visibility, alpha, n.v); HDRP's row 0 is alpha = (1/128)^2, clamped to ALPHA_MIN
WORST_CHARLIE_TEXELS = [
    ("sheen_fgd", 1, "charlie", 1e-4, 1 / 128),  # preIntegratedFGD_CharlieFabricLambert (0, 0): G x 2 pi = 6.69
    ("sheen_fgd", 1, "charlie", 1e-4, 3 / 128),
    ("sheen_albedo", 0, "charlie", 1 / 128, 1 / 128),  # lut_sheen_E (0, 0): E = 2.19
    ("sheen_albedo", 0, "charlie", 1 / 128, 3 / 128),
    ("charlie", 2, "ashikhmin", 1 / 256, 1 / 256),  # lut_charlie (0, 0)
]
CHARLIE_TOLERANCE = 1e-6  # the presets' float32 default (lutbake.tolerance)


@pytest.mark.parametrize("layout, channel, visibility, alpha, nov", WORST_CHARLIE_TEXELS)
def test_smooth_grazing_charlie_texels_reach_the_tolerance(charlie_reference, layout, channel, visibility, alpha, nov):
    """At the smooth grazing corner (sin^(1/alpha) theta_h with 1/alpha up to 1e4) every estimate is within the
    tolerance and bounds the error against the independent l-space reference. Before: D_charlie's power of a float32
    h put 1e-7 / (2 alpha) relative into every order (estimates 3.6e-3, 3e-5), and the Lambda fit's coefficient slopes,
    computed in float32 by Warp, moved E by 1e-6 relative (errors 6.8e-6, 2.1e-6: past any estimate)."""
    from lutbake.integrands.specular import specular_integrand
    from lutbake.sampling.hemisphere import AdaptiveGaussLegendre

    integrand = specular_integrand("ggx", "none", layout)
    one = np.ones(1, np.float32)
    inputs = {"nov": nov * one, "alpha": integrand.alpha_input(alpha * one), "param": 0 * one}
    value, estimate = AdaptiveGaussLegendre(CHARLIE_TOLERANCE, 0.0).evaluate_with_error(integrand, inputs, "cpu")
    ref = charlie_reference(float(inputs["alpha"][0]), float(inputs["nov"][0]), visibility)
    assert estimate[0, channel] <= CHARLIE_TOLERANCE
    assert abs(value[0, channel] - ref) <= estimate[0, channel], (value[0, channel], ref, estimate[0, channel])
