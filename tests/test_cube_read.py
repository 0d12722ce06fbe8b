"""Cube pixel readers (lutbake.io.cube_read) and the packed encodings (lutbake.io.encodings): RGB9E5 and B10G11R11
against decodings and searches written here from the specs (not the package's), known bit patterns, every
container and dtype written and read back, engines' files (Bevy's zstd RGB9E5 KTX 2.0, Filament's KTX 1.1), hostile
files refused in one line, `lutbake inspect` describing pixels and `read` refusing a cube with a pointer."""

from __future__ import annotations

import json
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest
import zstandard
from click.testing import CliRunner

from lutbake.cli import main
from lutbake.io import encodings
from lutbake.io.cube_read import read_cube
from lutbake.io.cubemap import encode_ktx2_cube, write_cube
from lutbake.io.ktx1 import encode_ktx1_cube
from lutbake.io.readers import ReadError, read

DATA = Path(__file__).parent / "data"
BEVY = DATA / "bevy_pisa_diffuse_rgb9e5_zstd.ktx2"
FILAMENT = DATA / "filament_pillars_2k_ibl_mips1-4.ktx"
RNG = np.random.default_rng(7)


# --------------------------------------------------------------------------- the spec's decodings, written here


def rgb9e5_value(word: int) -> tuple[float, float, float]:
    """EXT_texture_shared_exponent: component = mantissa * 2^(exponent - 15 - 9)."""
    e = word >> 27
    return tuple(((word >> (9 * c)) & 511) * 2.0 ** (e - 24) for c in range(3))


def small_float_value(code: int, mantissa_bits: int) -> float:
    """Vulkan §3.9: unsigned 11/10-bit floats, exponent bias 15, subnormals 2^-14 m / 2^M."""
    e, m = code >> mantissa_bits, code & ((1 << mantissa_bits) - 1)
    if e == 0:
        return 2.0**-14 * m / 2**mantissa_bits
    return 2.0 ** (e - 15) * (1 + m / 2**mantissa_bits)


def rgb9e5_by_search(rgb) -> int:
    """The spec's encoding restated: the smallest shared exponent at which the largest component, rounded half up,
    fits 9 bits; every mantissa rounded half up at it."""
    rgb = [min(max(float(v), 0.0), encodings.RGB9E5_MAX) for v in rgb]
    for e in range(32):
        mant = [int(np.floor(v / 2.0 ** (e - 24) + 0.5)) for v in rgb]
        if max(mant) <= 511:
            return e << 27 | mant[2] << 18 | mant[1] << 9 | mant[0]
    raise AssertionError(rgb)


# ------------------------------------------------------------------------------------------------ encodings


@pytest.mark.parametrize(
    "rgb, word",
    [
        ((1.0, 1.0, 1.0), 0x84020100),  # exponent 16, mantissas 256
        ((0.0, 0.0, 0.0), 0x00000000),
        ((65408.0, 65408.0, 65408.0), 0xFFFFFFFF),  # sharedexp_max: exponent 31, mantissas 511
        ((2.0**-24, 0.0, 0.0), 0x00000001),  # the smallest step: exponent 0, mantissa 1
        ((0.5, 0.25, 0.125), 0x79010100),  # exponent 15: 256, 128, 64
        ((511.5 / 512, 0.0, 0.0), 0x80000100),  # rounds up to 512: the exponent steps up (max_s = 2^N)
    ],
)
def test_rgb9e5_known_bit_patterns(rgb, word):
    assert int(encodings.encode_rgb9e5(np.array(rgb))) == word
    np.testing.assert_array_equal(encodings.decode_rgb9e5(np.uint32(word)), rgb9e5_value(word))


def test_rgb9e5_matches_the_specs_encoding_restated_as_a_search():
    values = RNG.random((3000, 3)) * np.exp(RNG.uniform(-18, 11, (3000, 1)))
    values[::7, 1] = 0.0
    words = encodings.encode_rgb9e5(values)
    for rgb, word in zip(values[:600], words[:600]):
        assert int(word) == rgb9e5_by_search(rgb), rgb
    decoded = np.array([rgb9e5_value(int(w)) for w in words])
    np.testing.assert_array_equal(encodings.decode_rgb9e5(words), decoded)
    step = 2.0 ** ((words >> 27).astype(float) - 24)  # half a mantissa step at the shared exponent, at most
    assert np.all(np.abs(decoded - values) <= step[:, None] / 2 * (1 + 1e-12))


def test_b10g11r11_is_the_nearest_code_ties_to_even():
    codes11, codes10 = np.arange(31 << 6), np.arange(31 << 5)  # every finite code
    table = {
        6: np.array([small_float_value(c, 6) for c in codes11]),
        5: np.array([small_float_value(c, 5) for c in codes10]),
    }
    values = RNG.random((2000, 3)) * np.exp(RNG.uniform(-18, 11, (2000, 1)))
    values = np.minimum(values, encodings.B10G11R11_MAX)
    words = encodings.encode_b10g11r11(values)
    for c, (m, shift) in enumerate(((6, 0), (6, 11), (5, 22))):
        got = (words >> shift) & ((1 << (m + 5)) - 1)
        dist = np.abs(table[m][None, :] - values[:, c : c + 1])
        best = dist.min(axis=1, keepdims=True)
        ties = dist == best  # the nearest codes; a tie goes to the even one
        want = np.where(ties.sum(1) > 1, np.argmax(ties & (np.arange(dist.shape[1]) % 2 == 0), 1), np.argmin(dist, 1))
        np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(encodings.decode_b10g11r11(words)[:, c], table[m][got])


@pytest.mark.parametrize(
    "rgb, word",
    [
        ((1.0, 1.0, 1.0), 0x781E03C0),  # 15 << 6 in R and G, 15 << 5 in B
        ((65024.0, 65024.0, 64512.0), 0xF7FDFFBF),  # the largest finite values
        ((2.0**-20, 0.0, 0.0), 0x1),  # the smallest subnormal of an 11-bit float: 2^-14 / 64
        ((1.0 + 2**-7, 0.0, 0.0), 0x3C0),  # half a step above 1: a tie, to the even mantissa 0
        ((1.0 + 3 * 2**-7, 0.0, 0.0), 0x3C2),  # 1.5 steps: a tie, to the even mantissa 2
        ((-3.0, 0.0, 0.0), 0x0),  # negative: 0
    ],
)
def test_b10g11r11_known_bit_patterns(rgb, word):
    assert int(encodings.encode_b10g11r11(np.array(rgb))) == word


@pytest.mark.parametrize("dtype", ["rgb9e5", "b10g11r11"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, 70000.0])
def test_packed_encoders_refuse_what_the_format_cannot_hold(dtype, bad):
    with pytest.raises(ValueError, match="not finite|past the largest"):
        encodings.ENCODERS[dtype](np.array([1.0, bad, 0.5]))


# --------------------------------------------------------------------------------------- written, read back


@pytest.fixture(scope="module")
def mips():
    return [RNG.random((6, 8 >> m, 8 >> m, 3)) * 30 for m in range(4)]


ROUND = {
    "half": lambda a: a.astype(np.float16).astype(float),
    "float32": lambda a: a.astype(np.float32).astype(float),
    "rgb9e5": lambda a: encodings.decode_rgb9e5(encodings.encode_rgb9e5(a)),
    "b10g11r11": lambda a: encodings.decode_b10g11r11(encodings.encode_b10g11r11(a)),
}


@pytest.mark.parametrize(
    "fmt, dtype",
    [(f, d) for f in ("ktx2", "dds") for d in ROUND] + [("exr", "half"), ("exr", "float32"), ("ktx1", "float32")],
)
def test_every_written_cube_reads_back_its_values_faces_and_record(tmp_path, mips, fmt, dtype):
    path = write_cube(mips, tmp_path / f"c.{fmt}", {"kind": "environment_specular", "mip_curve": "linear"}, fmt, dtype)
    cube = read_cube(path)
    assert cube.container == fmt and len(cube.mips) == 4 and cube.transfer == "linear"
    for got, want in zip(cube.mips, mips):
        np.testing.assert_array_equal(got, ROUND[dtype](want))
    assert cube.record["mip_curve"] == "linear"


def test_packed_dtypes_are_refused_in_exr_and_ktx1(tmp_path, mips):
    for fmt in ("exr", "ktx1"):
        with pytest.raises(ValueError, match="ktx2 and dds cubes only"):
            write_cube(mips, tmp_path / f"c.{fmt}", {}, fmt, "rgb9e5")
        assert not list(tmp_path.iterdir())


def test_a_packed_ktx2_has_the_dfd_and_type_size_of_the_format():
    blob = encode_ktx2_cube([np.ones((6, 2, 2, 3))], {}, "rgb9e5")
    vk, type_size = struct.unpack_from("<2I", blob, 12)
    dfd_off, dfd_len = struct.unpack_from("<2I", blob, 48)
    words = struct.unpack_from(f"<{dfd_len // 4}I", blob, dfd_off)
    assert (vk, type_size, dfd_len) == (123, 4, 4 + 24 + 6 * 16)
    # KDF 1.3's E5B9G9R9 samples: per channel a 9-bit mantissa (upper 8448) and the shared 5-bit exponent at bit 27
    samples = [words[7 + 4 * k : 11 + 4 * k] for k in range(6)]
    assert [(s[0] & 0xFFFF, (s[0] >> 16) & 0xFF, s[0] >> 24) for s in samples] == [
        (0, 8, 0),
        (27, 4, 0x20),
        (9, 8, 1),
        (27, 4, 0x21),
        (18, 8, 2),
        (27, 4, 0x22),
    ]
    assert [(s[2], s[3]) for s in samples] == [(0, 8448), (15, 31)] * 3


# ----------------------------------------------------------------------------------------- engines' files


def test_bevy_pisa_diffuse_reads_as_its_zstd_rgb9e5_words_decoded_by_the_spec():
    cube = read_cube(BEVY)
    assert (cube.container, cube.pixel_format, cube.size, len(cube.mips)) == ("ktx2", "E5B9G9R9_UFLOAT_PACK32", 32, 1)
    assert cube.facts["supercompression"] == "zstd" and cube.record is None
    blob = BEVY.read_bytes()
    off, length, raw_len = struct.unpack_from("<3Q", blob, 80)
    raw = zstandard.ZstdDecompressor().decompress(blob[off : off + length], max_output_size=raw_len)
    words = struct.unpack(f"<{6 * 32 * 32}I", raw)
    want = np.array([rgb9e5_value(w) for w in words]).reshape(6, 32, 32, 3)
    np.testing.assert_array_equal(cube.mips[0], want)


def test_filament_ktx1_reads_its_r11g11b10f_levels_and_sh():
    cube = read_cube(FILAMENT)
    assert (cube.container, cube.pixel_format, [m.shape[1] for m in cube.mips]) == (
        "ktx1",
        "R11F_G11F_B10F",
        [128, 64, 32, 16],
    )
    assert len(cube.facts["sh"].split()) == 27
    blob = FILAMENT.read_bytes()
    start = 64 + struct.unpack_from("<I", blob, 60)[0] + 4  # header, key/value data, mip 0's imageSize
    word = struct.unpack_from("<I", blob, start)[0]  # +X, row 0, column 0
    want = [
        small_float_value(word & 0x7FF, 6),
        small_float_value((word >> 11) & 0x7FF, 6),
        small_float_value(word >> 22, 5),
    ]
    np.testing.assert_array_equal(cube.mips[0][0, 0, 0], want)


# ---------------------------------------------------------------------------------------------- hostile files


def ktx2_cube(vk=97, size=4, levels=1, faces=6, layers=0, scheme=0, level_bytes=None, raw_len=None, data=None):
    texel = {97: 8, 123: 4, 37: 4}.get(vk, 8)
    need = 6 * size * size * texel
    data = data if data is not None else b"\0" * need
    head = b"\xabKTX 20\xbb\r\n\x1a\n" + struct.pack("<9I", vk, 2, size, size, 0, layers, faces, levels, scheme)
    head += struct.pack("<4I2Q", 0, 0, 0, 0, 0, 0)
    offset = 80 + 24 * max(levels, 1)
    index = b"".join(
        struct.pack("<3Q", offset, level_bytes if level_bytes is not None else len(data), raw_len or need)
        for _ in range(min(max(levels, 1), 4))
    )
    return head + index + data


HOSTILE = {
    "truncated header": lambda: ktx2_cube()[:60],
    "faceCount 1": lambda: ktx2_cube(faces=1),
    "layerCount 2": lambda: ktx2_cube(layers=2),
    "an unknown vkFormat": lambda: ktx2_cube(vk=131),  # BC6H
    "levelCount 40": lambda: ktx2_cube(levels=40),
    "more levels than the chain": lambda: ktx2_cube(size=4, levels=4),
    "a face of 2^20 texels a side": lambda: ktx2_cube(size=1 << 20, data=b"\0" * 64),
    "a level past the file": lambda: ktx2_cube(level_bytes=1 << 40),
    "BasisLZ": lambda: ktx2_cube(scheme=1),
    "a zstd bomb": lambda: ktx2_cube(scheme=2, data=zstandard.ZstdCompressor().compress(b"\0" * (1 << 22))),
    "zstd shorter than declared": lambda: ktx2_cube(scheme=2, data=zstandard.ZstdCompressor().compress(b"\0" * 10)),
    "zlib garbage": lambda: ktx2_cube(scheme=3, data=b"not zlib at all"),
    "a zlib bomb": lambda: ktx2_cube(scheme=3, data=zlib.compress(b"\0" * (1 << 22))),
    "a DDS that is no cube": lambda: b"DDS " + struct.pack("<7I", 124, 0, 4, 4, 0, 0, 1) + b"\0" * 120,
    "a DDS cube cut short": lambda: (
        b"DDS "
        + struct.pack("<7I", 124, 0, 4, 4, 0, 0, 1)
        + b"\0" * 44
        + struct.pack("<II4s5I", 32, 4, b"DX10", 0, 0, 0, 0, 0)
        + struct.pack("<5I", 0x1000, 0xFE00, 0, 0, 0)
        + struct.pack("<5I", 10, 3, 4, 1, 0)
        + b"\0" * 10
    ),
    "a KTX1 of 2^20 texels a side": lambda: (
        encode_ktx1_cube([np.ones((6, 4, 4, 3))], "half")[:36]
        + struct.pack("<2I", 1 << 20, 1 << 20)
        + encode_ktx1_cube([np.ones((6, 4, 4, 3))], "half")[44:]
    ),
    "garbage": lambda: b"\x00\x01garbage" * 10,
}


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_a_hostile_cube_file_is_one_valueerror_naming_the_file(tmp_path, case):
    path = tmp_path / "hostile.ktx2"
    path.write_bytes(HOSTILE[case]())
    with pytest.raises(ValueError) as e:
        read_cube(path)
    assert str(e.value).startswith(str(path)) and "\n" not in str(e.value)


def test_a_zstd_level_is_decompressed_to_its_declared_size_only(tmp_path):
    good = np.full((6 * 4 * 4, 4), 2.0, np.float16).tobytes()
    path = tmp_path / "z.ktx2"
    path.write_bytes(ktx2_cube(scheme=2, data=zstandard.ZstdCompressor().compress(good)))
    np.testing.assert_array_equal(read_cube(path).mips[0], 2.0)


# ---------------------------------------------------------------------------------- inspect, read's refusal


def test_inspect_describes_an_engines_cube_and_its_pixels():
    r = CliRunner().invoke(main, ["inspect", str(BEVY)])
    assert r.exit_code == 0, r.output
    assert "E5B9G9R9_UFLOAT_PACK32, 32 x 32 faces, 1 mip(s)" in r.output and "no lutbake record" in r.output
    mean = float(r.output.split("\n  0    32     R        ")[1].split()[2])
    cube = read_cube(BEVY).mips[0]
    from lutbake.environment.cube import texel_solid_angles

    w = texel_solid_angles(32)
    assert mean == pytest.approx(float((cube[..., 0] * w).sum() / (4 * np.pi)), rel=1e-5)


def test_inspect_of_a_lutbake_cube_keeps_its_record_and_adds_pixels(tmp_path, mips):
    path = write_cube(mips, tmp_path / "c.ktx2", {"kind": "environment_specular", "mip_curve": "linear"}, "ktx2")
    out = CliRunner().invoke(main, ["inspect", str(path)]).output
    assert "mip_curve: linear" in out and "pixels (linear RGB" in out and out.count("\n  3    1      R") == 1


def test_read_refuses_a_cube_and_points_to_inspect_audit_and_read_cube():
    for path in (BEVY, FILAMENT):
        with pytest.raises(ReadError, match="lutbake audit.*read_cube"):
            read(path)


def test_the_provenance_notes_name_the_bytes_committed():
    import hashlib

    for name in ("filament_pillars_2k_ibl_mips1-4", "bevy_pisa_diffuse_rgb9e5_zstd"):
        note = json.loads((DATA / f"{name}.json").read_text())
        blob = next(DATA.glob(f"{name}.ktx*")).read_bytes()
        assert hashlib.sha256(blob).hexdigest() == note.get("sha256", note["source"].get("sha256"))
