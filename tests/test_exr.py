"""EXR writer: files written through OpenImageIO, checked with the OpenEXR project's own bindings
(an independent reader), plus the round trip through read_exr, atomicity and the NaN/Inf policy."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

OpenEXR = pytest.importorskip("OpenEXR")
pytest.importorskip("OpenImageIO")

from lutbake.axes import Axis  # noqa: E402
from lutbake.io import atomic as atomic_mod  # noqa: E402
from lutbake.io import exr as exr_mod  # noqa: E402
from lutbake.io import read_exr, write_exr  # noqa: E402
from lutbake.io.describe import describe  # noqa: E402
from lutbake.io.readers import ReadError  # noqa: E402
from lutbake.table import Table  # noqa: E402

PROVENANCE = {
    "terms": json.dumps({"D": "ggx", "G": "smith_height_correlated", "F": "schlick"}),
    "estimator": "sobol_ggx_vndf",
    "samples": "1024",
    "seed": "7",
    "config": '[table]\nkind = "dfg"\nsize = [8, 4]\n',
    "version": "0.1.0",
    "warp_version": "1.9.0",
}
EXPECTED_NP = {"float32": np.float32, "half": np.float16}


def _values_2d(ny: int, nx: int, nc: int) -> np.ndarray:
    """value = 10*y + x + 0.25*c: every texel distinct, exactly representable in half, so any row
    flip, transpose or channel swap shows."""
    y, x, c = np.meshgrid(np.arange(ny), np.arange(nx), np.arange(nc), indexing="ij")
    return (10.0 * y + x + 0.25 * c).astype(np.float32)


def table_2d(nc: int = 2) -> Table:
    names = ["scale", "bias", "third", "fourth"][:nc]
    return Table(
        name="dfg_test",
        kind="dfg",
        data=_values_2d(4, 8, nc),  # 4 rows (y) x 8 columns (x)
        axes=[
            Axis("perceptual_roughness", "y", 4),
            Axis("NoV", "x", 8),
        ],
        channels={n: f"meaning of {n}" for n in names},
        reconstruction="specular = f0 * R + G",
        attributes=dict(PROVENANCE),
    )


def table_3d() -> Table:
    data = np.stack([_values_2d(4, 5, 2) + 100.0 * z for z in range(3)])  # (3, 4, 5, 2)
    return Table(
        name="spec3d_test",
        kind="specular_3d",
        data=data,
        axes=[
            Axis("f0", "z", 3, 0.0, 1.0, texel="endpoint"),
            Axis("perceptual_roughness", "y", 4),
            Axis("NoV", "x", 5),
        ],
        channels={"reflectance": "directional albedo", "aux": "second channel"},
        reconstruction="trilinear lookup in (NoV, r, f0)",
        attributes=dict(PROVENANCE),
    )


def _oexr_part_array(f, k: int, letters) -> np.ndarray:
    ch = f.channels(k)
    return np.stack([np.asarray(ch[c].pixels) for c in letters], axis=-1)


# --------------------------------------------------------------------------------- 2D, OpenEXR


@pytest.mark.parametrize("dtype", ["float32", "half"])
def test_2d_read_back_with_openexr(tmp_path, dtype):
    t = table_2d()
    out = write_exr(t, tmp_path / "dfg.exr", dtype=dtype)
    assert out == tmp_path / "dfg.exr"
    f = OpenEXR.File(str(out), separate_channels=True)
    assert len(f.parts) == 1
    assert set(f.channels().keys()) == {"R", "G"}  # 2 channels -> R, G only (no B, no A)
    for c in ("R", "G"):
        px = np.asarray(f.channels()[c].pixels)
        assert px.dtype == EXPECTED_NP[dtype]
        assert px.shape == (4, 8)  # (height = y count, width = x count)
    got = _oexr_part_array(f, 0, ["R", "G"])
    np.testing.assert_array_equal(got.astype(np.float32), t.data)  # exact: values are half-exact
    # row order: row 0 is y index 0 (no flip), column 0 is x index 0
    assert got[0, 0, 0] == 0.0 and got[3, 0, 0] == 30.0 and got[0, 7, 0] == 7.0 and got[0, 0, 1] == 0.25

    h = f.header()
    assert h["compression"] == OpenEXR.ZIP_COMPRESSION
    assert h["lutbake:kind"] == "dfg"
    assert h["lutbake:reconstruction"] == "specular = f0 * R + G"
    axes = json.loads(h["lutbake:axes"])
    assert [a["name"] for a in axes] == ["perceptual_roughness", "NoV"]
    assert [a["dim"] for a in axes] == ["y", "x"]
    np.testing.assert_allclose(axes[0]["values"], t.axes[0].values(), rtol=0, atol=0)
    np.testing.assert_allclose(axes[1]["values"], t.axes[1].values(), rtol=0, atol=0)
    assert "alpha" in axes[0] and "alpha" not in axes[1]
    ch = json.loads(h["lutbake:channels"])
    assert set(ch) == {"R", "G"}
    assert "scale" in ch["R"] and "meaning of scale" in ch["R"]
    assert "bias" in ch["G"] and "meaning of bias" in ch["G"]
    assert json.loads(h["lutbake:channel_names"]) == {"R": "scale", "G": "bias"}
    for key, value in PROVENANCE.items():
        assert h[f"lutbake:{key}"] == value


@pytest.mark.parametrize("nc", [1, 2, 3, 4])
def test_channel_names_by_count(tmp_path, nc):
    t = table_2d(nc)
    out = write_exr(t, tmp_path / "t.exr")
    f = OpenEXR.File(str(out), separate_channels=True)
    letters = ["R", "G", "B", "A"][:nc]
    assert set(f.channels().keys()) == set(letters)
    np.testing.assert_array_equal(_oexr_part_array(f, 0, letters), t.data)
    data, attrs = read_exr(out)
    np.testing.assert_array_equal(data, t.data)
    assert json.loads(attrs["channel_names"]) == dict(zip(letters, t.channels))


@pytest.mark.parametrize("dtype", ["float32", "half"])
def test_2d_round_trip_read_exr(tmp_path, dtype):
    t = table_2d()
    t.data = t.data / 7.0  # not half-exact: checks rounding, not just layout
    data, attrs = read_exr(write_exr(t, tmp_path / "dfg.exr", dtype=dtype))
    assert data.dtype == np.float32 and data.shape == (4, 8, 2)
    expected = t.data.astype(EXPECTED_NP[dtype]).astype(np.float32)  # round to nearest even
    np.testing.assert_array_equal(data, expected)
    assert attrs["kind"] == "dfg" and attrs["table"] == "dfg_test"
    for key, value in PROVENANCE.items():
        assert attrs[key] == value
    assert json.loads(attrs["axes"]) == [a.describe() for a in t.axes]
    assert not any(k.startswith("lutbake:") for k in attrs)


# --------------------------------------------------------------------------------- 3D, multi-part


@pytest.mark.parametrize("dtype", ["float32", "half"])
def test_3d_multipart_with_openexr(tmp_path, dtype):
    t = table_3d()
    out = write_exr(t, tmp_path / "spec3d.exr", dtype=dtype)
    f = OpenEXR.File(str(out), separate_channels=True)
    assert len(f.parts) == 3
    z_values = t.axes[0].values()
    for k, part in enumerate(f.parts):
        assert part.name() == f"slice_{k}"
        h = f.header(k)
        assert h["name"] == f"slice_{k}"
        assert h["compression"] == OpenEXR.ZIP_COMPRESSION
        assert h["lutbake:slice_index"] == str(k)
        assert float(h["lutbake:slice_value"]) == pytest.approx(float(z_values[k]), abs=1e-7)
        assert h["lutbake:kind"] == "specular_3d"
        axes = json.loads(h["lutbake:axes"])
        assert [a["dim"] for a in axes] == ["z", "y", "x"]
        assert axes[0]["values"] == [0.0, 0.5, 1.0]  # endpoint texels
        assert set(f.channels(k).keys()) == {"R", "G"}
        got = _oexr_part_array(f, k, ["R", "G"])
        assert got.dtype == EXPECTED_NP[dtype] and got.shape == (4, 5, 2)
        np.testing.assert_array_equal(got.astype(np.float32), t.data[k])
        assert got[0, 0, 0] == 100.0 * k and got[3, 0, 0] == 100.0 * k + 30.0


def test_3d_round_trip_read_exr(tmp_path):
    t = table_3d()
    data, attrs = read_exr(write_exr(t, tmp_path / "spec3d.exr"))
    assert data.shape == (3, 4, 5, 2) and data.dtype == np.float32
    np.testing.assert_array_equal(data, t.data)
    assert attrs["kind"] == "specular_3d"
    assert "slice_index" not in attrs and "slice_value" not in attrs


def test_single_slice_3d_stays_3d(tmp_path):
    t = table_3d()
    t.data = t.data[:1]
    t.axes = [Axis("f0", "z", 1), *t.axes[1:]]
    data, _ = read_exr(write_exr(t, tmp_path / "one.exr"))
    assert data.shape == (1, 4, 5, 2)


# --------------------------------------------------------------------------------- describe


def test_describe_exr(tmp_path):
    out = write_exr(table_3d(), tmp_path / "spec3d.exr", dtype="half")
    text = describe(out)
    for needle in [
        "specular_3d",
        "f0",
        "perceptual_roughness",
        "NoV",
        "slices",
        "rows",
        "columns",
        "endpoint",
        "center",
        "alpha",
        "reflectance",
        "directional albedo",
        "trilinear lookup",
        "sobol_ggx_vndf",
        "1024",
        "seed: 7",
        "0.1.0",
        "1.9.0",
        "slice_2",
        "min",
        "max",
        "mean",
        "half",
        "zip",
    ]:
        assert needle in text, needle


def test_describe_missing_and_foreign_files(tmp_path):
    with pytest.raises(ReadError, match="nope.exr: no such file"):
        describe(tmp_path / "nope.exr")
    with pytest.raises(FileNotFoundError, match="nope.exr"):
        read_exr(tmp_path / "nope.exr")
    # an EXR that lutbake did not write
    foreign = tmp_path / "foreign.exr"
    OpenEXR.File({}, {"R": np.zeros((2, 2), np.float32)}).write(str(foreign))
    with pytest.raises(ValueError, match="foreign.exr.*not a lutbake EXR"):
        read_exr(foreign)
    text = describe(foreign)  # inspect says what it can of a table lutbake did not write
    assert "no lutbake metadata" in text and "2 x 2, 1 channel(s)" in text and "R: min 0  max 0" in text
    junk = tmp_path / "junk.exr"
    junk.write_bytes(b"not an image at all")
    with pytest.raises(ValueError, match="junk.exr"):
        read_exr(junk)


# --------------------------------------------------------------------------------- atomicity


def _leftovers(d):
    return sorted(p.name for p in d.iterdir() if p.name.endswith(".tmp.exr"))


def test_failure_mid_write_leaves_target_untouched(tmp_path, monkeypatch):
    target = tmp_path / "spec3d.exr"
    write_exr(table_2d(), target)
    before = target.read_bytes()

    real_oiio = exr_mod._oiio()
    seen = {}

    class FailingOutput:
        """Wraps OIIO's ImageOutput; fails on the second part, after the first is on disk."""

        def __init__(self, inner):
            self.inner, self.parts = inner, 0

        def open(self, path, *args):
            seen["tmp"] = path
            return self.inner.open(path, *args)

        def write_image(self, pixels):
            if self.parts == 1:
                seen["tmp_existed"] = os.path.exists(seen["tmp"])
                raise RuntimeError("simulated crash mid-write")
            self.parts += 1
            return self.inner.write_image(pixels)

        def __getattr__(self, name):
            return getattr(self.inner, name)

    class FakeOIIO:
        def __getattr__(self, name):
            return getattr(real_oiio, name)

        class ImageOutput:
            @staticmethod
            def create(path):
                return FailingOutput(real_oiio.ImageOutput.create(path))

    monkeypatch.setattr(exr_mod, "_oiio", lambda: FakeOIIO())
    with pytest.raises(RuntimeError, match="simulated crash"):
        write_exr(table_3d(), target)
    assert seen["tmp_existed"]  # the crash happened with a partial temp file on disk
    assert os.path.dirname(seen["tmp"]) == str(tmp_path)  # temp file in the target's directory
    assert target.read_bytes() == before
    assert _leftovers(tmp_path) == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ["spec3d.exr"]


@pytest.mark.parametrize("exc", [OSError("disk full"), KeyboardInterrupt()])
def test_failure_before_rename_leaves_target_untouched(tmp_path, monkeypatch, exc):
    target = tmp_path / "dfg.exr"
    write_exr(table_2d(), target, dtype="half")
    before = target.read_bytes()

    def boom(path):
        assert os.path.exists(path)  # complete temp file, not yet renamed
        raise exc

    monkeypatch.setattr(atomic_mod, "_fsync_file", boom)
    with pytest.raises(type(exc)):
        write_exr(table_2d(), target, dtype="float32")
    assert target.read_bytes() == before
    assert _leftovers(tmp_path) == []


def test_overwrite_replaces_target(tmp_path):
    target = tmp_path / "dfg.exr"
    write_exr(table_2d(), target)
    t = table_2d()
    t.data = t.data + 1.0
    write_exr(t, target)
    np.testing.assert_array_equal(read_exr(target)[0], t.data)
    assert _leftovers(tmp_path) == []


# --------------------------------------------------------------------------------- finite values


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("make", [table_2d, table_3d])
def test_non_finite_raises_and_writes_nothing(tmp_path, bad, make):
    t = make()
    t.data = t.data.copy()
    t.data[(1,) * (t.data.ndim - 1) + (0,)] = bad
    target = tmp_path / "bad.exr"
    with pytest.raises(ValueError, match=t.name):
        write_exr(t, target)
    assert list(tmp_path.iterdir()) == []


def test_non_finite_keeps_existing_target(tmp_path):
    target = tmp_path / "dfg.exr"
    write_exr(table_2d(), target)
    before = target.read_bytes()
    t = table_2d()
    t.data[0, 0, 1] = np.nan
    with pytest.raises(ValueError, match="dfg_test.*NaN"):
        write_exr(t, target)
    assert target.read_bytes() == before
    assert _leftovers(tmp_path) == []


def test_half_overflow_raises(tmp_path):
    t = table_2d()
    t.data[2, 3, 0] = 1.0e5  # finite in float32, Inf in half
    with pytest.raises(ValueError, match="dfg_test.*overflows half"):
        write_exr(t, tmp_path / "x.exr", dtype="half")
    assert list(tmp_path.iterdir()) == []
    write_exr(t, tmp_path / "x.exr", dtype="float32")  # fine in float32


# --------------------------------------------------------------------------------- malformed tables


def test_malformed_tables_raise(tmp_path):
    t = table_2d()
    with pytest.raises(ValueError, match="dtype"):
        write_exr(t, tmp_path / "x.exr", dtype="float16")
    t2 = table_2d()
    t2.axes = [Axis("perceptual_roughness", "y", 5), t2.axes[1]]
    with pytest.raises(ValueError, match="count 5"):
        write_exr(t2, tmp_path / "x.exr")
    t3 = table_2d()
    t3.channels = {"only": "one"}
    with pytest.raises(ValueError, match="channel"):
        write_exr(t3, tmp_path / "x.exr")
    t4 = table_2d()
    t4.attributes = {**t4.attributes, "kind": "other"}
    with pytest.raises(ValueError, match="reserved"):
        write_exr(t4, tmp_path / "x.exr")
    assert list(tmp_path.iterdir()) == []
