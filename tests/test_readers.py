"""lutbake.io.readers: every format lutbake writes reads back (checked against the independent readers of
test_formats where they exist), dispatched by magic bytes not by extension; a LUT without lutbake metadata
is described; malformed files and metadata give one clean line naming the file once, never a traceback."""

import json
import shutil

import numpy as np
import pytest
from click.testing import CliRunner
from test_formats import read_dds_spec, read_ktx2_spec, table2d, table3d

from lutbake.cli import main
from lutbake.io.formats import write_table
from lutbake.io.integrity import sidecar_path
from lutbake.io.readers import ReadError, read, read_table

HALF = {"half": np.float16, "float32": np.float32}
GENERIC_FORMATS = ["exr", "npy", "png16", "dds", "ktx2", "h"]  # any table (the engine-specific ones: test_outputs)


def inspect(path):
    return CliRunner().invoke(main, ["inspect", str(path)])


def assert_one_line_error(r, path, *needles):
    assert r.exit_code == 2, r.output
    assert "Traceback" not in r.output and r.exception is None or isinstance(r.exception, SystemExit), r.output
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), r.output
    assert lines[0].count(str(path)) == 1, r.output  # the path once
    for n in needles:
        assert n in lines[0], (n, r.output)


@pytest.mark.parametrize("fmt", GENERIC_FORMATS)
@pytest.mark.parametrize("dtype", ["half", "float32"])
def test_every_format_reads_back_with_its_metadata(tmp_path, fmt, dtype):
    t = table2d(3 if fmt != "png16" else 2)
    p = write_table(t, tmp_path, fmt, dtype)
    view = read_table(p)
    tol = 0.5 / 65535 if fmt == "png16" else 0
    want = t.data.astype(HALF[dtype] if fmt != "png16" else np.float32).astype(np.float32)
    np.testing.assert_allclose(view.data, want, atol=tol, rtol=0)
    assert view.kind == "dfg" and view.name == "lut" and view.channel_names == list(t.channels)
    assert [a.name for a in view.axes] == ["perceptual_roughness", "NoV"]
    np.testing.assert_array_equal(view.axes[1].values(), t.axes[1].values())
    if fmt == "dds":  # the package reader agrees with the one written here from the specification
        np.testing.assert_array_equal(read(p).data, read_dds_spec(p.read_bytes())[0].astype(np.float32))
    if fmt == "ktx2":
        np.testing.assert_array_equal(read(p).data, read_ktx2_spec(p.read_bytes())[0].astype(np.float32))


@pytest.mark.parametrize("fmt", ["exr", "npy", "dds", "ktx2", "h"])
def test_3d_tables_read_back_in_every_format_that_holds_them(tmp_path, fmt):
    t = table3d(2)
    view = read_table(write_table(t, tmp_path, fmt, "float32"))
    np.testing.assert_array_equal(view.data, t.data)
    assert [a.name for a in view.axes] == ["f0", "perceptual_roughness", "NoV"]


def test_the_sidecar_reads_as_its_data_file(tmp_path):
    t = table2d(2)
    write_table(t, tmp_path, "dds", "half")
    view = read_table(tmp_path / "lut.dds.json")
    assert view.loaded.format == "sidecar" and view.kind == "dfg"
    np.testing.assert_array_equal(view.data, t.data.astype(np.float16).astype(np.float32))


def test_format_is_chosen_by_magic_bytes_not_extension(tmp_path):
    t = table2d(2)
    for fmt, ext in (("dds", ".exr"), ("exr", ".png"), ("ktx2", ".npy"), ("npy", ".dds")):
        src = write_table(t, tmp_path / fmt, fmt, "float32")
        dst = tmp_path / f"renamed_{fmt}{ext}"
        shutil.copy(src, dst)
        got = read(dst)
        assert got.format == fmt, (fmt, ext)
        np.testing.assert_array_equal(got.data[..., :2], t.data)


def test_inspect_describes_a_lut_without_lutbake_metadata(tmp_path):
    """A table as an engine ships it: no sidecar, no lutbake attributes."""
    t = table2d(2)
    for fmt in ("dds", "png16", "npy", "ktx2"):
        p = write_table(t, tmp_path / fmt, fmt, "half")
        sidecar_path(p).unlink()
        if fmt == "ktx2":  # drop the key/value metadata: keep only what KTX itself says
            from lutbake.io import ktx2

            p.write_bytes(ktx2.encode(t.data.astype(np.float16)))
        r = inspect(p)
        assert r.exit_code == 0, r.output
        assert "no lutbake metadata" in r.output and "7 x 5" in r.output, r.output
        assert "min" in r.output and "max" in r.output and "Traceback" not in r.output
        top = float(t.data[..., 0].astype(np.float16).max())
        assert f"max {top:.6g}" in r.output or fmt == "png16", r.output


def test_a_sidecar_describing_another_file_is_not_used(tmp_path):
    t = table2d(2)
    write_table(t, tmp_path, "npy")
    side = json.loads((tmp_path / "lut.npy.json").read_text())
    side["file"] = "lut.h"
    (tmp_path / "lut.npy.json").write_text(json.dumps(side))
    r = inspect(tmp_path / "lut.npy")
    assert r.exit_code == 0 and "no lutbake metadata" in r.output and "describes lut.h" in r.output, r.output


# ------------------------------------------------------------------------------------------ malformed


def _exr_with(tmp_path, name, **attrs):
    """A lutbake EXR with some lutbake:* attributes replaced."""
    oiio = pytest.importorskip("OpenImageIO")
    src = write_table(table2d(2), tmp_path / "src", "exr")
    buf = oiio.ImageBuf(str(src))
    for k, v in attrs.items():
        buf.specmod().attribute("lutbake:" + k, v)
    out = tmp_path / name
    buf.write(str(out))
    return out


def test_axes_that_are_not_a_list_is_one_clean_line(tmp_path):
    p = _exr_with(tmp_path, "axes.exr", axes='{"a":1}')
    assert_one_line_error(inspect(p), p, "lutbake:axes", "JSON list")


def test_an_axis_count_of_1e11_is_refused_before_any_allocation(tmp_path):
    axes = json.loads(read(write_table(table2d(2), tmp_path / "src", "exr")).attrs["axes"])
    axes[0]["count"] = 1e11
    p = _exr_with(tmp_path, "count.exr", axes=json.dumps(axes))
    assert_one_line_error(inspect(p), p, "count 100000000000")
    axes[0]["count"] = 6  # an integer, but not the image's
    p = _exr_with(tmp_path, "count6.exr", axes=json.dumps(axes))
    assert_one_line_error(inspect(p), p, "count 6", "5 rows")


def test_a_1d_npy_is_one_clean_line(tmp_path):
    p = tmp_path / "line.npy"
    np.save(p, np.arange(5.0))
    assert_one_line_error(inspect(p), p, "shape (5,)")


def test_a_sidecar_whose_lutbake_is_not_an_object_is_one_clean_line(tmp_path):
    p = write_table(table2d(2), tmp_path, "npy")
    side = sidecar_path(p)
    side.write_text('{"lutbake":"oops"}')
    for target in (p, side):
        r = inspect(target)
        assert_one_line_error(r, side, "key 'lutbake' must be a JSON object")
    r = CliRunner().invoke(main, ["preview", str(p), "-o", str(tmp_path / "x.png")])
    assert_one_line_error(r, side, "key 'lutbake'")


def test_a_1gb_junk_file_is_refused_by_its_magic_bytes(tmp_path):
    p = tmp_path / "junk.exr"
    with open(p, "wb") as f:
        f.truncate(1 << 30)  # sparse: 1 GB of zeros, nothing written
    assert_one_line_error(inspect(p), p, "not a format lutbake reads", "00 00 00 00")
    r = CliRunner().invoke(main, ["preview", str(p), "-o", str(tmp_path / "x.png")])
    assert_one_line_error(r, p, "not a format lutbake reads")


@pytest.mark.parametrize("fmt", ["dds", "ktx2", "npy", "h", "exr", "png16"])
def test_truncated_files_are_one_clean_line(tmp_path, fmt):
    p = write_table(table2d(2, h=32, w=32), tmp_path, fmt, "float32")
    p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2])
    assert_one_line_error(inspect(p), p)


def test_missing_file_and_directory_are_one_clean_line(tmp_path):
    assert_one_line_error(inspect(tmp_path / "none.exr"), tmp_path / "none.exr", "no such file")
    assert_one_line_error(inspect(tmp_path), tmp_path, "not a regular file")


def test_read_error_is_a_value_error():
    assert issubclass(ReadError, ValueError)


def test_the_bake_report_is_described_and_not_taken_for_a_sidecar(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('[[table]]\nname = "report"\nkind = "dfg"\nsize = [8, 4]\nsamples = 48\nformat = "npy"\n')
    out = tmp_path / "o"
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(out), "--report", str(out / "run.json")])
    assert r.exit_code == 0, r.output
    r = inspect(out / "run.json")
    assert r.exit_code == 0 and "bake report" in r.output and "baked" in r.output and "report.npy" in r.output
    r = CliRunner().invoke(main, ["preview", str(out / "run.json"), "-o", str(tmp_path / "x.png")])
    assert_one_line_error(r, out / "run.json", "holds no pixels")
    assert inspect(out / "report.npy").exit_code == 0  # its sidecar report.json is the table's, not a report
