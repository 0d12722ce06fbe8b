"""lutbake preview: a picture that fits every kind (1D curves, 3D slice grids labelled with their z value, btf
light x view images per sigma and phi), readable titles, and spheres shaded with the table's own
reconstruction (through its axes' uv), omitted where a kind has none."""

import json

import numpy as np
import pytest

from lutbake.axes import Axis
from lutbake.io.formats import write_table
from lutbake.io.readers import read_table
from lutbake.table import Table

plt = pytest.importorskip("matplotlib.pyplot")
from lutbake.commands.preview import figure, lookup, sphere, split_sum  # noqa: E402

LOOKUP_TOL = 1e-6  # float32 table values, float64 interpolation weights


def make(tmp_path, kind, data, axes, channels, terms=None, name="t"):
    t = Table(
        name,
        kind,
        np.asarray(data, np.float32),
        axes,
        channels,
        "see docs",
        {"terms": json.dumps(terms or {}), "estimator": "gauss_legendre", "samples": "432"},
    )
    return write_table(t, tmp_path, "exr")


def titles(fig):
    return [t for ax in fig.axes for t in (ax.get_title(), ax.get_title(loc="left")) if t]


def test_lookup_reproduces_a_linear_table_through_nonlinear_flipped_axes():
    """A table linear in its axis values is reconstructed exactly between texel centres, whatever the
    texel convention, mapping and row order (the sphere row depends on it)."""
    ay = Axis("NoV", "y", 9, texel="endpoint", mapping="one_minus_t2", order="hi_first")
    ax = Axis("perceptual_roughness", "x", 7, mapping="linear")
    data = (2.0 * ay.values()[:, None] + 3.0 * ax.values()[None, :])[..., None]
    # the exact linear function at texel centres; in between, bilinear in uv, so sample at texel centres
    # of both axes and at points where only the linear axis varies
    nov = ay.values()[[1, 4, 6]].astype(np.float64)
    r = np.array([0.2, 0.5, 0.77])
    got = lookup(data, [ay, ax], {"NoV": nov, "perceptual_roughness": r})[..., 0]
    np.testing.assert_allclose(got, 2.0 * nov + 3.0 * r, atol=LOOKUP_TOL)


def test_charlie_spheres_use_the_sheen_channel_and_are_not_black(tmp_path):
    axes = [Axis("alpha", "y", 6), Axis("NoV", "x", 8)]
    data = np.zeros((6, 8, 3))
    data[..., 2] = 0.6  # lut_charlie: R = G = 0, B = the sheen DV
    p = make(tmp_path, "dfg", data, axes, {"zero_r": "0", "zero_g": "0", "charlie_dv": "sheen"}, {"layout": "charlie"})
    how, E, broad = split_sum(read_table(p))
    assert "B" in how and broad
    img = sphere(E, 0.5, 1.0, size=32)
    centre = img[12:20, 12:20].mean()
    assert centre > 0.3, centre  # 0 (black) before: the scale/bias formula read R and G
    data[..., 2] = 0.0
    p = make(tmp_path, "dfg", data, axes, {"zero_r": "0", "zero_g": "0", "charlie_dv": "sheen"}, {"layout": "charlie"})
    assert sphere(split_sum(read_table(p))[1], 0.5, 1.0, size=32)[12:20, 12:20].max() == 0.0


def test_spheres_follow_each_layouts_reconstruction(tmp_path):
    axes = [Axis("perceptual_roughness", "y", 4), Axis("NoV", "x", 4)]
    data = np.stack([np.full((4, 4), 0.25), np.full((4, 4), 0.5)], -1)
    f0 = np.array([1.0, 0.71, 0.29])
    nov, r = np.array([0.5]), np.array([0.5])
    cases = {"scale_bias": f0 * 0.25 + 0.5, "multiscatter": (1 - f0) * 0.25 + f0 * 0.5}
    for layout, want in cases.items():
        p = make(tmp_path, "dfg", data, axes, {"a": "a", "b": "b"}, {"layout": layout}, name=layout)
        np.testing.assert_allclose(split_sum(read_table(p))[1](nov, r)[0], want, atol=LOOKUP_TOL)


@pytest.mark.parametrize("kind,layout", [("albedo", None), ("diffuse", None), ("dfg", "sheen_albedo")])
def test_kinds_without_a_split_sum_get_no_sphere_row_and_say_so(tmp_path, kind, layout):
    axes = [Axis("perceptual_roughness" if kind != "diffuse" else "sigma", "y", 4), Axis("NoV", "x", 5)]
    nch = 2 if layout else 1
    p = make(
        tmp_path,
        kind,
        np.full((4, 5, nch), 0.5),
        axes,
        {f"c{i}": "x" for i in range(nch)},
        {"layout": layout} if layout else {},
    )
    assert split_sum(read_table(p)) is None
    fig = figure(p)
    assert "no sphere row" in fig.get_suptitle() and len(fig.axes) == 2 * nch  # images + colour bars
    plt.close(fig)


def test_1d_table_is_a_curve(tmp_path):
    ax = Axis("perceptual_roughness", "x", 16)
    p = make(tmp_path, "albedo_avg", np.linspace(1, 0.5, 16)[None, :, None], [ax], {"e_avg": "E_avg"})
    fig = figure(p)
    (line,) = fig.axes[0].get_lines()
    np.testing.assert_allclose(line.get_xdata(), ax.values())
    np.testing.assert_allclose(line.get_ydata(), np.linspace(1, 0.5, 16), atol=1e-6)
    plt.close(fig)


def test_3d_table_is_a_grid_of_slices_labelled_with_their_z_value(tmp_path):
    axes = [Axis("f0", "z", 4, 0.0, 1.0), Axis("perceptual_roughness", "y", 5), Axis("NoV", "x", 6)]
    p = make(
        tmp_path,
        "specular_3d",
        np.random.default_rng(1).random((4, 5, 6, 1)),
        axes,
        {"e": "E"},
        {"fresnel": "dielectric_f0"},
    )
    fig = figure(p)
    labels = titles(fig)
    for k, v in enumerate(axes[0].values()):
        assert any(f"f0 = {v:.3g}  (slice {k})" in t for t in labels), (k, labels)
    assert "spheres" in " ".join(sf.get_suptitle() for sf in fig.subfigs)  # specular_3d has a reconstruction
    plt.close(fig)


def test_btf_is_light_by_view_images_per_sigma_and_phi(tmp_path):
    axes = [
        Axis("sigma", "z", 3, 0.0, 1.0),
        Axis("phi", "y_block", 4, 0.0, np.pi),
        Axis("theta_v", "y", 5, 0.0, np.pi / 2),
        Axis("theta_l", "x", 6, 0.0, np.pi / 2),
    ]
    p = make(tmp_path, "btf", np.random.default_rng(2).random((3, 20, 6, 1)), axes, {"f": "BRDF"})
    fig = figure(p)
    images = [ax for ax in fig.axes if ax.get_images()]
    assert len(images) == 3 * 4
    assert all(ax.get_images()[0].get_array().shape == (5, 6) for ax in images)  # theta_v up, theta_l across
    labels = titles(fig)
    assert any("σ = 0.5" in t and "φ = 1.18 rad" in t for t in labels), labels
    assert images[-1].get_xlabel().startswith("θ_l") and images[0].get_ylabel().startswith("θ_v")
    plt.close(fig)


def test_titles_are_words_not_json(tmp_path):
    axes = [Axis("perceptual_roughness", "y", 4), Axis("NoV", "x", 4)]
    data = np.random.default_rng(3).random((4, 4, 2))
    p = make(
        tmp_path,
        "dfg",
        data,
        axes,
        {"scale": "multiplies f0", "bias": "added"},
        {"ndf": "ggx", "masking": "smith_height_correlated", "layout": "scale_bias"},
    )
    fig = figure(p)
    title = fig.get_suptitle()
    assert "{" not in title and '"' not in title
    assert "ndf ggx" in title and "masking smith_height_correlated" in title and "samples 432 per texel" in title
    assert any(t.startswith("R = scale\nmultiplies f0") for t in titles(fig)), titles(fig)
    plt.close(fig)


def test_a_table_without_lutbake_metadata_is_drawn_by_index(tmp_path):
    from test_formats import table2d

    from lutbake.io.integrity import sidecar_path

    p = write_table(table2d(4, h=8, w=6), tmp_path, "dds")
    sidecar_path(p).unlink()
    fig = figure(p)
    assert "no lutbake metadata" in fig.get_suptitle() and fig.axes[0].get_xlabel() == "x index"
    plt.close(fig)


LTC_MEANINGS = {
    "x": "slice 0 (ltc_1): M^-1_00 / M^-1_11; slice 1 (ltc_2): magnitude = ∫ f (n.l) dω_l with F = 1 (fit = shaded: "
    "fitted with the matrix)",
    "y": "slice 0: M^-1_20 / M^-1_11 (glm invM[0][2]); slice 1: fresnel = ∫ f (1 - v.h)^5 (n.l) dω_l (= magnitude for "
    "lobes without Fresnel)",
    "z": "slice 0: M^-1_02 / M^-1_11 (glm invM[2][0]); slice 1: fit_error = (E / ∫ f^3 dω)^(1/3), E = Heitz's L3 "
    "metric of the fit (0 in engine layouts)",
    "w": "slice 0: M^-1_22 / M^-1_11; slice 1: sphere = horizon-clipped / unclipped form factor of a spherical cap, at "
    "x = z * 0.5 + 0.5, y = len (own axes, endpoint texels)",
}


def ltc_table(tmp_path, n=16):
    """An LTC table as the engine layouts hold one: matrix entries from about 1 up to FP16's 65504 (HDRP's smooth
    grazing texels), and ltc_2's channels in [0, 1]."""
    rng = np.random.default_rng(3)
    data = rng.random((2, n, n, 4))
    data[0] = 10.0 ** (rng.random((n, n, 4)) * 4.8)  # 1 ... 65504: decades
    data[0, -1, 0, :] = 65504.0
    axes = [
        Axis("texture", "z", 2, 1.0, 2.0, texel="endpoint"),
        Axis("NoV", "y", n, texel="endpoint", mapping="one_minus_t2"),
        Axis("perceptual_roughness", "x", n, texel="endpoint"),
    ]
    return make(tmp_path, "ltc", data, axes, LTC_MEANINGS, {"lobe": "ggx"}, name="ltc")


@pytest.fixture(scope="module")
def ltc_figure(tmp_path_factory):
    """The preview of ltc_table, laid out once (drawn) for the three tests below."""
    fig = figure(ltc_table(tmp_path_factory.mktemp("ltc"), n=8))
    fig.canvas.draw()
    yield fig
    plt.close(fig)


def panel(fig, start):
    """The Axes whose (left) title starts with ``start``, and its image."""
    (ax,) = [a for a in fig.axes if a.get_title(loc="left").startswith(start) and a.get_images()]
    return ax, ax.get_images()[0]


def test_ltc_matrix_entries_spanning_decades_get_a_log_colour_scale(ltc_figure):
    """Matrix entries from 1 to 65504 on a linear scale were one flat colour; on the symmetric log scale the
    texels keep their order and most of them a colour of their own."""
    from matplotlib.colors import SymLogNorm

    fig = ltc_figure
    ax, im = panel(fig, "R (.x): M^-1_00")
    values = np.asarray(im.get_array())
    assert isinstance(im.norm, SymLogNorm) and "log colour scale" in ax.get_title(loc="left")
    colours = np.unique(np.round(im.norm(values.ravel()) * 255))
    assert len(colours) >= 0.5 * min(values.size, 256), len(colours)
    _, magnitude = panel(fig, "R (.x): magnitude")
    assert not isinstance(magnitude.norm, SymLogNorm)  # ltc_2 in [0, 1]: linear


def test_ltc_titles_do_not_overlap(ltc_figure):
    """No title (panel titles, the textures' row titles) overlaps another title or another panel."""
    fig = ltc_figure
    renderer = fig.canvas.get_renderer()
    texts = [t for ax in fig.axes for t in (ax.title, ax._left_title) if t.get_text()]
    texts += [sf._suptitle for sf in getattr(fig, "subfigs", []) if sf._suptitle is not None]
    boxes = [t.get_window_extent(renderer) for t in texts]
    for i, a in enumerate(boxes):
        for j in range(i + 1, len(boxes)):
            assert not a.overlaps(boxes[j]), (texts[i].get_text()[:40], texts[j].get_text()[:40])
    panels = [ax.get_window_extent(renderer) for ax in fig.axes if ax.get_images()]
    for t, box in zip(texts, boxes):
        assert not any(box.overlaps(p) for p in panels), t.get_text()[:40]


def test_ltc_sphere_channel_is_drawn_on_its_own_axes(ltc_figure):
    """ltc_2's sphere channel is indexed by (z * 0.5 + 0.5, len), not by (roughness, NoV): its panel's ticks run over
    z in [-1, 1] and len in [0, 1], the other panels' over the table's axes."""
    fig = ltc_figure
    ax, _ = panel(fig, "A (.w): sphere")
    assert ax.get_xlabel().startswith("z = cos elevation") and ax.get_ylabel().startswith("len = |F|")
    assert [t.get_text() for t in ax.get_xticklabels()][::3] == ["-1", "1"]
    assert [t.get_text() for t in ax.get_yticklabels()][::3] == ["0", "1"]
    other, _ = panel(fig, "R (.x): magnitude")
    assert other.get_xlabel().startswith("perceptual roughness")
