"""KTX 1.1 cube maps as Filament loads its image-based light: the file ``cmgen --format=ktx`` writes
(``<name>_ibl.ktx``) and ``Engine.createIblFromKtx1`` / ``ktxreader::Ktx1Reader::createTexture`` read.

- **Header** (KTX 1.1 §2): the identifier, endianness 0x04030201, glType, glTypeSize, glFormat, glInternalFormat,
  glBaseInternalFormat, pixelWidth = pixelHeight = n, pixelDepth 0, numberOfArrayElements 0, numberOfFaces 6,
  numberOfMipmapLevels M, bytesOfKeyValueData (64 bytes in all: Filament libs/image/src/Ktx1Bundle.cpp
  ``SerializationHeader``).
- **Formats** (``FORMATS``): ``r11g11b10f`` is cmgen's: every GL enum of the header R11F_G11F_B10F (0x8C3A) and
  glTypeSize 1, as tools/cmgen/src/cmgen.cpp ``iblRoughnessPrefilter`` fills its KtxInfo (glType 0x8C3A is not GL's
  UNSIGNED_INT_10F_11F_11F_REV; Filament's Ktx1Reader ``toPixelDataType`` maps it, and nothing else, to
  UINT_10F_11F_11F_REV); each texel one little-endian uint32, B << 22 | G << 11 | R, rounded as cmgen rounds
  (``pack_r11g11b10f``). ``half`` (HALF_FLOAT, RGB, RGB16F) and ``float32`` (FLOAT, RGB, RGB32F) are the uncompressed
  RGB float formats Ktx1Reader also uploads (filament.js ``_createIblFromKtx1`` warns about RGB16F's enum but loads
  it). cmgen's KTX offers no RGBM and no RGB9_E5: Filament's IBL shader reads linear floats, and Ktx1Reader has no
  pixel type for RGB9_E5's UNSIGNED_INT_5_9_9_9_REV.
- **Data**, level 0 first: imageSize (uint32, the bytes of one face: a non-array cube, KTX 1.1 §2.16), then the faces
  +X, -X, +Y, -Y, +Z, -Z (cmgen's ``exportKtxFaces`` order, uploaded by Filament as GL_TEXTURE_CUBE_MAP_POSITIVE_X + i),
  each face's row 0 first. The face images are lutbake.environment.cube's (GL's table; cmgen's ``Cubemap`` addresses
  its faces with the same table, row = t). Filament's Ktx1Bundle reads without cube or mip padding, so a face whose
  size is not a multiple of 4 bytes (a 1-texel ``half`` face) is refused.
- **Key/value data**: ``sh`` = the 9 RGB coefficients Filament's ``IndirectLight::Builder::irradiance`` takes
  (lutbake.environment.sh form ``filament``), one ``r g b`` line each (cmgen writes ``v.r << " " << v.g << " " << v.b
  << "\\n"``; filament.js splits the text on single white space: ``shstring.split(/\\s/, 27)``); values without a NUL
  (Ktx1Bundle::serialize writes a value's bytes only); and ``lutbake:metadata`` (JSON of lutbake's record).

Values must be finite, non-negative for ``r11g11b10f`` (cmgen's unsigned floats would write 0) and within the
format's range (r11g11b10f 64512, cmgen's clamp; half 65504): anything else is refused, never written.
"""

from __future__ import annotations

import json
import struct

import numpy as np

IDENTIFIER = bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])
ENDIANNESS = 0x04030201
GL_RGB, GL_HALF_FLOAT, GL_FLOAT = 0x1907, 0x140B, 0x1406
GL_R11F_G11F_B10F, GL_RGB16F, GL_RGB32F = 0x8C3A, 0x881B, 0x8815
# format -> (glType, glTypeSize, glFormat, glInternalFormat, glBaseInternalFormat, bytes per texel)
FORMATS = {
    "r11g11b10f": (GL_R11F_G11F_B10F, 1, GL_R11F_G11F_B10F, GL_R11F_G11F_B10F, GL_R11F_G11F_B10F, 4),
    "half": (GL_HALF_FLOAT, 2, GL_RGB, GL_RGB16F, GL_RGB, 6),
    "float32": (GL_FLOAT, 4, GL_RGB, GL_RGB32F, GL_RGB, 12),
}
MAX_VALUE = {"r11g11b10f": 64512.0, "half": 65504.0, "float32": float(np.finfo(np.float32).max)}
HEADER = struct.Struct("<12s13I")
# unsigned small floats: (exponent bits, mantissa bits) of R, G (fp11) and B (fp10); exponent bias 15
SMALL_FLOATS = ((5, 6), (5, 6), (5, 5))
SHIFTS = (0, 11, 22)


def _small_float_bits(f: np.ndarray, mantissa: int) -> np.ndarray:
    """Filament math ``fp<0, 5, M>::fromf`` (math/half.h): the float32's mantissa cut below the M kept bits, the first
    dropped bit rounding up (+ 1 << (22 - M)), the exponent rebiased by a float32 multiply with 2^(15 - 127) (so
    results below the normal range, 2^-14, come out subnormal, within one subnormal step), capped at the infinity code,
    shifted down; f <= 0 gives 0.
    ``f`` float32 >= 0, at most 64512 (cmgen's clamp)."""
    bits = np.asarray(f, np.float32).view(np.uint32).copy()
    bits &= np.uint32(~((1 << (22 - mantissa)) - 1) & 0xFFFFFFFF)
    bits += np.uint32(1 << (22 - mantissa))
    scaled = (bits.view(np.float32) * np.float32(2.0**-112)).view(np.uint32)
    scaled = np.minimum(scaled, np.uint32(31 << 23))
    return np.where(np.asarray(f) > 0, scaled >> np.uint32(23 - mantissa), 0).astype(np.uint32)


def pack_r11g11b10f(rgb: np.ndarray) -> np.ndarray:
    """(...) uint32 of (..., 3) float values >= 0: B (fp10) << 22 | G (fp11) << 11 | R (fp11), as
    image::linearToRGB_10_11_11_REV (libs/image/include/image/ColorTransform.h) packs them."""
    rgb = np.asarray(rgb, np.float32)
    out = np.zeros(rgb.shape[:-1], np.uint32)
    for c, ((_, m), shift) in enumerate(zip(SMALL_FLOATS, SHIFTS)):
        out |= (_small_float_bits(rgb[..., c], m) & np.uint32((1 << (m + 5)) - 1)) << np.uint32(shift)
    return out


def unpack_r11g11b10f(packed: np.ndarray) -> np.ndarray:
    """(..., 3) float64 of packed texels: 2^(e - 15) (1 + m / 2^M), subnormals 2^-14 m / 2^M (the GL ES 3.0 §2.1.3
    unsigned 11- and 10-bit floats); the infinity code decodes to inf."""
    packed = np.asarray(packed, np.uint32)
    out = []
    for (_, m), shift in zip(SMALL_FLOATS, SHIFTS):
        code = (packed >> np.uint32(shift)) & np.uint32((1 << (m + 5)) - 1)
        e, frac = (code >> np.uint32(m)).astype(np.float64), (code & np.uint32((1 << m) - 1)) / 2.0**m
        value = np.where(e == 0, 2.0**-14 * frac, 2.0 ** (e - 15) * (1 + frac))
        out.append(np.where(e == 31, np.inf, value))
    return np.stack(out, axis=-1)


def sh_text(coefficients: np.ndarray) -> str:
    """The ``sh`` value: 9 lines ``r g b`` of the (9, 3) coefficients, each a float32 written to 9 significant digits
    (enough to give the float32 back; cmgen writes its floats with the ostream default of 6)."""
    c = np.asarray(coefficients, np.float64)
    if c.shape != (9, 3) or not np.all(np.isfinite(c)):
        raise ValueError(f"the KTX 'sh' value takes 9 finite RGB coefficients, got shape {c.shape}")
    return "".join(" ".join(f"{float(np.float32(v)):.9g}" for v in row) + "\n" for row in c)


def _kv(pairs: dict[str, str]) -> bytes:
    """KTX 1.1 §2.10 key/value data: per pair u32 keyAndValueByteSize, the key, NUL, the value's bytes, padding to 4;
    keys sorted (Filament's Ktx1Bundle writes no NUL after a value, and so does this)."""
    out = b""
    for key in sorted(pairs):
        kv = key.encode("utf-8") + b"\0" + pairs[key].encode("utf-8")
        out += struct.pack("<I", len(kv)) + kv + b"\0" * (-len(kv) % 4)
    return out


def _face_bytes(face: np.ndarray, fmt: str, where: str) -> bytes:
    """One face (n, n, 3) in ``fmt``, rows first to last; ValueError (naming ``where``) for a value out of range."""
    a = np.asarray(face, np.float64)
    lowest = 0.0 if fmt == "r11g11b10f" else -MAX_VALUE[fmt]
    if not np.all(np.isfinite(a)) or a.min() < lowest or a.max() > MAX_VALUE[fmt]:
        raise ValueError(
            f"{where}: a value is not finite or outside [{lowest:g}, {MAX_VALUE[fmt]:g}] ({fmt}); nothing written"
        )
    if fmt == "r11g11b10f":
        data = pack_r11g11b10f(a).astype("<u4").tobytes()
    else:
        data = a.astype("<f2" if fmt == "half" else "<f4").tobytes()
    if len(data) % 4:
        raise ValueError(f"{where}: a {fmt} face of {len(data)} bytes would need KTX padding Filament does not read")
    return data


def encode_ktx1_cube(
    mips: list[np.ndarray], fmt: str = "r11g11b10f", sh: np.ndarray | None = None, metadata: dict | None = None
) -> bytes:
    """KTX 1.1 bytes of a cube with ``len(mips)`` levels, each (6, n >> m, n >> m, 3) (module docstring); ``sh`` the
    (9, 3) coefficients of form ``filament``; ``metadata`` lutbake's record."""
    if fmt not in FORMATS:
        raise ValueError(f"KTX1 cube format must be one of {sorted(FORMATS)}, got {fmt!r}")
    size = np.asarray(mips[0]).shape[1]
    levels = []
    for m, level in enumerate(mips):
        level = np.asarray(level)
        side = max(1, size >> m)
        if level.shape != (6, side, side, 3):
            raise ValueError(f"mip {m}: a cube mip of a {size}² cube is (6, {side}, {side}, 3), got {level.shape}")
        faces = [_face_bytes(level[f], fmt, f"mip {m} face {f}") for f in range(6)]
        levels.append(struct.pack("<I", len(faces[0])) + b"".join(faces))
    pairs = {} if sh is None else {"sh": sh_text(sh)}
    if metadata:
        pairs["lutbake:metadata"] = json.dumps(metadata, sort_keys=True)
    kv = _kv(pairs)
    gl_type, type_size, gl_format, internal, base, _ = FORMATS[fmt]
    head = HEADER.pack(
        IDENTIFIER, ENDIANNESS, gl_type, type_size, gl_format, internal, base, size, size, 0, 0, 6, len(mips), len(kv)
    )
    return head + kv + b"".join(levels)


def key_values(data: bytes) -> dict[str, str]:
    """The pairs of KTX 1.1 key/value data (§2.10, ``_kv``): each entry's size checked against ``data``; a value's
    trailing NULs dropped (other writers end a value with one); ValueError says what is wrong."""
    pairs, pos = {}, 0
    while pos < len(data):
        if pos + 4 > len(data):
            raise ValueError(f"KTX1 key/value entry at byte {pos} runs past the key/value data")
        (n,) = struct.unpack_from("<I", data, pos)
        if pos + 4 + n > len(data):
            raise ValueError(f"KTX1 key/value entry at byte {pos} runs past the key/value data")
        key, sep, value = data[pos + 4 : pos + 4 + n].partition(b"\0")
        if not sep:
            raise ValueError(f"KTX1 key/value entry at byte {pos} has no NUL after its key")
        pairs[key.decode("utf-8", "replace")] = value.rstrip(b"\0").decode("utf-8", "replace")
        pos += 4 + n + (-n % 4)
    return pairs


def decode_ktx1_cube(blob: bytes) -> tuple[list[np.ndarray], str, dict[str, str]]:
    """(mips as (6, n, n, 3) float64, format, key/value pairs) of a KTX 1.1 cube in one of ``FORMATS`` (what
    ``encode_ktx1_cube`` and cmgen write); every size is checked against the file's length; ValueError says what is
    wrong."""
    if len(blob) < HEADER.size or blob[:12] != IDENTIFIER:
        raise ValueError("not a KTX 1.1 file (identifier)")
    _, endian, gl_type, type_size, gl_format, internal, base, width, height, depth, layers, faces, levels, kv_len = (
        HEADER.unpack_from(blob)
    )
    fmt = next((name for name, f in FORMATS.items() if f[0] == gl_type and f[3] == internal), None)
    if endian != ENDIANNESS or fmt is None or faces != 6 or layers or depth or width != height:
        raise ValueError(
            f"not a little-endian uncompressed RGB float KTX1 cube (endianness {endian:#x}, glType {gl_type:#x}, "
            f"glInternalFormat {internal:#x}, faces {faces}, layers {layers}, depth {depth}, {width}x{height})"
        )
    if not 1 <= levels <= 32 or HEADER.size + kv_len > len(blob):
        raise ValueError(f"KTX1 numberOfMipmapLevels {levels} or bytesOfKeyValueData {kv_len} does not fit the file")
    pairs, pos = key_values(blob[HEADER.size : HEADER.size + kv_len]), HEADER.size + kv_len
    texel = FORMATS[fmt][5]
    mips = []
    for m in range(levels):
        side = max(1, width >> m)
        need = side * side * texel
        if pos + 4 > len(blob) or struct.unpack_from("<I", blob, pos)[0] != need or pos + 4 + 6 * need > len(blob):
            raise ValueError(f"KTX1 level {m}: expected imageSize {need} and 6 faces within {len(blob)} bytes")
        raw = blob[pos + 4 : pos + 4 + 6 * need]
        if fmt == "r11g11b10f":
            level = unpack_r11g11b10f(np.frombuffer(raw, "<u4"))
        else:
            level = np.frombuffer(raw, "<f2" if fmt == "half" else "<f4").astype(np.float64)
        mips.append(level.reshape(6, side, side, 3))
        pos += 4 + 6 * need
    return mips, fmt, pairs
