"""Filament's image-based light as lutbake writes it: the KTX 1 cube in cmgen's layout (lutbake.io.ktx1) and the SH in
the form Filament's shader takes (lutbake.environment.sh form ``filament``). Header fields and the R11F_G11F_B10F
rounding against the formats' definitions, the SH against closed forms. In the engine: tests/test_web_filament.py."""

from __future__ import annotations

import re
import struct

import numpy as np
import pytest

from lutbake.environment import cube, sh
from lutbake.environment.latlong import directions
from lutbake.io.cubemap import write_cube
from lutbake.io.ktx1 import (
    FORMATS,
    decode_ktx1_cube,
    encode_ktx1_cube,
    pack_r11g11b10f,
    unpack_r11g11b10f,
)

RNG = np.random.default_rng(7)
SH_ATOL = 2e-5  # a 512 x 256 lat-long of a smooth function against its closed form (texel-constant: O(texel²))


def small_float_values(mantissa: int) -> np.ndarray:
    """Every finite value of an unsigned float with 5 exponent bits (bias 15) and ``mantissa`` bits, code order: the
    GL ES 3.0 §2.1.3 definition, written out here on its own."""
    out = []
    for e in range(31):
        for m in range(2**mantissa):
            out.append(2.0**-14 * m / 2**mantissa if e == 0 else 2.0 ** (e - 15) * (1 + m / 2**mantissa))
    return np.array(out)


def mips_of(radiance, size=16, smallest=4):
    return [radiance(cube.texel_centres(n)) for n in (size >> m for m in range(8)) if n >= smallest]


@pytest.mark.parametrize("channel, mantissa", [(0, 6), (1, 6), (2, 5)])
def test_r11g11b10f_rounds_each_value_to_a_nearest_code(channel, mantissa):
    """cmgen's packing (math::fp<0, 5, M>::fromf) lands on a code nearest the value (a tie rounds up) in the normal
    range; below it (2^-14) fromf rounds at the normal mantissa's position and its float multiply then truncates, so
    a value lands within one subnormal step 2^-14 / 2^M of its own."""
    codes = small_float_values(mantissa)
    x = np.concatenate([10.0 ** RNG.uniform(-7, np.log10(64512), 4000), codes[1:200:7], [64512.0, 1.0, 0.5]])
    x = x.astype(np.float32).astype(np.float64)
    rgb = np.zeros((len(x), 3))
    rgb[:, channel] = x
    packed = pack_r11g11b10f(rgb)
    got = unpack_r11g11b10f(packed)[:, channel]
    normal = x >= 2.0**-14
    nearest = np.abs(codes[None, :] - x[normal, None]).min(axis=1)
    np.testing.assert_allclose(np.abs(got - x)[normal], nearest, rtol=1e-12, atol=0)
    assert np.all(np.abs(x - got)[~normal] < 2.0**-14 / 2**mantissa) and (~normal).sum() > 100
    assert np.all(unpack_r11g11b10f(packed)[:, [c for c in range(3) if c != channel]] == 0)


def test_r11g11b10f_known_bits_and_its_tie_rule():
    # 1.0: exponent 15, mantissa 0 in each field: R 0x3C0, G 0x3C0 << 11, B 0x1E0 << 22
    assert int(pack_r11g11b10f(np.ones(3))) == 0x3C0 | 0x3C0 << 11 | 0x1E0 << 22
    assert int(pack_r11g11b10f(np.zeros(3))) == 0
    halfway = 1 + 2.0**-7  # between 1 and 1 + 2^-6 (R's step at 1): fromf adds one at the first dropped bit
    assert unpack_r11g11b10f(pack_r11g11b10f(np.array([halfway, 0, 0])))[0] == 1 + 2.0**-6


@pytest.mark.parametrize("fmt", sorted(FORMATS))
def test_ktx1_cube_has_cmgens_header_and_level_layout(fmt):
    mips = mips_of(lambda d: 0.5 + 0.25 * d)
    coefficients = RNG.uniform(-1, 1, (9, 3))
    blob = encode_ktx1_cube(mips, fmt, coefficients, {"kind": "environment_specular"})
    fields = struct.unpack_from("<12s13I", blob)
    assert fields[0] == bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])
    gl_type, type_size, gl_format, internal, base, texel = FORMATS[fmt]
    assert fields[1:7] == (0x04030201, gl_type, type_size, gl_format, internal, base)
    assert fields[7:13] == (16, 16, 0, 0, 6, 3)  # width, height, depth, array elements, faces, levels
    if fmt == "r11g11b10f":  # cmgen's KtxInfo: every GL enum R11F_G11F_B10F, glTypeSize 1
        assert fields[2] == fields[4] == fields[5] == fields[6] == 0x8C3A and fields[3] == 1
    pos = 64 + fields[13]
    for side in (16, 8, 4):
        assert struct.unpack_from("<I", blob, pos)[0] == side * side * texel  # imageSize: one face's bytes
        pos += 4 + 6 * side * side * texel
    assert pos == len(blob)
    got, got_fmt, pairs = decode_ktx1_cube(blob)
    assert got_fmt == fmt and sorted(pairs) == ["lutbake:metadata", "sh"]
    for a, b in zip(got, mips):
        if fmt == "r11g11b10f":
            np.testing.assert_allclose(a, b, rtol=2.0**-6)
        else:
            np.testing.assert_allclose(a, b, rtol=2.0**-11 if fmt == "half" else 1e-7)


def test_ktx1_sh_text_parses_as_filament_js_and_ktx1bundle_read_it():
    """filament.js: shstring.split(/\\s/, 27).map(parseFloat); Ktx1Bundle::getSphericalHarmonics: 27 strtof calls."""
    coefficients = RNG.uniform(-3, 3, (9, 3))
    _, _, pairs = decode_ktx1_cube(encode_ktx1_cube(mips_of(np.ones_like), sh=coefficients))
    tokens = re.split(r"\s", pairs["sh"])[:27]
    np.testing.assert_allclose(np.array(tokens, float).reshape(9, 3), coefficients, rtol=1e-7)
    assert pairs["sh"].count("\n") == 9 and "  " not in pairs["sh"]


@pytest.mark.parametrize(
    "values, fmt, fragment",
    [
        (-0.01, "r11g11b10f", "outside [0"),
        (70000.0, "r11g11b10f", "64512"),
        (np.nan, "float32", "not finite"),
        (70000.0, "half", "65504"),
    ],
)
def test_ktx1_refuses_values_the_format_cannot_hold(values, fmt, fragment):
    mips = mips_of(np.ones_like)
    mips[1] = mips[1].copy()
    mips[1][2, 0, 0, 1] = values
    with pytest.raises(ValueError, match=re.escape(fragment)) as e:
        encode_ktx1_cube(mips, fmt)
    assert "mip 1 face 2" in str(e.value)


def test_ktx1_refuses_a_face_filament_would_read_without_its_padding():
    mips = [np.ones((6, n, n, 3)) for n in (2, 1)]
    with pytest.raises(ValueError, match="padding"):
        encode_ktx1_cube(mips, "half")  # a 1x1 RGB16F face is 6 bytes
    assert decode_ktx1_cube(encode_ktx1_cube(mips, "r11g11b10f"))[0][1].shape == (6, 1, 1, 3)


def test_ktx1_decoder_names_what_does_not_fit():
    blob = encode_ktx1_cube(mips_of(np.ones_like))
    with pytest.raises(ValueError, match="level 2"):
        decode_ktx1_cube(blob[:-8])
    with pytest.raises(ValueError, match="identifier"):
        decode_ktx1_cube(b"\0" * 64)


def test_write_cube_writes_filaments_ktx1(tmp_path):
    mips = mips_of(lambda d: 1 + d * 0.5)
    path = write_cube(
        mips, tmp_path / "env_ibl.ktx", {"kind": "environment_specular"}, "ktx1", "r11g11b10f", sh=np.eye(9, 3)
    )
    got, fmt, pairs = decode_ktx1_cube(path.read_bytes())
    assert fmt == "r11g11b10f" and len(got) == 3 and '"kind": "environment_specular"' in pairs["lutbake:metadata"]


def fine_latlong(radiance, h=256):
    theta = (np.arange(h) + 0.5) / h * np.pi
    phi = (np.arange(2 * h) + 0.5) / (2 * h) * 2 * np.pi - np.pi
    return radiance(directions(theta[:, None], phi[None, :]))


def test_sh_filament_form_of_a_linear_environment_is_its_closed_form():
    """L = a + b.ω: E(n)/pi = a + 2/3 b.n (Â_1 / Â_0 = 2/3), so c = (a, 2/3 b_y, 2/3 b_z, 2/3 b_x, 0, ...)."""
    a, b = np.array([0.6, 0.2, 1.5]), np.array([[0.3, -0.1, 0.05], [0.0, 0.4, -0.2], [-0.25, 0.1, 0.3]])  # b[axis, c]
    c = sh.convolve(sh.project(fine_latlong(lambda d: a + d @ b)), "filament")
    expected = np.zeros((9, 3))
    expected[0] = a
    expected[[3, 1, 2]] = 2 / 3 * b
    np.testing.assert_allclose(c, expected, atol=SH_ATOL)


def test_sh_filament_form_of_z_squared_is_its_closed_form():
    """L = z²: 1/3 + (3z² - 1)/3, band 2 scaled by Â_2 / pi = 1/4: c_0 = 1/3, c_6 = 1/12 (on 3z² - 1)."""
    c = sh.convolve(sh.project(fine_latlong(lambda d: d[..., 2:3] ** 2)), "filament")[:, 0]
    expected = np.zeros(9)
    expected[0], expected[6] = 1 / 3, 1 / 12
    np.testing.assert_allclose(c, expected, atol=SH_ATOL)


def test_sh_filament_form_on_the_bare_polynomials_is_irradiance_over_pi():
    radiance = RNG.normal(size=(9, 2))
    d = RNG.normal(size=(50, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    np.testing.assert_allclose(
        sh.polynomials(d) @ sh.convolve(radiance, "filament"),
        sh.evaluate(sh.convolve(radiance, "irradiance_over_pi"), d),
        rtol=1e-12,
        atol=1e-12,
    )
