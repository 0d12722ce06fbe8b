"""JS / WGSL / Rust array outputs and zstd KTX2, each read back by an independent reader:
node (JS), rustc (Rust), a parser written here (WGSL), and a KTX2 parser written here with the zstandard
package (KTX2). Node and rustc tests skip with the reason where the tool is missing."""

import json
import re
import shutil
import struct
import subprocess

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
    assert (vk, type_size, w, h, scheme) == (83, 1, W, H, 2)  # R16G16_SFLOAT, typeSize 1 when supercompressed, zstd
    off, size, raw = struct.unpack_from("<QQQ", blob, 80)
    assert raw == H * W * 2 * 2 and off + size == len(blob)
    level = zstandard.ZstdDecompressor().decompress(blob[off : off + size], max_output_size=raw)
    np.testing.assert_array_equal(np.frombuffer(level, "<f2").reshape(H, W, 2).astype(np.float32), half(table.data))
    kvd_off, kvd_len = struct.unpack_from("<II", blob, 56)
    assert b"lutbake:metadata" in blob[kvd_off : kvd_off + kvd_len]
