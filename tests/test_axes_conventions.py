"""Axis-convention keys of kind dfg: axis order, row order, NoV / roughness mappings, NoV clamp, and
the texture coordinate each axis records for shaders (uv)."""

import json

import numpy as np
import pytest

from lutbake.axes import Axis
from lutbake.errors import ConfigError

BASE = {"name": "t", "kind": "dfg", "size": [8, 6], "samples": 48}


@pytest.fixture(scope="module")
def default(bake):
    return bake(BASE)


def test_defaults_keep_nov_columns_and_smooth_first_row(default):
    assert [(a.name, a.dim, a.order, a.mapping) for a in default.axes] == [
        ("perceptual_roughness", "y", "lo_first", "linear"),
        ("NoV", "x", "lo_first", "linear"),
    ]


def test_roughness_x_transposes_the_table(default, bake):
    t = bake(BASE, axis_order="roughness_x")
    assert [(a.name, a.dim) for a in t.axes] == [("NoV", "y"), ("perceptual_roughness", "x")]
    np.testing.assert_array_equal(t.data, default.data.transpose(1, 0, 2))


def test_hi_first_flips_rows(default, bake):
    t = bake(BASE, row_order="hi_first")
    np.testing.assert_array_equal(t.data, default.data[::-1])
    np.testing.assert_allclose(t.axes[0].values()[0], 1 - 0.5 / 6, rtol=1e-6)


def test_blender_nov_mapping_one_minus_t2_with_clamp():
    ax = Axis("NoV", "y", 64, texel="endpoint", mapping="one_minus_t2", clamp=(1e-4, 0.9999))
    v = np.arange(64) / 63
    np.testing.assert_allclose(ax.values(), np.clip(1 - v * v, 1e-4, 0.9999), rtol=1e-6)
    # Blender's runtime lookup: uv = sqrt(1 - NoV) * 63/64 + 0.5/64 hits the texel centres
    inner = ax.values()[1:-1]
    np.testing.assert_allclose(ax.uv(inner) * 64, np.arange(1, 63) + 0.5, atol=1e-4)


def test_filament_texel_offset_rows():
    ax = Axis("perceptual_roughness", "y", 128, mapping="texel_offset", order="hi_first")
    y = np.arange(128)
    np.testing.assert_allclose(ax.values(), np.clip((128 - y + 0.5) / 128, 0, 1), rtol=1e-6)
    assert ax.values()[0] == 1.0 and ax.values()[1] == np.float32(127.5 / 128)
    # the corrected lookup for such a table: u = 1 - (r - 1/128), row y centre at (y + 0.5)/128
    np.testing.assert_allclose(ax.uv(ax.values()[1:]) * 128, y[1:] + 0.5, atol=1e-4)


def test_conventions_are_in_the_axes_metadata(bake):
    t = bake(BASE, axis_order="roughness_x", texel="endpoint", nov_mapping="one_minus_t2", nov_clamp=[1e-4, 0.9999])
    d = t.axes[0].describe()
    assert json.loads(json.dumps(d)) == d  # the lutbake:axes entry is plain JSON
    assert d["mapping"] == "one_minus_t2" and d["clamp"] == [1e-4, 0.9999] and d["order"] == "lo_first"
    assert "sqrt(1 - x)" in d["uv_formula"]


def test_texel_offset_needs_texel_centres(spec):
    with pytest.raises(ConfigError, match="texel_offset"):
        spec(BASE, roughness_mapping="texel_offset", texel="endpoint")


def test_three_channel_layouts_extend_the_two_channel_ones(default, bake):
    f82 = bake(BASE, layout="scale_bias_f82")
    np.testing.assert_allclose(f82.data[..., :2], default.data, atol=1e-6)
    assert list(f82.channels) == ["scale", "bias", "f82"]
    assert np.all(f82.data[..., 2] >= 0) and np.all(f82.data[..., 2] < 0.1)
    # to the default tolerance (1e-6 each): the cloth layout's Charlie channel adds panels graded towards theta_h = pi/2
    # (lutbake.sampling.horizon.next_toward), so at a fixed low order its GGX channels sit on other nodes
    adaptive = {k: v for k, v in BASE.items() if k != "samples"}
    cloth = bake(adaptive, layout="multiscatter_cloth")
    ms = bake(adaptive, layout="multiscatter")
    np.testing.assert_allclose(cloth.data[..., :2], ms.data, atol=2e-6)
    assert np.all(cloth.data[..., 2] > 0)  # the Charlie cloth integral (bake_table already rejects NaN/Inf)


def test_axis_metadata_round_trips_through_the_preview_reader():
    """An axis rebuilt from its lutbake:axes entry (as `lutbake preview` does) has the same values and uv."""
    import numpy as np

    from lutbake.axes import Axis
    from lutbake.io.readers import axis_from_meta

    for a in (
        Axis("NoV", "y", 8, texel="endpoint", mapping="one_minus_t2", order="hi_first", clamp=(1e-4, 0.9999)),
        Axis("perceptual_roughness", "x", 16, mapping="texel_offset"),
        Axis("sigma", "z", 3, 0.1, 0.9, mapping="listed", listed=(0.1, 0.3, 0.9)),
    ):
        b = axis_from_meta(a.describe())
        np.testing.assert_array_equal(b.values(), a.values())
        x = np.linspace(0.0, 1.0, 11)
        np.testing.assert_allclose(b.uv(x), a.uv(x))
        assert (b.order, b.clamp, b.mapping) == (a.order, a.clamp, a.mapping)
