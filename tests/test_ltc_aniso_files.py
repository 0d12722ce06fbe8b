"""Kind ltc_aniso's 3D texture files (lutbake.io.ltc_aniso_textures): ``format = "ktx2"`` / ``"dds"`` write
<name>_t0, _t1, _t2, each one 3D texture of docs/shaders/ltc_aniso.glsl, byte for byte the EXR's part and the npy's
slice in glTexImage3D order; their headers against the KTX 2.0 specification and Microsoft's DDS documentation (the
independent readers of test_formats, and the constants checked here), three.js's KTX2Loader loading each KTX2 as a
Data3DTexture (node; skipped without web/node_modules/three), the reader's round trip and refusals, the three files
verified as one unit, ``lutbake inspect`` of each file, the files a config plans."""

import json
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from test_formats import read_dds_spec, read_ktx2_spec

from lutbake.api import bake
from lutbake.batch import schedule
from lutbake.cli import main
from lutbake.config import load_configs
from lutbake.errors import ConfigError
from lutbake.io import dds, ktx2
from lutbake.io.integrity import verified_attributes
from lutbake.io.ltc_aniso_textures import TEXTURES, read_textures
from lutbake.io.readers import read_table
from lutbake.io.sidecar import ReadError

N = 3  # texels per axis: textures 3 x 3 x 9
THREE = Path(__file__).resolve().parents[1] / "web" / "node_modules" / "three"
TABLES = {  # name -> (format, dtype): one fit, written eight ways (lutbake.sharing: computed once)
    "lx": ("exr", "float32"),
    "ln": ("npy", "float32"),
    "lnh": ("npy", "half"),
    "lp": ("ltc_aniso_npy", "float32"),
    "lk": ("ktx2", "half"),
    "lk32": ("ktx2", "float32"),
    "ld": ("dds", "half"),
    "ld32": ("dds", "float32"),
}
# Vulkan's VkFormat (vulkan_core.h): VK_FORMAT_R16G16B16A16_SFLOAT = 97, VK_FORMAT_R32G32B32A32_SFLOAT = 109;
# DXGI_FORMAT (dxgiformat.h): DXGI_FORMAT_R16G16B16A16_FLOAT = 10, DXGI_FORMAT_R32G32B32A32_FLOAT = 2
VK_FORMAT = {"half": 97, "float32": 109}
DXGI_FORMAT = {"half": 10, "float32": 2}
# Microsoft, "DDS_HEADER structure" (learn.microsoft.com/windows/win32/direct3ddds/dds-header): dwFlags DDSD_DEPTH
# 0x800000 ("Required in a depth texture"), dwCaps DDSCAPS_TEXTURE 0x1000 ("Required"), dwCaps2 DDSCAPS2_VOLUME
# 0x200000 ("Required for a volume texture"); "DDS_HEADER_DXT10 structure": resourceDimension
# D3D10_RESOURCE_DIMENSION_TEXTURE3D = 4, arraySize "For a 3D texture, you must set this number to 1"
DDSD_DEPTH, DDSCAPS_TEXTURE, DDSCAPS2_VOLUME, DIMENSION_TEXTURE3D = 0x800000, 0x1000, 0x200000, 4


def files_of(out: Path, name: str) -> list[Path]:
    ext = "ktx2" if TABLES[name][0] == "ktx2" else "dds"
    return [out / f"{name}_t{k}.{ext}" for k in range(3)]


@pytest.fixture(scope="module")
def baked(tmp_path_factory) -> dict:
    tmp = tmp_path_factory.mktemp("ltc_aniso_files")
    cfg = tmp / "la.toml"
    cfg.write_text(
        "".join(
            f'[[table]]\nname = "{name}"\nkind = "ltc_aniso"\nsize = {N}\nfit_samples = 8\nsamples = 256\n'
            f'format = "{fmt}"\ndtype = "{dtype}"\n\n'
            for name, (fmt, dtype) in TABLES.items()
        )
    )
    out = tmp / "out"
    bake(cfg, out, workers=1)
    return {
        "cfg": cfg,
        "out": out,
        "float32": np.load(out / "ln.npy"),  # (3, N^3, N, 4)
        "half": np.load(out / "lnh.npy"),
        "exr": read_table(out / "lx.exr").data,
        "paper": np.load(out / "lp.npy"),  # M (N, N, N, N, 3, 3)
    }


def texture_bytes(path: Path) -> tuple[np.ndarray, int]:
    """(the texels as stored, the pixel format code) by the spec readers of test_formats."""
    blob = path.read_bytes()
    arr, fmt = (read_ktx2_spec(blob)[:2]) if path.suffix == ".ktx2" else read_dds_spec(blob)
    return arr, fmt


@pytest.mark.parametrize("name", ["lk", "lk32", "ld", "ld32"])
def test_each_file_is_the_exr_part_and_the_npy_slice_byte_for_byte(baked, name):
    dtype = TABLES[name][1]
    for k, path in enumerate(files_of(baked["out"], name)):
        arr, _ = texture_bytes(path)
        assert arr.shape == (N * N, N, N, 4)  # depth = layers, height = theta, width = phi, RGBA
        assert arr.tobytes() == np.ascontiguousarray(baked[dtype][k]).tobytes()
        if dtype == "float32":
            assert arr.tobytes() == np.ascontiguousarray(baked["exr"][k]).tobytes()


def test_texels_are_in_glteximage3d_order(baked):
    """Texel (x = phi l, y = theta k, z = layer b + N a) of t0 at byte ((z N + y) N + x) 16 of level 0 is
    (M00, M01, M02, M10) of M[a, b, k, l] in the paper's layout (format ltc_aniso_npy); t1 and t2 likewise."""
    m = baked["paper"].reshape(N, N, N, N, 9)
    for k, path in enumerate(files_of(baked["out"], "lk32")):
        blob = path.read_bytes()
        (offset,) = struct.unpack_from("<Q", blob, 80)  # KTX 2.0 §3.9: level 0's byteOffset
        for a, b, t, p in [(0, 0, 0, 0), (2, 1, 0, 1), (1, 2, 2, 0), (2, 0, 1, 2)]:
            x, y, z = p, t, b + N * a
            texel = struct.unpack_from("<4f", blob, offset + ((z * N + y) * N + x) * 16)
            want = list(m[a, b, t, p, 4 * k : 4 * k + 4]) if k < 2 else [m[a, b, t, p, 8]]
            np.testing.assert_array_equal(texel[: len(want)], np.float32(want))


@pytest.mark.parametrize("dtype", ["half", "float32"])
def test_ktx2_headers_follow_the_khronos_specification(baked, dtype):
    """KTX 2.0 §3.4 vkFormat, §3.3 typeSize, §3.5 pixelDepth (3D: the depth), §3.6 layerCount 0 (no array), §3.7
    faceCount 1, §3.8 levelCount 1, supercompressionScheme 0; the DFD (RGBSDA, BT.709, linear, signed float samples)
    and the sorted key/value data by read_ktx2_spec."""
    for k, path in enumerate(files_of(baked["out"], "lk" if dtype == "half" else "lk32")):
        blob = path.read_bytes()
        _, vk, channels, kv, (depth, layers) = read_ktx2_spec(blob)
        head = struct.unpack_from("<9I", blob, 12)
        assert head == (VK_FORMAT[dtype], 2 if dtype == "half" else 4, N, N, N * N, 0, 1, 1, 0)
        assert vk == VK_FORMAT[dtype] and channels == [0, 1, 2, 15] and (depth, layers) == (N * N, 0)
        assert kv["KTXorientation"] == "rdi" and kv["KTXwriter"].startswith("lutbake ")
        record = json.loads(kv["lutbake:metadata"])
        assert record["kind"] == "ltc_aniso" and record["ltc_aniso_texture"].startswith(f"t{k} = (")
        assert json.loads(record["channel_names"]) == dict(zip("RGBA", TEXTURES[f"t{k}"]))


@pytest.mark.parametrize("dtype", ["half", "float32"])
def test_dds_headers_follow_microsofts_dds_documentation(baked, dtype):
    for path in files_of(baked["out"], "ld" if dtype == "half" else "ld32"):
        blob = path.read_bytes()
        arr, fmt = read_dds_spec(blob)
        size, flags, height, width, pitch, depth, mips = struct.unpack_from("<7I", blob, 4)
        caps, caps2 = struct.unpack_from("<II", blob, 108)
        dxgi, dim, misc, array_size, _ = struct.unpack_from("<5I", blob, 128)
        assert (size, height, width, depth, mips) == (124, N, N, N * N, 1)
        assert flags & DDSD_DEPTH and caps & DDSCAPS_TEXTURE and caps2 == DDSCAPS2_VOLUME
        assert pitch == N * 4 * (2 if dtype == "half" else 4)
        assert (dxgi, dim, misc, array_size) == (DXGI_FORMAT[dtype], DIMENSION_TEXTURE3D, 0, 1)
        assert fmt == DXGI_FORMAT[dtype] and arr.shape == (N * N, N, N, 4)


@pytest.mark.skipif(shutil.which("node") is None or not THREE.is_dir(), reason="node or web/node_modules/three missing")
def test_threejs_ktx2loader_loads_each_file_as_a_data3dtexture(baked, tmp_path):
    """three.js's own loader (examples/jsm/loaders/KTX2Loader.js, its ktx-parse and createRawTexture; no GPU): a
    Data3DTexture N x N x N^2, RGBAFormat, HalfFloatType, linear colour space, whose data are the file's texels."""
    script = tmp_path / "load.mjs"
    loader = THREE / "examples" / "jsm" / "loaders" / "KTX2Loader.js"
    script.write_text(
        f"""import {{ readFileSync }} from "node:fs";
const {{ KTX2Loader }} = await import({json.dumps(loader.as_uri())});
const THREE = await import({json.dumps((THREE / "build" / "three.module.js").as_uri())});
const loader = new KTX2Loader();
loader.workerConfig = {{}};  // detectSupport(renderer) without a renderer: only transcoded formats read it
const out = [];
for (const file of process.argv.slice(2)) {{
  const b = readFileSync(file);
  const t = await loader._createTexture(b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength));
  out.push({{is3d: t.isData3DTexture === true, size: [t.image.width, t.image.height, t.image.depth],
    rgba: t.format === THREE.RGBAFormat, half: t.type === THREE.HalfFloatType,
    linear: t.colorSpace === THREE.LinearSRGBColorSpace, data: Array.from(t.image.data)}});
}}
console.log(JSON.stringify(out));
"""
    )
    files = files_of(baked["out"], "lk")
    run = subprocess.run(["node", str(script), *map(str, files)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    for k, got in enumerate(json.loads(run.stdout)):
        assert got["is3d"] and got["rgba"] and got["half"] and got["linear"]
        assert got["size"] == [N, N, N * N]
        assert got["data"] == baked["half"][k].view(np.uint16).ravel().tolist()


@pytest.mark.parametrize("name", ["lk", "lk32", "ld", "ld32"])
def test_read_textures_gives_back_what_was_written(baked, name):
    dtype = TABLES[name][1]
    want = baked[dtype].reshape(3, N * N, N, N, 4)
    first = files_of(baked["out"], name)[0]
    sidecar = json.loads(first.with_name(first.name + ".json").read_text())
    for path in files_of(baked["out"], name):  # any of the three finds the set
        got = read_textures(path)
        assert got.data.dtype == want.dtype and np.array_equal(got.data, want)
        assert got.record == sidecar["lutbake"] and [f.name for f in got.files] == sidecar["files"]


def copied(baked, name: str, dest: Path) -> list[Path]:
    first = files_of(baked["out"], name)[0]
    for p in [*files_of(baked["out"], name), first.with_name(first.name + ".json")]:
        shutil.copy(p, dest / p.name)
    return [dest / p.name for p in files_of(baked["out"], name)]


@pytest.mark.parametrize("name", ["lk", "ld"])
def test_a_truncated_wrong_dimension_or_missing_texture_is_refused_naming_it(baked, tmp_path, name):
    t0, t1, t2 = copied(baked, name, tmp_path)
    t1.write_bytes(t1.read_bytes()[:-7])
    with pytest.raises(ReadError, match=rf"{t1.name}: not a readable .*bytes"):
        read_textures(t0)
    shutil.copy(files_of(baked["out"], name)[1], t1)
    need = f"is 3D, depth x height x width x RGBA {N * N} x {N} x {N} x 4"
    for wrong in (np.zeros((N, N, 4), np.float16), np.zeros((N, N, N, 4), np.float16)):  # 2D; 3D, N layers
        t2.write_bytes((ktx2 if name == "lk" else dds).encode(wrong))
        with pytest.raises(ReadError) as refused:
            read_textures(t1)
        got = f"a {wrong.ndim - 1}D texture of {' x '.join(map(str, wrong.shape))}"
        assert f"{t2}: {got}; " in str(refused.value) and need in str(refused.value)
    t2.unlink()
    with pytest.raises(ReadError, match=rf"{t2.name}: not a readable"):
        read_textures(t0)


def test_a_texture_of_another_bake_is_refused(baked, tmp_path):
    _, t1, _ = copied(baked, "lk", tmp_path)
    blob = bytearray(t1.read_bytes())
    i = blob.index(b'"content_hash": "') + len(b'"content_hash": "')
    blob[i : i + 1] = b"0" if blob[i : i + 1] != b"0" else b"1"
    t1.write_bytes(bytes(blob))
    with pytest.raises(ReadError, match=rf"{t1.name}: its record is not the sidecar's table"):
        read_textures(t1)


def test_a_missing_or_edited_texture_makes_the_output_not_up_to_date(baked, tmp_path):
    """The sidecar names the sha256 of all three files (lutbake.io.integrity): the up-to-date check sees each."""
    specs = [s for s in load_configs([baked["cfg"]]) if s.name in ("lk", "ld")]

    def up_to_date() -> list[bool]:
        return [job.status == "skipped" for job in schedule(specs, tmp_path)]

    for name in ("lk", "ld"):
        copied(baked, name, tmp_path)
    assert up_to_date() == [True, True]
    for name in ("lk", "ld"):
        _, _, t2 = files_of(tmp_path, name)
        good = t2.read_bytes()
        t2.write_bytes(good[:-2] + bytes([good[-2] ^ 1]) + good[-1:])  # one bit of one texel
        assert verified_attributes(files_of(tmp_path, name)[0]) is None
        t2.write_bytes(good)
    assert up_to_date() == [True, True]
    files_of(tmp_path, "lk")[1].unlink()
    files_of(tmp_path, "ld")[2].unlink()
    assert up_to_date() == [False, False]


@pytest.mark.parametrize("file, texture", [("lk_t1.ktx2", "t1"), ("ld_t2.dds", "t2"), ("lk_t0.ktx2.json", "t0")])
def test_inspect_shows_each_textures_own_record(baked, file, texture):
    r = CliRunner().invoke(main, ["inspect", str(baked["out"] / file)])
    assert r.exit_code == 0, r.output
    out = " ".join(r.output.split())
    names = TEXTURES[texture]
    assert "kind: ltc_aniso" in out and f"image: {N * N} slices of {N} x {N}, 4 channel(s)" in out
    assert "layer: z (slices)" in out and "theta_v: y (rows)" in out and "phi_v: x (columns)" in out
    assert all(f"{c} = {n}:" in out for c, n in zip("RGBA", names))


@pytest.mark.parametrize("lobes, texture, nth", [(1, "t2", "third"), (2, "t5", "sixth"), (3, "t8", "ninth")])
def test_a_config_plans_every_texture_and_refuses_a_table_writing_one_of_them(tmp_path, lobes, texture, nth):
    """The other textures are the output's files (lutbake.preflight.planned_files; three per lobe): a table whose
    file is one of them is refused before any kernel runs."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        f'[[table]]\nname = "a"\nkind = "ltc_aniso"\nsize = 2\nfit = "shaded"\nlobes = {lobes}\nformat = "ktx2"\n\n'
        f'[[table]]\nname = "a_{texture}"\nkind = "dfg"\nsize = [4, 4]\nformat = "ktx2"\n'
    )
    with pytest.raises(ConfigError, match=f"{nth} texture of table 'a'"):
        bake(cfg, tmp_path / "out")
