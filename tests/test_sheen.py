"""KHR_materials_sheen tables: dfg layouts `charlie` (the glTF Sample Viewer's lut_charlie) and `sheen_albedo`
(the spec's albedo-scaling E), and the presets gltf-charlie / gltf-sheen-e.

The baked channels are checked against an independent brute-force midpoint rule over l in numpy (the
terms written out again from the KHR spec's GLSL, not lutbake's @wp.funcs)."""

import numpy as np
import pytest

from lutbake.api import bake_table
from lutbake.config import load_config, parse_overrides, preset_path, presets
from lutbake.errors import ConfigError
from lutbake.validate.checks import CHECKS


def bake_preset(name, *overrides):
    (spec,) = load_config(preset_path(name), parse_overrides(list(overrides)))
    return spec, bake_table(spec)[0]


def lambda_sheen(c, a):
    """KHR_materials_sheen README, "Sheen visibility" (Estevez & Kulla 2017 fit)."""
    t = (1 - a) ** 2
    A, B, C = 21.5473 + 3.7772 * t, 3.82987 - 0.50552 * t, 0.19823 - 0.03022 * t
    D, E = -1.97760 + 0.70367 * t, -4.32054 - 0.53913 * t

    def l(x):
        return A / (1 + B * np.abs(x) ** C) + D * x + E

    return np.where(np.abs(c) < 0.5, np.exp(l(c)), np.exp(2 * l(0.5) - l(1 - c)))


def brute_force(alpha, nov, vis, n=3000, clamp=False):
    """∫ D_charlie V (n.l) dω_l by the midpoint rule in (theta_l, phi_l in [0, pi]) x 2 (symmetry)."""
    th = (np.arange(n) + 0.5) / n * np.pi / 2
    ph = (np.arange(n) + 0.5) / n * np.pi
    T, P = np.meshgrid(th, ph, indexing="ij")
    l = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1)
    h = l + [np.sqrt(1 - nov * nov), 0, nov]
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    D = (2 + 1 / alpha) * (h[..., 0] ** 2 + h[..., 1] ** 2) ** (0.5 / alpha) / (2 * np.pi)
    nl = l[..., 2]
    if vis == "ashikhmin":
        V = 1 / (4 * (nl + nov - nl * nov))
    else:
        V = 1 / ((1 + lambda_sheen(nov, alpha) + lambda_sheen(nl, alpha)) * 4 * nov * nl)
    if clamp:
        V = np.minimum(V, 1.0)
    return 2 * np.sum(D * V * nl * np.sin(T)) * (np.pi / 2 / n) * (np.pi / n)


TEXELS = [(0, 0), (0, 5), (5, 0), (16, 16), (31, 0), (31, 31), (10, 25)]  # (row = alpha, column = NoV) of 32²


@pytest.fixture(scope="module")
def sheen_e():
    return bake_preset("gltf-sheen-e", "size=[32, 32]")


@pytest.fixture(scope="module")
def charlie():
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


def test_charlie_channel_agrees_with_an_independent_quadrature(charlie):
    _, table = charlie
    rough, nov = table.axes
    for y, x in TEXELS:
        a, c = float(rough.alpha()[y]), float(nov.values()[x])
        np.testing.assert_allclose(
            table.data[y, x, 2], brute_force(a, c, "ashikhmin"), rtol=2e-5
        )  # measured 7.2e-6 (3072 samples); the midpoint rule: 2.8e-6


def test_sheen_albedo_agrees_with_an_independent_quadrature(sheen_e):
    _, table = sheen_e
    rough, nov = table.axes
    for y, x in TEXELS:
        a, c = float(rough.alpha()[y]), float(nov.values()[x])
        np.testing.assert_allclose(table.data[y, x, 0], brute_force(a, c, "charlie"), rtol=2e-5)
        np.testing.assert_allclose(table.data[y, x, 1], brute_force(a, c, "ashikhmin"), rtol=2e-5)


def test_sheen_albedo_le_one_except_the_grazing_smooth_corner():
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


def test_clamped_layouts_are_the_viewers_integrand():
    """*_clamped clamp V to [0, 1] as the viewer's V_Ashikhmin / V_Sheen: against the brute-force rule with the
    same clamp, and never above the unclamped tables (at alpha = 0.5, NoV = 0.1 the clamp removes 2.7 %)."""
    _, clamped = bake_preset("gltf-charlie", "size=[16, 16]", "layout=charlie_clamped")
    _, plain = bake_preset("gltf-charlie", "size=[16, 16]")
    _, e_clamped = bake_preset("gltf-sheen-e", "size=[16, 16]", "layout=sheen_albedo_clamped")
    assert np.all(clamped.data <= plain.data + 1e-7)
    assert clamped.data[0, 0, 2] < 0.8 * plain.data[0, 0, 2]  # the smooth grazing corner: measured -24 % at 16²
    rough, nov = clamped.axes
    for y, x in [(0, 0), (8, 1), (15, 15)]:
        a, c = float(rough.alpha()[y]), float(nov.values()[x])
        # the clamp puts a kink (min(V, 1)) inside the domain, which neither rule resolves: measured 2.4e-5
        np.testing.assert_allclose(clamped.data[y, x, 2], brute_force(a, c, "ashikhmin", clamp=True), rtol=1e-4)
        np.testing.assert_allclose(e_clamped.data[y, x, 0], brute_force(a, c, "charlie", clamp=True), rtol=1e-4)
    assert e_clamped.data[..., 0].max() <= 1.0  # the clamp also removes the corner's E > 1 (measured max below)
