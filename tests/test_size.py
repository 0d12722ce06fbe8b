"""lutbake size: bilinear reconstruction between texels, storage rounding, and the resolution search."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.ndimage import map_coordinates

from lutbake.cli import main
from lutbake.commands.reference import conventions
from lutbake.commands.size import axis_at, bilinear_half, measure, smallest_sizes, store

SMOOTH_NOV = 0.3  # away from the grazing corner the DFG is smooth: bilinear error ~ h^2
H2_RATIO_MIN = 3.0  # error ratio per doubling of N there (4 in the limit)


def test_bilinear_half_equals_scipy_linear_interpolation():
    rng = np.random.default_rng(1)
    t = rng.random((5, 7, 2))
    yy, xx = np.meshgrid(np.arange(9) / 2.0, np.arange(13) / 2.0, indexing="ij")
    for c in range(2):
        ref = map_coordinates(t[..., c], [yy, xx], order=1)
        np.testing.assert_allclose(bilinear_half(t)[..., c], ref, rtol=0, atol=1e-15)


def test_store_rounds_to_the_format():
    v = np.array([0.0, 0.3, 0.5, 1.0, 1.2])
    np.testing.assert_allclose(store(v, "unorm8"), np.round(np.clip(v, 0, 1) * 255) / 255)
    assert np.max(np.abs(store(v, "unorm16") - np.clip(v, 0, 1))) <= 0.5 / 65535 + 1e-15
    np.testing.assert_array_equal(store(v, "f16"), v.astype(np.float16).astype(np.float64))
    with pytest.raises(ValueError, match="unorm8"):
        store(v, "bc6h")


def test_axis_at_integer_indices_are_the_texel_values():
    conv = conventions(preset="filament", shape=(16, 16))
    for a in conv.axes:
        np.testing.assert_allclose(axis_at(a, np.arange(a.count)), a.values(), rtol=1e-6, atol=1e-7)


def test_error_away_from_grazing_falls_as_h_squared():
    e16 = measure({"preset": "default"}, 16, nov_min=SMOOTH_NOV)["f32"]
    e32 = measure({"preset": "default"}, 32, nov_min=SMOOTH_NOV)["f32"]
    assert e16 / e32 >= H2_RATIO_MIN, (e16, e32)


def test_unorm8_never_beats_its_rounding():
    r = smallest_sizes({"preset": "default"}, 1e-3, sizes=(8, 16), nov_min=SMOOTH_NOV)
    assert r.smallest["unorm8"] is None
    for n in r.errors:
        assert r.errors[n]["unorm8"] >= r.errors[n]["f32"] - 0.5 / 255


def test_cli_size_json():
    res = CliRunner().invoke(main, ["size", "--max-error", "0.05", "--sizes", "8,16", "--json"])
    assert res.exit_code == 0, res.output
    doc = json.loads(res.output)
    assert doc["smallest"]["f32"] in (8, 16)
    res = CliRunner().invoke(main, ["size", "--max-error", "0", "--sizes", "8"])
    assert res.exit_code == 2


@pytest.mark.parametrize(
    "args, option",
    [
        (["size", "--max-error", "nan"], "--max-error"),
        (["size", "--max-error", "inf"], "--max-error"),
        (["size", "--max-error", "-1e-3"], "--max-error"),
        (["size", "--max-error", "1e-3", "--nov-min", "nan"], "--nov-min"),
        (["size", "--max-error", "1e-3", "--nov-min", "-inf"], "--nov-min"),
        (["size", "--max-error", "1e-3", "--nov-min", "1.5"], "--nov-min"),
        (["audit", "missing.exr", "--tolerance", "nan"], "--tolerance"),
        (["audit", "missing.exr", "--tolerance", "inf"], "--tolerance"),
        (["audit", "missing.exr", "--tolerance", "-1"], "--tolerance"),
    ],
)
def test_every_float_option_refuses_nan_inf_and_out_of_range(args, option):
    """`size --max-error nan` was accepted (NaN compares false: never met, never refused); the same for each float
    option of the CLI: exit 2 naming the option, before any table is measured."""
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 2, res.output
    assert f"Invalid value for '{option}'" in res.output and args[-1] in res.output
