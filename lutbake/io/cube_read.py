"""Read the pixels of a cube map with mips, lutbake's or an engine's: ``read_cube(path)`` returns every mip as float64
(6, n, n, 3) linear RGB in lutbake's face table (lutbake.environment.cube: faces +X -X +Y -Y +Z -Z, row 0 at t = 0,
column 0 at s = 0), with the container's facts and lutbake's record where the file has one.

- **KTX 2.0**: faceCount 6, layerCount 0 or 1, no depth; supercompression none, Zstandard (2) or ZLIB (3); level m
  at the level index's offset; inside a level the faces in table order, rows t = 0 first (KTX 2.0 §3.9, §4.1: cube
  faces are stored without any flip).
- **DDS**: the DX10 header (TEXTURE2D, DDS_RESOURCE_MISC_TEXTURECUBE, arraySize 1) or a legacy header
  (DDSCAPS2_CUBEMAP with all six face bits; FourCC 113 / 116 float RGBA, or 32-bit RGBA / BGRA masks); data face by
  face, each face's mips largest first (Direct3D's subresource order; the D3D face table is GL's).
- **EXR**: lutbake's layout: one part per mip named ``mip_<m>``, the six faces stacked top to bottom.
- **KTX 1.1**: the cube Filament's cmgen writes (lutbake.io.ktx1: R11F_G11F_B10F, RGB16F, RGB32F); its ``sh`` key.

Pixel formats (``VK_PIXELS``, ``DXGI_PIXELS``): RGBA16F, RGB16F, RGBA32F, RGB32F, RGB9E5 (E5B9G9R9_UFLOAT_PACK32,
R9G9B9E5_SHAREDEXP), B10G11R11_UFLOAT_PACK32 (R11G11B10_FLOAT), RGBA8 and BGRA8 UNORM and their sRGB forms: an
``*_SRGB`` format is decoded by the sRGB EOTF (what a GPU sampler returns), a UNORM one as code / 255; alpha is dropped
(the cube's RGB is what a shader reads; RGBM / RGBD-packed files are not recognised here).

Bounded like every reader of lutbake (lutbake.io.bounded): the file is read whole only up to MAX_READ_BYTES, the
declared sizes of every mip are checked against the texel and memory caps before anything is decompressed or
allocated, a compressed level expands to exactly its declared size or is refused, and each level's bytes are checked
against the file. A ValueError names what is wrong in one line.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import bounded
from .encodings import decode_b10g11r11, decode_rgb9e5, srgb_eotf

MAX_LEVELS = 32  # a 2^31-texel face; the texel cap binds first


@dataclass(frozen=True)
class Pixels:
    """How one stored pixel format decodes: its name, bytes per texel and channels in memory order."""

    name: str
    size: int
    packing: str  # "f16x4", "f16x3", "f32x4", "f32x3", "rgb9e5", "b10g11r11", "u8x4"
    srgb: bool = False
    bgr: bool = False  # the first three channels in memory are B, G, R


_F16_RGBA = Pixels("R16G16B16A16_SFLOAT", 8, "f16x4")
_F32_RGBA = Pixels("R32G32B32A32_SFLOAT", 16, "f32x4")
_RGB9E5 = Pixels("E5B9G9R9_UFLOAT_PACK32", 4, "rgb9e5")
_B10G11R11 = Pixels("B10G11R11_UFLOAT_PACK32", 4, "b10g11r11")
VK_PIXELS = {  # VkFormat (vulkan_core.h) -> Pixels
    37: Pixels("R8G8B8A8_UNORM", 4, "u8x4"),
    43: Pixels("R8G8B8A8_SRGB", 4, "u8x4", srgb=True),
    44: Pixels("B8G8R8A8_UNORM", 4, "u8x4", bgr=True),
    50: Pixels("B8G8R8A8_SRGB", 4, "u8x4", srgb=True, bgr=True),
    90: Pixels("R16G16B16_SFLOAT", 6, "f16x3"),
    97: _F16_RGBA,
    106: Pixels("R32G32B32_SFLOAT", 12, "f32x3"),
    109: _F32_RGBA,
    122: _B10G11R11,
    123: _RGB9E5,
}
DXGI_PIXELS = {  # DXGI_FORMAT (dxgiformat.h) -> Pixels
    2: _F32_RGBA,
    6: Pixels("R32G32B32_FLOAT", 12, "f32x3"),
    10: _F16_RGBA,
    26: _B10G11R11,
    28: Pixels("R8G8B8A8_UNORM", 4, "u8x4"),
    29: Pixels("R8G8B8A8_UNORM_SRGB", 4, "u8x4", srgb=True),
    67: _RGB9E5,
    87: Pixels("B8G8R8A8_UNORM", 4, "u8x4", bgr=True),
    91: Pixels("B8G8R8A8_UNORM_SRGB", 4, "u8x4", srgb=True, bgr=True),
}
D3DFMT_PIXELS = {113: _F16_RGBA, 116: _F32_RGBA}  # legacy DDS FourCCs A16B16G16R16F, A32B32G32R32F
KTX2_SCHEMES = {0: "none", 2: "zstd", 3: "zlib"}  # supercompressionScheme (BasisLZ, 1, is a codec lutbake lacks)
DDS_CUBE_CAPS2 = 0x200 | 0xFC00  # DDSCAPS2_CUBEMAP and the six DDSCAPS2_CUBEMAP_* face bits
DDS_MISC_TEXTURECUBE = 0x4
DDPF_FOURCC, DDPF_RGB = 0x4, 0x40


@dataclass
class CubeFile:
    """A cube map as read: ``mips[m]`` (6, n >> m, n >> m, 3) float64 linear RGB in lutbake's face table; the
    container (ktx2, dds, exr, ktx1), the stored pixel format, its transfer (``linear``, or ``srgb`` where the
    format's sRGB decoding was applied), the container's facts and lutbake's record (None: a file lutbake did not
    write)."""

    path: Path
    container: str
    pixel_format: str
    transfer: str
    mips: list[np.ndarray]
    facts: dict = field(default_factory=dict)
    record: dict | None = None

    @property
    def size(self) -> int:
        return self.mips[0].shape[1]

    @property
    def stored_8bit(self) -> bool:
        """Whether the values were stored as 8-bit codes (UNORM or sRGB)."""
        return self.pixel_format.startswith(("R8G8B8A8", "B8G8R8A8"))


def decode_pixels(raw, count: int, pixels: Pixels) -> np.ndarray:
    """(count, 3) float64 linear RGB of ``count`` texels of ``pixels`` in the bytes ``raw``."""
    if pixels.packing in ("rgb9e5", "b10g11r11"):
        words = np.frombuffer(raw, "<u4", count)
        return decode_rgb9e5(words) if pixels.packing == "rgb9e5" else decode_b10g11r11(words)
    if pixels.packing == "u8x4":
        codes = np.frombuffer(raw, np.uint8, 4 * count).reshape(count, 4)[:, :3].astype(np.float64) / 255.0
        codes = codes[:, ::-1] if pixels.bgr else codes
        return srgb_eotf(codes) if pixels.srgb else codes
    kind, channels = pixels.packing.split("x")
    values = np.frombuffer(raw, "<f2" if kind == "f16" else "<f4", int(channels) * count)
    return values.reshape(count, int(channels))[:, :3].astype(np.float64)


def check_cube(size: int, levels: int, texel_bytes: int, what: str) -> None:
    """ValueError unless a cube of ``size``^2 faces with ``levels`` mips is one lutbake may read: square, levels
    within the chain, its texels (every face of every mip) within the texel and memory caps, before any allocation."""
    if size < 1 or not 1 <= levels <= min(MAX_LEVELS, size.bit_length()):
        raise ValueError(f"{what}: a {size}^2 cube with {levels} mip level(s) (at most floor(log2 size) + 1)")
    texels = 6 * sum(max(1, size >> m) ** 2 for m in range(levels))
    bounded.check_texels((texels, 3), f"{what} (6 faces x {levels} mips of {size}^2)", itemsize=8 + texel_bytes)


def read_cube(path) -> CubeFile:
    """The cube map in ``path`` (module docstring), by its first bytes; ValueError (one line, naming the file)
    for anything lutbake cannot read as a cube."""
    from .cubemap import DDS_HEADER_BYTES
    from .ktx1 import IDENTIFIER as KTX1_IDENTIFIER
    from .ktx2 import IDENTIFIER as KTX2_IDENTIFIER

    path = Path(path)
    problem = bounded.regular_file_problem(path)
    if problem:
        raise ValueError(f"{path}: {problem}")
    with open(path, "rb") as f:
        head = f.read(DDS_HEADER_BYTES)
    try:
        if head[:12] == KTX2_IDENTIFIER:
            cube = _read_ktx2(path)
        elif head[:12] == KTX1_IDENTIFIER:
            cube = _read_ktx1(path)
        elif head[:4] == b"DDS ":
            cube = _read_dds(path)
        elif head[:4] == b"\x76\x2f\x31\x01":
            cube = _read_exr(path)
        else:
            raise ValueError("not a cube file lutbake reads (KTX 2.0, KTX 1.1, DDS or lutbake's EXR cube)")
    except (ValueError, struct.error, OverflowError) as e:
        raise ValueError(f"{path}: {e}") from None
    cube.record = cube.record if cube.record is not None else _record(path)
    return cube


def _record(path: Path) -> dict | None:
    """lutbake's record of a cube file it wrote (lutbake.io.cubemap.read_cube_record), else None."""
    from .cubemap import cube_kind, read_cube_record

    if cube_kind(path) is None:
        return None
    try:
        record = read_cube_record(path)["record"]
    except (ValueError, OSError, UnicodeDecodeError):
        return None
    return record or None


def _levels_of(blobs, size: int, pixels: Pixels) -> list[np.ndarray]:
    """Each level's bytes (faces in table order, rows first) as (6, n, n, 3)."""
    out = []
    for m, raw in enumerate(blobs):
        n = max(1, size >> m)
        out.append(decode_pixels(raw, 6 * n * n, pixels).reshape(6, n, n, 3))
    return out


def _read_ktx2(path: Path) -> CubeFile:
    from .ktx2 import _kv_pairs

    blob = bounded.read_bytes(path, what="a cube map")
    if len(blob) < 80:
        raise ValueError(f"a KTX 2.0 file of {len(blob)} bytes is shorter than its header")
    vk, _, width, height, depth, layers, faces, levels, scheme = struct.unpack_from("<9I", blob, 12)
    dfd_off, dfd_len, kvd_off, kvd_len = struct.unpack_from("<4I", blob, 48)
    levels = max(1, levels)
    if faces != 6 or depth or layers > 1 or width != height:
        raise ValueError(
            f"not a KTX 2.0 cube map (faceCount {faces}, layerCount {layers}, pixelDepth {depth}, "
            f"{width} x {height}; a cube has 6 square faces, layerCount 0 or 1)"
        )
    if vk not in VK_PIXELS:
        names = ", ".join(f"{p.name} ({k})" for k, p in VK_PIXELS.items())
        raise ValueError(f"vkFormat {vk} is not one lutbake reads ({names})")
    if scheme not in KTX2_SCHEMES:
        raise ValueError(f"supercompressionScheme {scheme}: lutbake reads none (0), Zstandard (2) and ZLIB (3)")
    pixels = VK_PIXELS[vk]
    check_cube(width, levels, pixels.size, "the KTX 2.0 header")
    if 80 + 24 * levels > len(blob) or kvd_off + kvd_len > len(blob) or dfd_off + dfd_len > len(blob):
        raise ValueError("its level index, DFD or key/value data runs past the file")
    blobs = []
    for m in range(levels):
        off, length, raw_len = struct.unpack_from("<3Q", blob, 80 + 24 * m)
        n = max(1, width >> m)
        need = 6 * n * n * pixels.size
        if off + length > len(blob) or (scheme == 0 and length != need) or raw_len != need:
            raise ValueError(
                f"level {m}: {length} bytes ({raw_len} uncompressed) at {off}; a {n}^2 cube level of "
                f"{pixels.name} is {need} bytes, within the file's {len(blob)}"
            )
        data = blob[off : off + length]
        blobs.append(data if scheme == 0 else _inflate(data, need, KTX2_SCHEMES[scheme]))
    transfer = blob[dfd_off + 4 + 10] if dfd_len >= 16 else None  # DFD: total size, then the block's third word
    pairs = _kv_pairs(blob, kvd_off, kvd_len)
    facts = {
        "supercompression": KTX2_SCHEMES[scheme],
        "layer_count": layers,
        "dfd_transfer": {1: "linear", 2: "srgb"}.get(transfer, f"{transfer}"),
        **{k: v for k, v in pairs.items() if k.startswith("KTX")},
    }
    record = None
    if "lutbake:metadata" in pairs:
        from .cubemap import _decoded

        record = _decoded(bounded.loads_json(pairs["lutbake:metadata"])) or None
    return CubeFile(path, "ktx2", pixels.name, _transfer(pixels), _levels_of(blobs, width, pixels), facts, record)


def _transfer(pixels: Pixels) -> str:
    return "srgb" if pixels.srgb else "linear"


def _inflate(data: bytes, size: int, scheme: str) -> bytes:
    """One supercompressed level expanded to exactly ``size`` bytes (bounded: never more is made)."""
    if scheme == "zstd":
        return bounded.zstd_decompress(data, size)
    d = zlib.decompressobj()
    try:
        out = d.decompress(data, size + 1)
    except zlib.error as e:
        raise ValueError(f"its zlib data cannot be inflated ({e})") from None
    if len(out) != size or not d.eof:
        raise ValueError(f"its zlib data does not expand to the {size} bytes the header declares")
    return out


def _read_dds(path: Path) -> CubeFile:
    blob = bounded.read_bytes(path, what="a cube map")
    if len(blob) < 128:
        raise ValueError(f"a DDS file of {len(blob)} bytes is shorter than its header (128 bytes)")
    size, _, height, width, _, _, mips = struct.unpack_from("<7I", blob, 4)
    pf_flags, fourcc, bits, rmask, gmask, bmask, _ = struct.unpack_from("<I4s5I", blob, 80)
    caps2 = struct.unpack_from("<I", blob, 112)[0]
    if size != 124 or width != height:
        raise ValueError(f"DDS header size {size} or {width} x {height} faces: not a DDS cube map")
    offset = 128
    if pf_flags & DDPF_FOURCC and fourcc == b"DX10":
        if len(blob) < 148:
            raise ValueError("a DX10 DDS shorter than its DX10 header")
        dxgi, dim, misc, array_size, _ = struct.unpack_from("<5I", blob, 128)
        if dim != 3 or not misc & DDS_MISC_TEXTURECUBE or array_size != 1:
            raise ValueError(
                f"not a DDS cube map (resourceDimension {dim}, miscFlag {misc:#x}, arraySize {array_size}; a cube is "
                "TEXTURE2D with DDS_RESOURCE_MISC_TEXTURECUBE and arraySize 1)"
            )
        if dxgi not in DXGI_PIXELS:
            names = ", ".join(f"{p.name} ({k})" for k, p in DXGI_PIXELS.items())
            raise ValueError(f"DXGI format {dxgi} is not one lutbake reads ({names})")
        pixels, offset, header = DXGI_PIXELS[dxgi], 148, "DX10"
    else:
        if caps2 & DDS_CUBE_CAPS2 != DDS_CUBE_CAPS2:
            raise ValueError(f"not a DDS cube map with all six faces (dwCaps2 {caps2:#x})")
        pixels, header = _legacy_pixels(pf_flags, fourcc, bits, (rmask, gmask, bmask)), "legacy"
    levels = max(1, mips)
    check_cube(width, levels, pixels.size, "the DDS header")
    sizes = [max(1, width >> m) ** 2 * pixels.size for m in range(levels)]  # one face's bytes per mip
    need = 6 * sum(sizes)
    if offset + need > len(blob):
        raise ValueError(
            f"{levels} mips of a {width}^2 {pixels.name} cube need {need} bytes; the file holds "
            f"{len(blob) - offset} after its header"
        )
    starts = offset + np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    face = sum(sizes)
    blobs = [b"".join(blob[starts[m] + f * face : starts[m + 1] + f * face] for f in range(6)) for m in range(levels)]
    facts = {"dds_header": header}
    return CubeFile(path, "dds", pixels.name, _transfer(pixels), _levels_of(blobs, width, pixels), facts)


def _legacy_pixels(flags: int, fourcc: bytes, bits: int, masks: tuple[int, int, int]) -> Pixels:
    """The Pixels of a legacy DDS_PIXELFORMAT: FourCC 113 / 116 (D3DFMT_A16B16G16R16F / A32B32G32R32F), or 32-bit
    RGB masks of RGBA8 (R in the low byte) or BGRA8 (R in the third byte)."""
    code = struct.unpack("<I", fourcc)[0]
    if flags & DDPF_FOURCC and code in D3DFMT_PIXELS:
        return D3DFMT_PIXELS[code]
    if flags & DDPF_RGB and bits == 32:
        if masks == (0xFF, 0xFF00, 0xFF0000):
            return DXGI_PIXELS[28]
        if masks == (0xFF0000, 0xFF00, 0xFF):
            return DXGI_PIXELS[87]
    raise ValueError(
        f"legacy DDS pixel format (flags {flags:#x}, FourCC {fourcc!r}, {bits} bits, masks "
        f"{', '.join(hex(m) for m in masks)}) is not one lutbake reads (FourCC 113, 116; 32-bit RGBA8 / BGRA8)"
    )


def _read_exr(path: Path) -> CubeFile:
    from .exr import exr_parts

    parts = exr_parts(path)
    names = [str(f.get("part") or "") for _, _, f in parts]
    if names != [f"mip_{m}" for m in range(len(parts))]:
        raise ValueError(f"an EXR whose parts are {names[:4]}...: not lutbake's cube layout (parts mip_0, mip_1, ...)")
    size = parts[0][0].shape[1]
    check_cube(size, len(parts), 4, "the EXR")
    mips = []
    for m, (arr, _, _) in enumerate(parts):
        n = max(1, size >> m)
        if arr.shape[:2] != (6 * n, n) or arr.shape[2] < 3:
            raise ValueError(f"part mip_{m} is {arr.shape}; a {n}^2 mip of lutbake's layout is ({6 * n}, {n}, >= 3)")
        mips.append(arr[..., :3].astype(np.float64).reshape(6, n, n, 3))
    return CubeFile(path, "exr", str(parts[0][2]["pixel_type"]), "linear", mips, {})


def _read_ktx1(path: Path) -> CubeFile:
    from .ktx1 import FORMATS, HEADER, decode_ktx1_cube

    blob = bounded.read_bytes(path, what="a cube map")
    if len(blob) < HEADER.size:
        raise ValueError("a KTX 1.1 file shorter than its header")
    fields = HEADER.unpack_from(blob)
    width, levels = fields[7], max(1, fields[12])
    texel = next((f[5] for f in FORMATS.values() if f[0] == fields[2] and f[3] == fields[5]), 12)
    check_cube(width, levels, texel, "the KTX 1.1 header")
    mips, fmt, pairs = decode_ktx1_cube(blob)
    facts = {k: v for k, v in pairs.items() if k != "lutbake:metadata"}
    record = None
    if "lutbake:metadata" in pairs:
        from .cubemap import _decoded

        record = _decoded(bounded.loads_json(pairs["lutbake:metadata"])) or None
    names = {"r11g11b10f": "R11F_G11F_B10F", "half": "RGB16F", "float32": "RGB32F"}
    return CubeFile(path, "ktx1", names[fmt], "linear", mips, facts, record)
