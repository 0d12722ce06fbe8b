"""JS / WGSL / Rust array outputs and zstd KTX2, each read back by an independent reader:
node (JS), rustc (Rust), a parser written here (WGSL), and a KTX2 parser written here with the zstandard
package (KTX2). Node and rustc tests skip with the reason where the tool is missing."""

import json
import re
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
import zstandard

from lutbake.axes import Axis
from lutbake.io.formats import write_table
from lutbake.table import Table

H, W = 5, 7


@pytest.fixture(scope="module")
def table():
    rng = np.random.default_rng(7)
    data = rng.random((H, W, 2)).astype(np.float32)
    axes = [Axis("perceptual_roughness", "y", H), Axis("NoV", "x", W)]
    return Table(
        "lut-x",
        "dfg",
        data,
        axes,
        {"scale": "multiplies f0", "bias": "added"},
        "E = f0 * t.r + t.g",
        {"config": '[[table]]\nname = "lut-x"\n'},
    )


def half(x):
    return np.asarray(x, np.float32).astype(np.float16).astype(np.float32)


@pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")
@pytest.mark.parametrize("dtype", ["half", "float32"])
def test_js_module_read_by_node(table, tmp_path, dtype):
    path = write_table(table, tmp_path, "js", dtype)
    text = path.read_text()
    assert text.startswith("/*") and "texel center" in text and "lutbake:shape = [5, 7, 2]" in text
    mjs = tmp_path / "read.mjs"
    mjs.write_text(
        f"import * as m from '{path.as_posix()}';\n"
        "const a = m.LUT_X; console.log(JSON.stringify({type: a.constructor.name, "
        "h: m.LUT_X_HEIGHT, w: m.LUT_X_WIDTH, c: m.LUT_X_CHANNELS, v: Array.from(a)}));\n"
    )
    out = json.loads(subprocess.run(["node", str(mjs)], capture_output=True, text=True, check=True).stdout)
    assert (out["h"], out["w"], out["c"]) == (H, W, 2)
    if dtype == "half":
        assert out["type"] == "Uint16Array"
        got = np.array(out["v"], np.uint16).view(np.float16).astype(np.float32)
        np.testing.assert_array_equal(got.reshape(H, W, 2), half(table.data))
    else:
        assert out["type"] == "Float32Array"
        np.testing.assert_array_equal(np.array(out["v"], np.float32).reshape(H, W, 2), table.data)


@pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")
def test_threejs_dfg_module_replaces_threes_own_file(table, tmp_path):
    """format threejs_dfg is three.js's src/renderers/shaders/DFGLUTData.js: put where three's stands (its relative
    imports resolved to stand-ins of three's DataTexture and constants), node's getDFGLUT() builds the W x H RG16F
    texture of the table's half bits, linear, clamped, no mipmaps."""
    src = tmp_path / "three" / "src"
    shaders = src / "renderers" / "shaders"
    shaders.mkdir(parents=True)
    (src / "textures").mkdir()
    (src / "textures" / "DataTexture.js").write_text(
        "export class DataTexture { constructor(data, width, height, format, type) "
        "{ Object.assign(this, {data, width, height, format, type}); } }\n"
    )
    names = ("RGFormat", "HalfFloatType", "LinearFilter", "ClampToEdgeWrapping")
    (src / "constants.js").write_text("".join(f"export const {n} = '{n}';\n" for n in names))
    path = write_table(table, tmp_path, "threejs_dfg", "half")
    shutil.copy(path, shaders / "DFGLUTData.js")
    mjs = tmp_path / "read.mjs"
    mjs.write_text(
        f"import {{ getDFGLUT }} from '{(shaders / 'DFGLUTData.js').as_posix()}';\n"
        "const t = getDFGLUT(); console.log(JSON.stringify({same: t === getDFGLUT(), v: Array.from(t.data), "
        "w: t.width, h: t.height, f: t.format, ty: t.type, min: t.minFilter, mag: t.magFilter, s: t.wrapS, "
        "t: t.wrapT, mips: t.generateMipmaps, name: t.name}));\n"
    )
    out = json.loads(subprocess.run(["node", str(mjs)], capture_output=True, text=True, check=True).stdout)
    assert out["same"] and (out["w"], out["h"], out["name"], out["mips"]) == (W, H, "DFG_LUT", False)
    assert (out["f"], out["ty"], out["min"], out["mag"], out["s"], out["t"]) == (
        "RGFormat", "HalfFloatType", "LinearFilter", "LinearFilter", "ClampToEdgeWrapping", "ClampToEdgeWrapping"
    )  # fmt: skip
    got = np.array(out["v"], np.uint16).view(np.float16).astype(np.float32)
    np.testing.assert_array_equal(got.reshape(H, W, 2), half(table.data))


def test_threejs_dfg_is_refused_where_three_could_not_load_it(tmp_path):
    from lutbake.config import validate_table
    from lutbake.errors import ConfigError

    with pytest.raises(ConfigError, match="threejs_dfg holds a dfg table only"):
        validate_table({"name": "t", "kind": "albedo", "format": "threejs_dfg", "dtype": "half"}, "c.toml", 0)
    with pytest.raises(ConfigError, match="a two-channel layout and dtype = 'half'"):
        validate_table({"name": "t", "kind": "dfg", "format": "threejs_dfg"}, "c.toml", 0)
    with pytest.raises(ConfigError, match="a two-channel layout"):
        raw = {"name": "t", "kind": "dfg", "format": "threejs_dfg", "dtype": "half", "layout": "scale_bias_f82"}
        validate_table(raw, "c.toml", 0)


def test_wgsl_array_parsed_independently(table, tmp_path):
    text = write_table(table, tmp_path, "wgsl", "half").read_text()
    assert all(line.startswith("//") for line in text.split("const")[0].strip().splitlines())
    m = re.search(r"const LUT_X: array<f32, (\d+)> = array<f32, \d+>\(([^)]*)\);", text)
    assert m and int(m.group(1)) == H * W * 2
    vals = np.array([float(x) for x in m.group(2).replace("\n", " ").split(",")], np.float32)
    np.testing.assert_array_equal(vals.reshape(H, W, 2), half(table.data))
    assert re.search(r"const LUT_X_WIDTH: u32 = 7u;", text)


@pytest.mark.skipif(shutil.which("rustc") is None, reason="rustc is not installed")
def test_rust_const_read_by_rustc(table, tmp_path):
    path = write_table(table, tmp_path, "rs", "half")
    main = tmp_path / "main.rs"
    main.write_text(
        f'include!("{path.as_posix()}");\n'
        'fn main() { println!("{} {} {}", LUT_X_HEIGHT, LUT_X_WIDTH, LUT_X_CHANNELS); '
        'for b in LUT_X.iter() { println!("{}", b); } }\n'
    )
    exe = tmp_path / "main"
    subprocess.run(["rustc", "-O", "-o", str(exe), str(main)], check=True, capture_output=True)
    lines = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.split()
    assert lines[:3] == ["5", "7", "2"]
    got = np.array([int(x) for x in lines[3:]], np.uint16).view(np.float16).astype(np.float32)
    np.testing.assert_array_equal(got.reshape(H, W, 2), half(table.data))


def test_ktx2_zstd_parsed_independently(table, tmp_path):
    blob = write_table(table, tmp_path, "ktx2zst", "half").read_bytes()
    assert blob[:12] == bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])
    vk, type_size, w, h, depth, layers, faces, levels, scheme = struct.unpack_from("<9I", blob, 12)
    assert (vk, w, h, scheme) == (83, W, H, 2)  # R16G16_SFLOAT, zstd
    assert type_size == ktx2_spec_type_size(vk)
    off, size, raw = struct.unpack_from("<QQQ", blob, 80)
    assert raw == H * W * 2 * 2 and off + size == len(blob)
    level = zstandard.ZstdDecompressor().decompress(blob[off : off + size], max_output_size=raw)
    np.testing.assert_array_equal(np.frombuffer(level, "<f2").reshape(H, W, 2).astype(np.float32), half(table.data))
    kvd_off, kvd_len = struct.unpack_from("<II", blob, 56)
    assert b"lutbake:metadata" in blob[kvd_off : kvd_off + kvd_len]


# KTX 2.0 §3.3 "typeSize": for an unpacked format, the bytes of one component ("derived from the format name", e.g.
# 16 / 8 for R16G16B16_UNORM), with no exception for supercompressed files (1 only for VK_FORMAT_UNDEFINED and
# *_BLOCK formats). The vkFormat values lutbake writes and their names' component widths (vulkan_core.h):
VK_COMPONENT_BITS = {76: 16, 83: 16, 97: 16, 100: 32, 103: 32, 109: 32}  # R16, R16G16, R16G16B16A16, R32, ...


def ktx2_spec_type_size(vk: int) -> int:
    return VK_COMPONENT_BITS[vk] // 8


@pytest.mark.parametrize("dtype", ["half", "float32"])
@pytest.mark.parametrize("nch", [1, 2, 4])
def test_ktx2_zstd_type_size_is_the_component_size(tmp_path, dtype, nch):
    rng = np.random.default_rng(nch)
    axes, chans = [Axis("a", "y", 3), Axis("b", "x", 4)], {f"c{i}": "test" for i in range(nch)}
    t = Table("t", "dfg", rng.random((3, 4, nch)).astype(np.float32), axes, chans, "", {})
    for fmt in ("ktx2", "ktx2zst"):
        blob = write_table(t, tmp_path / fmt, fmt, dtype).read_bytes()
        vk, type_size = struct.unpack_from("<2I", blob, 12)
        assert type_size == ktx2_spec_type_size(vk) == (2 if dtype == "half" else 4), (fmt, vk, type_size)


def test_ktx2_zstd_header_and_dfd_equal_bevys_shipped_dfg_ktx2(tmp_path):
    """Bevy's dfg.ktx2 (tests/data/bevy_dfg.ktx2, written by `ktx create` v4.4.2) and lutbake's zstd KTX2 of an RG16F
    table: the same vkFormat, typeSize, supercompressionScheme and byte-identical data format descriptors."""
    bevy = (Path(__file__).parent / "data" / "bevy_dfg.ktx2").read_bytes()
    axes, chans = [Axis("a", "y", 64), Axis("b", "x", 64)], {"scale": "", "bias": ""}
    t = Table("t", "dfg", np.zeros((64, 64, 2), np.float32), axes, chans, "", {})
    ours = write_table(t, tmp_path, "ktx2zst", "half").read_bytes()

    def fields(blob):
        vk, type_size, w, h, d, layers, faces, levels, scheme = struct.unpack_from("<9I", blob, 12)
        dfd_off, dfd_len = struct.unpack_from("<2I", blob, 48)
        return (vk, type_size, w, h, d, layers, faces, levels, scheme), blob[dfd_off : dfd_off + dfd_len]

    (head_b, dfd_b), (head_o, dfd_o) = fields(bevy), fields(ours)
    assert head_b == (83, 2, 64, 64, 0, 0, 1, 1, 2)
    assert head_o == head_b
    assert dfd_o == dfd_b
