"""Cube maps with mips, the environment's files: KTX 2.0, DDS and EXR, each with lutbake's record of the bake
(face convention, mip curve, roughness and alpha per mip, weighting, error estimate per mip, the source's sha256).

- **KTX 2.0**: faceCount 6, levelCount M, VK_FORMAT_R16G16B16A16_SFLOAT (A = 1) or R32G32B32A32_SFLOAT; the level
  index lists level 0 first, the level images are stored smallest first (KTX 2.0 §3.9, §3.10); inside a level the
  faces +X, -X, +Y, -Y, +Z, -Z, each row 0 first. The record: key ``lutbake:metadata`` (JSON); ``KTXorientation``
  ``rd``.
- **DDS**: DX10 header, DXGI_FORMAT_R16G16B16A16_FLOAT / R32G32B32A32_FLOAT, TEXTURE2D with
  DDS_RESOURCE_MISC_TEXTURECUBE, arraySize 1, mipMapCount M, DDSCAPS2_CUBEMAP and the six face bits; data face by
  face (+X first), each face's mips largest first (Direct3D's subresource order). The record: ``<file>.json``.
- **EXR**: one part per mip, named ``mip_<m>``, the six faces stacked top to bottom (+X, -X, +Y, -Y, +Z, -Z; 6n rows
  of n), RGB; every part's display window is mip 0's (OpenEXR shares it between parts), its data window its own,
  at the origin. The record: ``lutbake:*`` attributes in every part.
- **KTX 1** (``ktx1``): Filament's image-based light, the layout cmgen writes (lutbake.io.ktx1): R11F_G11F_B10F
  (cmgen's), RGB16F or RGB32F, level 0 first, faces +X first, with the SH Filament's shader takes as key ``sh``.

Faces are written as lutbake.environment.cube's table gives them (OpenGL / KTX orientation); ``face_convention`` in
the record says so. Values must be finite and (half) below 65504: anything else is refused, never written.
"""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path

import numpy as np

from .atomic import atomic_write, atomic_write_bytes
from .ktx2 import IDENTIFIER, _dfd, _kvd

VK_RGBA = {"half": 97, "float32": 109}  # VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT
DXGI_RGBA = {"half": 10, "float32": 2}  # DXGI_FORMAT_R16G16B16A16_FLOAT, DXGI_FORMAT_R32G32B32A32_FLOAT
NUMPY = {"half": np.float16, "float32": np.float32}
DDSD = 0x1 | 0x2 | 0x4 | 0x8 | 0x1000 | 0x20000  # CAPS HEIGHT WIDTH PITCH PIXELFORMAT MIPMAPCOUNT
DDSCAPS = 0x1000 | 0x8 | 0x400000  # TEXTURE, COMPLEX, MIPMAP
DDSCAPS2_CUBE = 0x200 | 0xFC00  # CUBEMAP and the six faces
DDS_MISC_TEXTURECUBE = 0x4


def rgba(mips: list[np.ndarray], dtype: str) -> list[np.ndarray]:
    """Each mip (6, n, n, 3) as (6, n, n, 4) of ``dtype`` with A = 1; ValueError for a non-finite value or one half
    float cannot hold."""
    out = []
    for m, a in enumerate(mips):
        a = np.asarray(a, np.float64)
        if a.ndim != 4 or a.shape[0] != 6 or a.shape[1] != a.shape[2] or a.shape[3] != 3:
            raise ValueError(f"mip {m}: a cube mip is (6, n, n, 3), got {a.shape}")
        limit = float(np.finfo(NUMPY[dtype]).max)
        if not np.all(np.isfinite(a)) or np.abs(a).max() > limit:
            raise ValueError(f"mip {m}: a value is not finite or past what {dtype} holds ({limit:g}); nothing written")
        out.append(np.concatenate([a, np.ones(a.shape[:-1] + (1,))], axis=-1).astype(NUMPY[dtype]))
    return out


def encode_ktx2_cube(mips: list[np.ndarray], metadata: dict, dtype: str = "half") -> bytes:
    """KTX 2.0 bytes of a cube with ``len(mips)`` levels (module docstring)."""
    levels = rgba(mips, dtype)
    size = levels[0].shape[1]
    type_size = 2 if dtype == "half" else 4
    dfd = _dfd(4, type_size)
    kvd = _kvd(
        {"KTXorientation": "rd", "KTXwriter": "lutbake", "lutbake:metadata": json.dumps(metadata, sort_keys=True)}
    )
    header_len = 12 + 13 * 4 + 2 * 8 + 3 * 8 * len(levels)
    kvd_off = header_len + len(dfd)
    pos = kvd_off + len(kvd)
    align = math.lcm(4 * type_size, 4)
    blobs, offsets, body = [], {}, b""
    for m in reversed(range(len(levels))):  # smallest level first in the file
        pad = -pos % align
        body += b"\0" * pad
        pos += pad
        data = levels[m].astype(levels[m].dtype.newbyteorder("<"), copy=False).tobytes()
        offsets[m] = (pos, len(data))
        body += data
        pos += len(data)
        blobs.append(data)
    head = IDENTIFIER + struct.pack("<9I", VK_RGBA[dtype], type_size, size, size, 0, 0, 6, len(levels), 0)
    head += struct.pack("<IIIIQQ", header_len, len(dfd), kvd_off, len(kvd), 0, 0)
    for m in range(len(levels)):
        off, n = offsets[m]
        head += struct.pack("<QQQ", off, n, n)
    return head + dfd + kvd + body


def decode_ktx2_cube(blob: bytes) -> tuple[list[np.ndarray], dict]:
    """(mips as (6, n, n, 4) arrays, the lutbake metadata) of a KTX 2.0 cube ``encode_ktx2_cube`` writes; every
    offset is checked against the file's length; ValueError says what is wrong."""
    if blob[:12] != IDENTIFIER or len(blob) < 80:
        raise ValueError("not a KTX 2.0 file")
    vk, type_size, width, height, depth, layers, faces, levels, scheme = struct.unpack_from("<9I", blob, 12)
    if faces != 6 or depth or layers or scheme or width != height or vk not in VK_RGBA.values():
        raise ValueError("not an uncompressed RGBA float KTX 2.0 cube (faceCount 6, no layers or depth)")
    if not 1 <= levels <= 32 or 80 + 24 * levels > len(blob):
        raise ValueError(f"KTX2 levelCount {levels} does not fit the file")
    dtype = np.dtype("<f2" if vk == VK_RGBA["half"] else "<f4")
    mips = []
    for m in range(levels):
        off, n, _ = struct.unpack_from("<3Q", blob, 80 + 24 * m)
        side = max(1, width >> m)
        need = 6 * side * side * 4 * dtype.itemsize
        if n != need or off + n > len(blob):
            raise ValueError(f"KTX2 level {m}: {n} bytes at {off}, expected {need} within {len(blob)} bytes")
        mips.append(np.frombuffer(blob, dtype, 6 * side * side * 4, off).reshape(6, side, side, 4))
    kvd_off, kvd_len = struct.unpack_from("<II", blob, 56)
    from .ktx2 import _kv_pairs

    pairs = _kv_pairs(blob, kvd_off, kvd_len)
    return mips, json.loads(pairs.get("lutbake:metadata", "{}"))


def encode_dds_cube(mips: list[np.ndarray], dtype: str = "half") -> bytes:
    """DDS bytes of a cube with ``len(mips)`` mips (module docstring)."""
    levels = rgba(mips, dtype)
    size = levels[0].shape[1]
    pitch = size * 4 * np.dtype(NUMPY[dtype]).itemsize
    pixelformat = struct.pack("<II4sIIIII", 32, 0x4, b"DX10", 0, 0, 0, 0, 0)
    header = struct.pack("<IIIIIII", 124, DDSD, size, size, pitch, 0, len(levels)) + b"\0" * 44 + pixelformat
    header += struct.pack("<IIIII", DDSCAPS, DDSCAPS2_CUBE, 0, 0, 0)
    dx10 = struct.pack("<IIIII", DXGI_RGBA[dtype], 3, DDS_MISC_TEXTURECUBE, 1, 0)
    data = b"".join(
        levels[m][f].astype(levels[m].dtype.newbyteorder("<")).tobytes() for f in range(6) for m in range(len(levels))
    )
    return b"DDS " + header + dx10 + data


def write_cube(
    mips: list[np.ndarray], path, metadata: dict, fmt: str, dtype: str = "half", sh: np.ndarray | None = None
) -> Path:
    """Write a cube with mips to ``path`` in ``fmt`` (ktx2, dds, exr, ktx1), atomically; dds also writes the metadata to
    ``<path>.json``. Values that are not strings are written as JSON text in EXR attributes and the sidecar (every
    ``lutbake:*`` value is a string), as one JSON object in KTX 2.0's and KTX 1's ``lutbake:metadata``. ``ktx1`` is
    Filament's IBL file (lutbake.io.ktx1: ``dtype`` r11g11b10f, half or float32; ``sh`` the (9, 3) coefficients of
    lutbake.environment.sh form ``filament``, written as its ``sh`` key)."""
    path = Path(path)
    if fmt == "ktx1":
        from .ktx1 import encode_ktx1_cube

        return atomic_write_bytes(path, encode_ktx1_cube(mips, dtype, sh, metadata))
    if fmt == "ktx2":
        return atomic_write_bytes(path, encode_ktx2_cube(mips, metadata, dtype))
    text = {k: v if isinstance(v, str) else json.dumps(v, sort_keys=True) for k, v in metadata.items()}
    if fmt == "dds":
        atomic_write_bytes(path, encode_dds_cube(mips, dtype))
        sidecar = json.dumps({"lutbake": text}, indent=1, sort_keys=True) + "\n"
        atomic_write_bytes(path.with_name(path.name + ".json"), sidecar.encode())
        return path
    if fmt == "exr":
        from .exr import EXR_TYPES, _write_oiio

        parts = [
            (f"mip_{m}", text, np.ascontiguousarray(a[..., :3].reshape(-1, a.shape[2], 3)))
            for m, a in enumerate(rgba(mips, dtype))
        ]
        return atomic_write(path, lambda tmp: _write_oiio(tmp, parts, EXR_TYPES[dtype]))
    raise ValueError(f"cube format must be ktx2, dds, exr or ktx1, got {fmt!r}")
