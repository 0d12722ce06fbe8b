"""DDS writer (and a minimal reader for tests/tools), per Microsoft's DDS specification
("DDS_HEADER", "DDS_HEADER_DXT10", "DDS_PIXELFORMAT"; docs.microsoft.com, Programming Guide for DDS).

Always the DX10 extension header (FourCC ``DX10``), one mip level, no compression:
- 2D tables (y, x, C) -> TEXTURE2D; 3D tables (z, y, x, C) -> TEXTURE3D (DDSCAPS2_VOLUME, depth = z).
- DXGI format by channel count and dtype: 1 -> R16_FLOAT / R32_FLOAT, 2 -> R16G16_FLOAT / R32G32_FLOAT,
  3 or 4 -> R16G16B16A16_FLOAT / R32G32B32A32_FLOAT (a 3-channel table gets A = 1, as Filament's cmgen).
- Rows are stored first row first: DDS row 0 (the top row in D3D, v = 0) is table row 0.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from . import bounded
from .sidecar import LoadedFile, as_table_array, with_sidecar

MAGIC = b"DDS "
DDSD_CAPS, DDSD_HEIGHT, DDSD_WIDTH, DDSD_PITCH = 0x1, 0x2, 0x4, 0x8
DDSD_PIXELFORMAT, DDSD_MIPMAPCOUNT, DDSD_DEPTH = 0x1000, 0x20000, 0x800000
DDPF_FOURCC = 0x4
DDSCAPS_TEXTURE = 0x1000
DDSCAPS2_VOLUME = 0x200000
DIM_TEXTURE2D, DIM_TEXTURE3D = 3, 4
# (pixel type, channels) of every GPU format written: half / float32 x 1, 2 or 4 channels (3 gain A = 1)
PIXEL_FORMATS = [(dtype, n) for dtype in ("half", "float32") for n in (1, 2, 4)]


def layout_name(dtype: str, n: int) -> str:
    """ "R16G16" for ("half", 2): the channel letters with their bits, as DXGI and Vulkan spell a format."""
    return "".join(f"{c}{16 if dtype == 'half' else 32}" for c in "RGBA"[:n])


# DXGI_FORMAT values (dxgiformat.h): R16_FLOAT, R16G16_FLOAT, R16G16B16A16_FLOAT, R32_FLOAT, R32G32_FLOAT, ...
DXGI = dict(zip(PIXEL_FORMATS, (54, 34, 10, 41, 16, 2)))
DXGI_NAMES = {code: layout_name(*key) + "_FLOAT" for key, code in DXGI.items()}
FROM_DXGI = {v: k for k, v in DXGI.items()}


def gpu_channels(pixels: np.ndarray) -> np.ndarray:
    """1, 2 or 4 channels as GPUs take them: a 3-channel table gains A = 1."""
    if pixels.shape[-1] == 3:
        alpha = np.ones(pixels.shape[:-1] + (1,), dtype=pixels.dtype)
        return np.concatenate([pixels, alpha], axis=-1)
    return pixels


def encode(pixels: np.ndarray) -> bytes:
    """DDS bytes for a (y, x, C) or (z, y, x, C) float16/float32 array."""
    dtype = "half" if pixels.dtype == np.float16 else "float32"
    data = np.ascontiguousarray(gpu_channels(pixels))
    nch = data.shape[-1]
    fmt = DXGI[(dtype, nch)]
    is3d = data.ndim == 4
    depth = data.shape[0] if is3d else 1
    height, width = data.shape[-3], data.shape[-2]
    pitch = width * nch * data.dtype.itemsize
    flags = DDSD_CAPS | DDSD_HEIGHT | DDSD_WIDTH | DDSD_PITCH | DDSD_PIXELFORMAT | DDSD_MIPMAPCOUNT
    if is3d:
        flags |= DDSD_DEPTH
    pixelformat = struct.pack("<II4sIIIII", 32, DDPF_FOURCC, b"DX10", 0, 0, 0, 0, 0)
    header = struct.pack("<IIIIIII", 124, flags, height, width, pitch, depth if is3d else 0, 1)
    header += b"\0" * 44 + pixelformat
    header += struct.pack("<IIIII", DDSCAPS_TEXTURE, DDSCAPS2_VOLUME if is3d else 0, 0, 0, 0)
    assert len(header) == 124
    dx10 = struct.pack("<IIIII", fmt, DIM_TEXTURE3D if is3d else DIM_TEXTURE2D, 0, 1, 0)
    return MAGIC + header + dx10 + data.astype(data.dtype.newbyteorder("<"), copy=False).tobytes()


def decode(blob: bytes) -> tuple[np.ndarray, dict]:
    """Read an uncompressed float DDS with a DX10 header (what ``encode`` writes; OpenImageIO 3.x has no
    float DDS reader): (array (y, x, C) or (z, y, x, C) as stored, facts). Every header field is checked
    against the file length before any pixel is touched; a ValueError says what is wrong."""
    if blob[:4] != MAGIC:
        raise ValueError("not a DDS file (bad magic)")
    if len(blob) < 148:
        raise ValueError(f"DDS file of {len(blob)} bytes is shorter than its headers (148 bytes)")
    size, flags, height, width, pitch, depth, mips = struct.unpack_from("<IIIIIII", blob, 4)
    if size != 124:
        raise ValueError(f"DDS header size {size} != 124")
    fourcc = blob[84:88]  # magic (4) + 72 bytes of header before DDS_PIXELFORMAT, + dwSize, dwFlags
    if fourcc != b"DX10":
        raise ValueError(f"DDS without a DX10 header (FourCC {fourcc!r}); lutbake reads uncompressed float DDS only")
    fmt, dim, _, array_size, _ = struct.unpack_from("<IIIII", blob, 128)
    if fmt not in FROM_DXGI:
        raise ValueError(f"DXGI format {fmt} is not one lutbake reads ({', '.join(DXGI_NAMES.values())})")
    if dim not in (DIM_TEXTURE2D, DIM_TEXTURE3D):
        raise ValueError(f"DDS resource dimension {dim} (lutbake reads TEXTURE2D = 3 and TEXTURE3D = 4)")
    dtype, nch = FROM_DXGI[fmt]
    npdt = np.dtype("<f2" if dtype == "half" else "<f4")
    shape = ((depth,) if dim == DIM_TEXTURE3D else ()) + (height, width, nch)
    bounded.check_texels(shape, f"the DDS header ({DXGI_NAMES[fmt]})", itemsize=npdt.itemsize)
    need = 148 + int(np.prod(shape, dtype=object)) * npdt.itemsize
    if min(shape) < 1 or need > len(blob):
        raise ValueError(
            f"DDS header says {' x '.join(map(str, shape))} {DXGI_NAMES[fmt]} ({need} bytes) but the "
            f"file holds {len(blob)} bytes"
        )
    arr = np.frombuffer(blob, dtype=npdt, count=int(np.prod(shape)), offset=148).reshape(shape)
    return arr, {
        "dxgi_format": DXGI_NAMES[fmt],
        "dimension": "TEXTURE3D" if dim == DIM_TEXTURE3D else "TEXTURE2D",
        "mips": mips,
        "array_size": array_size,
    }


def read_dds(path: Path) -> LoadedFile:
    arr, facts = decode(bounded.read_bytes(path))
    return with_sidecar(LoadedFile(path, "dds", as_table_array(arr), {}, None, facts))
