"""lutbake reads back the values of the files it writes in an engine's own layout (LTC modules and textures, the
OpenPBR header, JS / WGSL / Rust arrays), shaped by their sidecar, exactly as stored (lutbake.io.engine_files)."""

import json

import numpy as np
import pytest
from test_formats import table2d

from lutbake.axes import Axis
from lutbake.io.formats import write_table
from lutbake.io.ltc import hdrp_fp16
from lutbake.io.openpbr import METAL_SLICE, unorm16
from lutbake.io.readers import read, read_table
from lutbake.io.sidecar import ReadError
from lutbake.table import Table

LTC_SIZE = (5, 4)  # view x roughness: not square, so a transposed read would fail


def ltc_table() -> Table:
    rng = np.random.default_rng(12)
    data = rng.uniform(-1.0, 1.0, (2, *LTC_SIZE, 4)).astype(np.float32)
    data[0, ..., 3] = rng.uniform(0.5, 1.5, LTC_SIZE)  # M^-1_22 / M^-1_11 > 0 (HDRP divides by it)
    axes = [
        Axis("texture", "z", 2, 1.0, 2.0, texel="endpoint", mapping="listed", listed=(1.0, 2.0)),
        Axis("NoV", "y", LTC_SIZE[0], 0.0, 1.0, texel="endpoint", mapping="one_minus_t2"),
        Axis("perceptual_roughness", "x", LTC_SIZE[1], 0.0, 1.0, texel="endpoint"),
    ]
    chans = {c: f"channel {c}" for c in "xyzw"}
    return Table("ltc_t", "ltc", data, axes, chans, "ltc", {"terms": json.dumps({"lobe": "ggx"})})


def engine_ltc(data: np.ndarray) -> np.ndarray:
    """What every LTC engine layout stores: ltc_2.z (the fit error) = 0."""
    out = data.copy()
    out[1, ..., 2] = 0.0
    return out


@pytest.mark.parametrize(("fmt", "dtype"), [("js", "float32"), ("c", "float32"), ("ltc_dds", "half")])
def test_ltc_engine_layouts_read_back_as_the_two_textures(tmp_path, fmt, dtype):
    table = ltc_table()
    path = write_table(table, tmp_path, fmt, dtype)
    expected = engine_ltc(table.data).astype(np.float16 if dtype == "half" else np.float32)
    for p in (path, path.with_name(path.name + ".json")):
        view = read_table(p)
        assert view.kind == "ltc" and view.data.shape == (2, *LTC_SIZE, 4), p
        np.testing.assert_array_equal(view.data, expected.astype(np.float32))


def test_babylon_ltc_is_babylons_eight_halfs_per_texel_and_reads_back_through_its_sidecar(tmp_path):
    """areaLightsLTC.bin: texel by texel (row t, column roughness) 4 FP16 of ltc_1 then 4 of ltc_2, as Babylon's
    DecodeLTCTextureDataAsync splits them; no magic bytes, so lutbake reads it through its sidecar."""
    table = ltc_table()
    path = write_table(table, tmp_path, "babylon_ltc", "float32")  # always FP16, as Babylon uploads it
    expected = engine_ltc(table.data).astype(np.float16)
    raw = np.frombuffer(path.read_bytes(), "<f2").reshape(*LTC_SIZE, 8)
    np.testing.assert_array_equal(raw[..., :4], expected[0])
    np.testing.assert_array_equal(raw[..., 4:], expected[1])
    view = read_table(path.with_name(path.name + ".json"))
    assert view.kind == "ltc" and view.data.shape == (2, *LTC_SIZE, 4)
    np.testing.assert_array_equal(view.data, expected.astype(np.float32))
    with pytest.raises(ReadError, match="not a format lutbake reads"):
        read_table(path)


def test_hdrp_cs_reads_back_as_hdrps_texel_with_its_own_channels(tmp_path):
    table = ltc_table()
    view = read_table(write_table(table, tmp_path, "cs", "half"))
    np.testing.assert_array_equal(view.data, hdrp_fp16(table.data[0]).astype(np.float32))
    assert [a.name for a in view.axes] == ["NoV", "perceptual_roughness"]
    assert view.channel_names == ["m00_over_m22", "m20_over_m22", "m11_over_m22", "m02_over_m22"]


def openpbr_table(avg: bool) -> Table:
    rng = np.random.default_rng(5)
    shape = (32, 32) if avg else (32, 32, 32)
    data = rng.random((*shape, 3)).astype(np.float32)
    data[..., 2] = data[METAL_SLICE, ..., 2]  # the metal channel does not depend on the IOR (z, or rows for avg)
    names = ["ior", "perceptual_roughness"] + ([] if avg else ["NoV"])
    axes = [Axis(n, d, 32) for n, d in zip(names, ("y", "x") if avg else ("z", "y", "x"))]
    word = "_average" if avg else ""
    chans = {f"{k}{word}_energy_complement": k for k in ("ideal_dielectric", "opaque_dielectric", "ideal_metal")}
    return Table("opbr", "dielectric_avg" if avg else "dielectric", data, axes, chans, "openpbr", {})


@pytest.mark.parametrize("avg", [False, True])
def test_openpbr_header_reads_back_as_unorm16_values(tmp_path, avg):
    table = openpbr_table(avg)
    path = write_table(table, tmp_path, "openpbr_h")
    view = read_table(path)
    np.testing.assert_array_equal(view.data, (unorm16(table.data) / 65535.0).astype(np.float32))
    assert read(path).format == "engine" and "UNORM16" in read(path).facts["engine_values"]


@pytest.mark.parametrize("fmt", ["js", "wgsl", "rs"])
@pytest.mark.parametrize("dtype", ["float32", "half"])
def test_code_arrays_read_back_as_stored(tmp_path, fmt, dtype):
    table = table2d(2)
    view = read_table(write_table(table, tmp_path, fmt, dtype))
    expected = table.data.astype(np.float16 if dtype == "half" else np.float32).astype(np.float32)
    np.testing.assert_array_equal(view.data, expected)


def test_an_engine_file_whose_values_do_not_fit_its_sidecar_is_read_as_metadata_with_the_reason(tmp_path):
    path = write_table(ltc_table(), tmp_path, "js")
    path.write_text(path.read_text().replace("LTC_MAT_2", "LTC_MAT_X"))
    loaded = read(path)
    assert loaded.data is None and "no array 'LTC_MAT_2'" in loaded.notes[0]
