"""Output formats: each file read back by an independent reader (OpenImageIO for PNG and EXR; readers
written here from the DDS and KTX 2.0 specifications; a C compiler for the header) and compared with
the table; atomic writes; the CLI's --format."""

import json
import shutil
import struct
import subprocess

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake.axes import Axis
from lutbake.cli import main
from lutbake.io.formats import FORMATS, write_table
from lutbake.io.integrity import sidecar_path
from lutbake.table import Table

HALF_REL = 2.0**-11  # half-float relative rounding
U16 = 1.0 / 65535


def table2d(nch=2, h=5, w=7, scale=1.0):
    rng = np.random.default_rng(nch)
    data = (rng.random((h, w, nch)) * scale).astype(np.float32)
    chans = {f"c{i}": f"channel {i}" for i in range(nch)}
    axes = [Axis("perceptual_roughness", "y", h), Axis("NoV", "x", w)]
    return Table("lut", "dfg", data, axes, chans, "E = f0 * t.r + t.g", {"estimator": "test", "config": "[[table]]"})


def table3d(nch=2):
    rng = np.random.default_rng(3)
    data = rng.random((3, 4, 6, nch)).astype(np.float32)
    axes = [Axis("f0", "z", 3), Axis("perceptual_roughness", "y", 4), Axis("NoV", "x", 6)]
    return Table("vol", "specular_3d", data, axes, {f"c{i}": "x" for i in range(nch)}, "r", {})


def expect_gpu(data, dtype):
    """What a GPU texture holds: half/float, 3 channels padded with A = 1."""
    d = data.astype(np.float16 if dtype == "half" else np.float32)
    if d.shape[-1] == 3:
        d = np.concatenate([d, np.ones(d.shape[:-1] + (1,), d.dtype)], axis=-1)
    return d


# ------------------------------------------------------------------ independent readers, from the specs


def read_dds_spec(blob):
    """DDS per Microsoft's 'DDS file layout': magic, DDS_HEADER (124 bytes), DDS_HEADER_DXT10 (20 bytes)."""
    assert blob[:4] == b"DDS "
    (size, flags, height, width, pitch, depth, mips) = struct.unpack("<7I", blob[4:32])
    assert size == 124
    pf_size, pf_flags, fourcc = struct.unpack("<II4s", blob[76:88])
    assert pf_size == 32 and pf_flags & 0x4 and fourcc == b"DX10"
    caps, caps2 = struct.unpack("<II", blob[108:116])
    assert caps & 0x1000
    fmt, dim, misc, array_size, misc2 = struct.unpack("<5I", blob[128:148])
    formats = {34: ("<f2", 2), 16: ("<f4", 2), 10: ("<f2", 4), 2: ("<f4", 4), 54: ("<f2", 1), 41: ("<f4", 1)}
    dt, nch = formats[fmt]
    assert pitch == width * nch * np.dtype(dt).itemsize
    if dim == 4:
        assert flags & 0x800000 and caps2 & 0x200000
        shape = (depth, height, width, nch)
    else:
        assert dim == 3 and not caps2 & 0x200000
        shape = (height, width, nch)
    assert array_size == 1 and mips in (0, 1)
    arr = np.frombuffer(blob[148:], dtype=dt)
    assert arr.size == np.prod(shape)
    return arr.reshape(shape), fmt


def read_ktx2_spec(blob):
    """KTX 2.0 per the Khronos specification, sections 3.1-3.12, and the KDF 1.3 basic descriptor; level 0 plain
    (supercompressionScheme 0) or one Zstandard frame (scheme 2, inflated with the ``zstandard`` package)."""
    assert blob[:12] == bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])
    vk, type_size, w, h, d, layers, faces, levels, scheme = struct.unpack_from("<9I", blob, 12)
    dfd_off, dfd_len, kvd_off, kvd_len, sgd_off, sgd_len = struct.unpack_from("<4I2Q", blob, 48)
    assert faces == 1 and levels == 1 and scheme in (0, 2) and sgd_len == 0
    lvl_off, lvl_len, lvl_ulen = struct.unpack_from("<3Q", blob, 80)
    assert lvl_len == lvl_ulen or scheme == 2
    # DFD: total size, then one basic block
    (total,) = struct.unpack_from("<I", blob, dfd_off)
    assert total == dfd_len
    w0, w1, w2, w3, w4, w5 = struct.unpack_from("<6I", blob, dfd_off + 4)
    assert w0 == 0 and (w1 & 0xFFFF) == 2
    block = w1 >> 16
    nsamples = (block - 24) // 16
    model, prim, transfer, _dflags = w2 & 0xFF, (w2 >> 8) & 0xFF, (w2 >> 16) & 0xFF, w2 >> 24
    assert (model, prim, transfer) == (1, 1, 1)  # RGBSDA, BT709, LINEAR (never sRGB = 2)
    channels = []
    for s in range(nsamples):
        sw0, sw1, lo, hi = struct.unpack_from("<4I", blob, dfd_off + 28 + 16 * s)
        bit_off, bit_len, ctype = sw0 & 0xFFFF, ((sw0 >> 16) & 0xFF) + 1, sw0 >> 24
        assert ctype & 0xC0 == 0xC0  # FLOAT | SIGNED
        assert bit_len == 8 * type_size and bit_off == s * bit_len
        channels.append(ctype & 0x0F)
    assert (w4 & 0xFF) == nsamples * type_size
    vk_formats = {83: ("<f2", 2), 103: ("<f4", 2), 97: ("<f2", 4), 109: ("<f4", 4), 76: ("<f2", 1), 100: ("<f4", 1)}
    dt, nch = vk_formats[vk]
    assert nch == nsamples and np.dtype(dt).itemsize == type_size
    # key/value data
    kv, p = {}, kvd_off
    while p < kvd_off + kvd_len:
        (n,) = struct.unpack_from("<I", blob, p)
        key, _, value = blob[p + 4 : p + 4 + n].partition(b"\0")
        kv[key.decode()] = value.rstrip(b"\0").decode()
        p += 4 + n + (-n % 4)
    assert list(kv) == sorted(kv)
    shape = ((d,) if d else (layers,) if layers else ()) + (h, w, nch)
    if scheme == 2:  # KTX 2.0 §3.12.2: a Zstandard frame inflating to uncompressedByteLength; no mipPadding
        import zstandard

        level = zstandard.ZstdDecompressor().decompress(blob[lvl_off : lvl_off + lvl_len], max_output_size=lvl_ulen)
        assert len(level) == lvl_ulen == np.prod(shape) * type_size
        blob, lvl_off = level, 0
    else:
        assert lvl_off % np.lcm(nch * type_size, 4) == 0
    arr = np.frombuffer(blob, dtype=dt, count=int(np.prod(shape)), offset=lvl_off).reshape(shape)
    return arr, vk, channels, kv, (d, layers)


# ------------------------------------------------------------------------------------------- tests


def test_every_format_is_documented():
    doc = open("docs/config.md", encoding="utf-8").read()
    for f in FORMATS:
        assert f"`{f}`" in doc


@pytest.mark.parametrize("dtype", ["half", "float32"])
@pytest.mark.parametrize("nch", [1, 2, 3, 4])
def test_dds_read_back_from_the_spec(tmp_path, dtype, nch):
    t = table2d(nch)
    p = write_table(t, tmp_path, "dds", dtype)
    arr, fmt = read_dds_spec(p.read_bytes())
    np.testing.assert_array_equal(arr, expect_gpu(t.data, dtype))
    meta = json.loads(sidecar_path(p).read_text())
    assert meta["dxgi_format"].endswith("_FLOAT") and meta["lutbake"]["kind"] == "dfg"


def test_dds_3d_is_a_volume_texture(tmp_path):
    t = table3d(2)
    arr, fmt = read_dds_spec(write_table(t, tmp_path, "dds", "half").read_bytes())
    assert fmt == 34 and arr.shape == (3, 4, 6, 2)
    np.testing.assert_array_equal(arr, t.data.astype(np.float16))


def test_openimageio_does_not_read_float_dds_so_the_spec_reader_is_the_check(tmp_path):
    """OpenImageIO 3.x's DDS reader has no float formats (it reports 'Unsupported DXGI format'); if a
    later version reads them, it must agree with the table."""
    oiio = pytest.importorskip("OpenImageIO")
    t = table2d(4)
    p = write_table(t, tmp_path, "dds", "float32")
    inp = oiio.ImageInput.open(str(p))
    if inp is None:
        pytest.skip(f"OpenImageIO {oiio.VERSION_STRING} cannot read float DDS: {oiio.geterror()}")
    arr = np.asarray(inp.read_image("float"))
    inp.close()
    np.testing.assert_allclose(arr.reshape(t.data.shape), t.data)


@pytest.mark.parametrize("dtype", ["half", "float32"])
@pytest.mark.parametrize("nch", [1, 2, 3])
def test_ktx2_read_back_from_the_spec(tmp_path, dtype, nch):
    t = table2d(nch)
    arr, vk, channels, kv, (d, layers) = read_ktx2_spec(write_table(t, tmp_path, "ktx2", dtype).read_bytes())
    np.testing.assert_array_equal(arr, expect_gpu(t.data, dtype))
    assert channels == [0, 1, 15][: max(nch, 1)] if nch < 3 else channels == [0, 1, 2, 15]
    assert kv["KTXorientation"] == "rd" and kv["KTXwriter"].startswith("lutbake")
    assert json.loads(kv["lutbake:metadata"])["kind"] == "dfg"
    assert (d, layers) == (0, 0)


def test_ktx2_3d_and_array(tmp_path):
    from lutbake.io.formats import write_ktx2

    t = table3d(2)
    arr, vk, _, kv, (d, layers) = read_ktx2_spec(write_table(t, tmp_path, "ktx2", "half").read_bytes())
    assert vk == 83 and (d, layers) == (3, 0) and kv["KTXorientation"] == "rdi"
    np.testing.assert_array_equal(arr, t.data.astype(np.float16))
    p = write_ktx2(t, tmp_path / "arr.ktx2", "float32", array=True)
    arr, vk, _, kv, (d, layers) = read_ktx2_spec(p.read_bytes())
    assert vk == 103 and (d, layers) == (0, 3)
    np.testing.assert_array_equal(arr, t.data)


def png_chunks(blob):
    assert blob[:8] == b"\x89PNG\r\n\x1a\n"
    pos, out = 8, {}
    while pos < len(blob):
        (n,) = struct.unpack(">I", blob[pos : pos + 4])
        out.setdefault(blob[pos + 4 : pos + 8].decode(), []).append(blob[pos + 8 : pos + 8 + n])
        pos += 12 + n
    return out


def test_png16_is_linear_16bit_and_never_tagged_srgb(tmp_path):
    oiio = pytest.importorskip("OpenImageIO")
    t = table2d(2)
    p = write_table(t, tmp_path, "png16")
    chunks = png_chunks(p.read_bytes())
    ihdr = chunks["IHDR"][0]
    assert ihdr[8] == 16 and ihdr[9] == 2  # bit depth 16, colour type RGB
    assert "sRGB" not in chunks and "iCCP" not in chunks
    if "gAMA" in chunks:
        assert struct.unpack(">I", chunks["gAMA"][0])[0] == 100000  # gamma 1.0: linear
    inp = oiio.ImageInput.open(str(p))
    arr = np.asarray(inp.read_image("uint16")).astype(np.float64) / 65535
    inp.close()
    np.testing.assert_allclose(arr[..., :2], t.data, atol=0.5 * U16 + 1e-7)
    assert np.all(arr[..., 2] == 0)


def test_png16_refuses_values_it_cannot_hold_and_leaves_no_file(tmp_path):
    t = table2d(3, scale=20.0)  # like the cloth channel (up to 18)
    with pytest.raises(ValueError, match="png16 stores"):
        write_table(t, tmp_path, "png16")
    assert list(tmp_path.iterdir()) == []


def test_npy_round_trip_with_sidecar(tmp_path):
    t = table3d(3)
    p = write_table(t, tmp_path, "npy", "half")
    arr = np.load(p)
    assert arr.dtype == np.float16 and arr.shape == t.data.shape
    np.testing.assert_array_equal(arr, t.data.astype(np.float16))
    side = json.loads(sidecar_path(p).read_text())
    assert side["shape"] == list(t.data.shape) and "axes" in side["lutbake"]


@pytest.mark.parametrize("dtype", ["half", "float32"])
def test_c_header_compiles_and_holds_the_values(tmp_path, dtype):
    t = table2d(2)
    p = write_table(t, tmp_path, "h", dtype)
    text = p.read_text()
    assert "row 0 = table row 0" in text and "reconstruction" in text and "sample at u =" in text
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler on PATH to compile the generated header")
    src = tmp_path / "main.c"
    conv = (
        (
            "float f; unsigned short b = lut[(y * LUT_WIDTH + x) * LUT_CHANNELS + c]; /* decode binary16 */\n"
            "int e = (b >> 10) & 31, m = b & 1023; f = e ? ldexpf(1024 + m, e - 25) : ldexpf(m, -24);\n"
            "if (b & 0x8000) f = -f;\n"
        )
        if dtype == "half"
        else "float f = lut[(y * LUT_WIDTH + x) * LUT_CHANNELS + c];\n"
    )
    src.write_text(
        '#include <stdio.h>\n#include <math.h>\n#include "lut.h"\nint main(void) {\n'
        "for (int y = 0; y < LUT_HEIGHT; y++) for (int x = 0; x < LUT_WIDTH; x++)"
        " for (int c = 0; c < LUT_CHANNELS; c++) {\n" + conv + 'printf("%.9g\\n", f); }\nreturn 0; }\n'
    )
    exe = tmp_path / "main"
    subprocess.run(
        [cc, "-std=c99", "-Wall", "-Werror", "-I", str(tmp_path), str(src), "-o", str(exe), "-lm"],
        check=True,
        capture_output=True,
    )
    out = np.array(subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout.split(), float)
    want = t.data.astype(np.float16 if dtype == "half" else np.float32).astype(np.float64).ravel()
    np.testing.assert_array_equal(out.astype(np.float32), want.astype(np.float32))  # %.9g round-trips float32


def test_cli_format_option_writes_that_format(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('[[table]]\nname = "small"\nkind = "dfg"\nsize = [16, 8]\nsamples = 48\ndtype = "half"\n')
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(tmp_path / "out"), "--format", "ktx2"])
    assert r.exit_code == 0, r.output
    arr, vk, *_ = read_ktx2_spec((tmp_path / "out" / "small.ktx2").read_bytes())
    assert vk == 83 and arr.shape == (8, 16, 2)
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(tmp_path / "o2"), "--set", 'format="dds"'])
    assert r.exit_code == 0 and (tmp_path / "o2" / "small.dds").is_file()


def test_cli_format_choices_are_the_writers():
    from lutbake.io.formats import ALL_FORMATS, CUBE_ONLY_FORMATS, WRITERS

    opt = next(p for p in main.commands["bake"].params if p.name == "fmt")
    # a table's formats are WRITERS'; a cube-only one is written by lutbake.io.cubemap.write_cube
    assert list(opt.type.choices) == list(ALL_FORMATS) and set(ALL_FORMATS) == set(WRITERS) | set(CUBE_ONLY_FORMATS)
    assert set(FORMATS) < set(ALL_FORMATS)


def test_format_option_accepts_every_format_a_kind_allows_and_the_refusal_lists_only_those(tmp_path):
    """One source: each kind's ``format`` key (its allowed values) is what the config check accepts and lists, and
    the --format option accepts every one of them (issue 39: ``--preset ltc-ggx --format c`` was refused by click)."""
    import re

    from lutbake.kinds import KINDS

    opt = next(p for p in main.commands["bake"].params if p.name == "fmt")
    for kind in KINDS.values():
        assert set(kind.keys["format"].choices) <= set(opt.type.choices), kind.name
    r = CliRunner().invoke(main, ["bake", "--preset", "ltc-ggx", "--format", "png16", "--out-dir", str(tmp_path / "o")])
    assert r.exit_code == 2 and "--format" in r.output, r.output
    listed = re.search(r"\(allowed: ([^)]*)\)", r.output).group(1).split(", ")
    assert listed == list(KINDS["ltc"].keys["format"].choices)
    for fmt in listed:  # every format the message lists passes the option and the check (bad --out-dir: exit 2 after)
        lobe = ["--set", "lobe=zeltner"] if fmt == "babylon_fuzz" else []  # it stores normal-frame fits only
        r = CliRunner().invoke(main, ["bake", "--preset", "ltc-ggx", *lobe, "--format", fmt, "--out-dir", "/proc/x"])
        assert "--format" not in r.output and "Invalid value" not in r.output, (fmt, r.output)
