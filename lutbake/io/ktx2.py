"""KTX 2.0 writer and reader, per the Khronos KTX File Format Specification 2.0 and the Khronos Data Format
Specification 1.3 (basic data format descriptor). One mip level, uncompressed or, with
``supercompression="zstd"``, supercompressionScheme 2 (Zstandard, level ZSTD_LEVEL): the level's bytes are one
zstd frame, ``byteLength`` the compressed and ``uncompressedByteLength`` the raw size (KTX 2.0 §3.12.2, §4.1;
Bevy's proposed DFG LUT is a zstd KTX2):
- 2D tables (y, x, C) -> a 2D texture; 3D tables (z, y, x, C) -> a 3D texture (pixelDepth = z), or, with
  ``array=True``, a 2D array texture (layerCount = z).
- vkFormat by channel count and dtype: 1 -> R16_SFLOAT / R32_SFLOAT, 2 -> R16G16_SFLOAT / R32G32_SFLOAT,
  3 or 4 -> R16G16B16A16_SFLOAT / R32G32B32A32_SFLOAT (a 3-channel table gains A = 1).
- The DFD says RGBSDA, BT.709 primaries, LINEAR transfer (never sRGB), float signed samples.
- Key/value data: ``KTXorientation`` = ``rd`` (``rdi`` for 3D): x to the right, y down, i.e. the first
  stored row is table row 0; ``KTXwriter``; and ``lutbake:metadata`` (JSON of the lutbake attributes).
"""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path

import numpy as np

from . import bounded
from .bounded import check_texels, zstd_decompress
from .dds import PIXEL_FORMATS, gpu_channels, layout_name
from .sidecar import LoadedFile, ReadError, as_table_array, string_attrs, with_sidecar

IDENTIFIER = bytes([0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])
# VkFormat values (vulkan_core.h): VK_FORMAT_R16_SFLOAT, R16G16_SFLOAT, R16G16B16A16_SFLOAT, R32_SFLOAT, ...
VK_FORMAT = dict(zip(PIXEL_FORMATS, (76, 83, 97, 100, 103, 109)))
VK_FORMAT_NAMES = {code: f"VK_FORMAT_{layout_name(*key)}_SFLOAT" for key, code in VK_FORMAT.items()}
KHR_DF_MODEL_RGBSDA = 1
KHR_DF_PRIMARIES_BT709 = 1
KHR_DF_TRANSFER_LINEAR = 1
KHR_DF_CHANNEL = (0, 1, 2, 15)  # R, G, B, A
KHR_DF_SAMPLE_DATATYPE_FLOAT = 0x80
KHR_DF_SAMPLE_DATATYPE_SIGNED = 0x40
SUPERCOMPRESSION = {"none": 0, "zstd": 2}  # KTX 2.0 supercompressionScheme values (BasisLZ = 1, ZLIB = 3)
ZSTD_LEVEL = 19  # deterministic output for a given zstandard version; a LUT is compressed once
FROM_VK_FORMAT = {v: k for k, v in VK_FORMAT.items()}


def _dfd(nch: int, bytes_per_channel: int) -> bytes:
    """Basic data format descriptor block for nch float channels, prefixed by dfdTotalSize."""
    block_size = 24 + 16 * nch
    words = [
        0,  # vendorId = KHRONOS (0), descriptorType = BASICFORMAT (0)
        2 | (block_size << 16),  # versionNumber = 2 (KDF 1.3)
        KHR_DF_MODEL_RGBSDA | (KHR_DF_PRIMARIES_BT709 << 8) | (KHR_DF_TRANSFER_LINEAR << 16),  # flags 0
        0,  # texelBlockDimension 1x1x1x1 (stored minus one)
        nch * bytes_per_channel,  # bytesPlane0
        0,
    ]
    bits = 8 * bytes_per_channel
    lower, upper = (0xBF800000, 0x3F800000)  # -1.0f, 1.0f: the spec's sampleLower/Upper for SFLOAT
    for c in range(nch):
        qual = KHR_DF_CHANNEL[c] | KHR_DF_SAMPLE_DATATYPE_FLOAT | KHR_DF_SAMPLE_DATATYPE_SIGNED
        words += [(c * bits) | ((bits - 1) << 16) | (qual << 24), 0, lower, upper]
    body = struct.pack(f"<{len(words)}I", *words)
    return struct.pack("<I", 4 + len(body)) + body


def _kvd(pairs: dict[str, str]) -> bytes:
    out = b""
    for key in sorted(pairs, key=lambda k: k.encode("utf-8")):
        kv = key.encode("utf-8") + b"\0" + pairs[key].encode("utf-8") + b"\0"
        out += struct.pack("<I", len(kv)) + kv
        out += b"\0" * (-len(kv) % 4)
    return out


def encode(
    pixels: np.ndarray,
    metadata: dict[str, str] | None = None,
    array: bool = False,
    writer: str = "lutbake",
    supercompression: str = "none",
) -> bytes:
    """KTX2 bytes for a (y, x, C) or (z, y, x, C) float16/float32 array; ``supercompression`` "none" or "zstd"."""
    dtype = "half" if pixels.dtype == np.float16 else "float32"
    data = np.ascontiguousarray(gpu_channels(pixels))
    nch = data.shape[-1]
    is3d = data.ndim == 4
    height, width = data.shape[-3], data.shape[-2]
    depth = data.shape[0] if is3d and not array else 0
    layers = data.shape[0] if is3d and array else 0
    type_size = data.dtype.itemsize
    dfd = _dfd(nch, type_size)
    pairs = {"KTXorientation": "rdi" if depth else "rd", "KTXwriter": writer}
    if metadata:
        pairs["lutbake:metadata"] = json.dumps(metadata, sort_keys=True, ensure_ascii=False)
    kvd = _kvd(pairs)
    header_len = 12 + 13 * 4 + 2 * 8 + 3 * 8  # identifier, header, index (dfd/kvd u32, sgd u64), 1 level
    dfd_off = header_len
    kvd_off = dfd_off + len(dfd)
    end = kvd_off + len(kvd)
    align = math.lcm(nch * type_size, 4)
    level_off = end + (-end % align)
    raw = data.astype(data.dtype.newbyteorder("<"), copy=False).tobytes()
    scheme = SUPERCOMPRESSION[supercompression]
    if scheme:
        import zstandard

        level = zstandard.ZstdCompressor(level=ZSTD_LEVEL).compress(raw)
        level_off = end  # supercompressed levels need no alignment (KTX 2.0 §3.9.7: mipPadding only if scheme 0)
    else:
        level = raw
    # typeSize (KTX 2.0 §3.3 "typeSize"): the bytes of one component of an unpacked format (2 for *16_SFLOAT, 4 for
    # *32_SFLOAT), whatever the supercompression; 1 only for VK_FORMAT_UNDEFINED and *_BLOCK formats. The DFD keeps
    # the pre-deflation bytesPlane0 ("DFD for Supercompressed Data"). `ktx create` writes the same (Bevy's dfg.ktx2).
    head = IDENTIFIER + struct.pack(
        "<9I", VK_FORMAT[(dtype, nch)], type_size, width, height, depth, layers, 1, 1, scheme
    )
    head += struct.pack("<IIIIQQ", dfd_off, len(dfd), kvd_off, len(kvd), 0, 0)
    head += struct.pack("<QQQ", level_off, len(level), len(raw))
    assert len(head) == header_len
    return head + dfd + kvd + b"\0" * (level_off - end) + level


def _kv_pairs(blob: bytes, start: int, length: int) -> dict[str, str]:
    """Key/value data: repeated (u32 keyAndValueByteLength, key NUL value NUL, padding to 4 bytes)."""
    pairs, pos, end = {}, start, start + length
    while pos + 4 <= end:
        (n,) = struct.unpack_from("<I", blob, pos)
        if n == 0 or pos + 4 + n > end:
            raise ValueError(f"KTX2 key/value entry at byte {pos} runs past the key/value data")
        key, sep, value = blob[pos + 4 : pos + 4 + n].partition(b"\0")
        if not sep:
            raise ValueError(f"KTX2 key/value entry at byte {pos} has no NUL after its key")
        pairs[key.decode("utf-8", "replace")] = value.rstrip(b"\0").decode("utf-8", "replace")
        pos += 4 + n + (-n % 4)
    return pairs


def decode(blob: bytes) -> tuple[np.ndarray, dict]:
    """Read a one-level float KTX 2.0 file (what ``encode`` writes, uncompressed or zstd): (array (y, x, C), or
    (z, y, x, C) for a 3D or array texture, as stored; facts incl. the key/value data). Only level 0 is read. Every
    offset and size is checked against the file length first; a ValueError says what is wrong."""
    if blob[:12] != IDENTIFIER:
        raise ValueError("not a KTX 2.0 file (bad identifier)")
    if len(blob) < 104:
        raise ValueError(f"KTX2 file of {len(blob)} bytes is shorter than its header (104 bytes)")
    vk, type_size, width, height, depth, layers, faces, levels, scheme = struct.unpack_from("<9I", blob, 12)
    _, _, kvd_off, kvd_len, _, _ = struct.unpack_from("<4I2Q", blob, 48)
    level_off, level_len, raw_len = struct.unpack_from("<3Q", blob, 80)
    if vk not in FROM_VK_FORMAT:
        raise ValueError(f"vkFormat {vk} is not one lutbake reads ({', '.join(VK_FORMAT_NAMES.values())})")
    if scheme not in SUPERCOMPRESSION.values():
        raise ValueError(f"KTX2 supercompressionScheme {scheme}: only none (0) and Zstandard (2) are read")
    if faces != 1:
        raise ValueError(f"KTX2 with {faces} faces (lutbake reads 2D, 3D and array textures)")
    if kvd_off + kvd_len > len(blob):
        raise ValueError(f"KTX2 key/value data [{kvd_off}, +{kvd_len}) runs past the file ({len(blob)} bytes)")
    dtype, nch = FROM_VK_FORMAT[vk]
    npdt = np.dtype("<f2" if dtype == "half" else "<f4")
    shape = ((depth,) if depth else (layers,) if layers else ()) + (height, width, nch)
    check_texels(
        shape, f"the KTX2 header ({VK_FORMAT_NAMES[vk]})", itemsize=npdt.itemsize
    )  # before anything is decompressed
    need = int(np.prod(shape, dtype=object)) * npdt.itemsize
    level = blob[level_off : level_off + level_len]
    if scheme:  # one zstd frame of uncompressedByteLength bytes (KTX 2.0 §3.12.2)
        if raw_len != need:
            raise ValueError(f"KTX2 uncompressedByteLength {raw_len} != {need} bytes of its header's shape")
        level = zstd_decompress(level, raw_len)  # streamed: stops at raw_len whatever the frame says
        level_off, level_len = 0, len(level)
    if min(shape) < 1 or need > level_len or (not scheme and level_off + need > len(blob)):
        raise ValueError(
            f"KTX2 header says {' x '.join(map(str, shape))} {VK_FORMAT_NAMES[vk]} ({need} bytes) but "
            f"level 0 holds {level_len} bytes at offset {level_off} of a {len(blob)}-byte file"
        )
    arr = np.frombuffer(level, dtype=npdt, count=int(np.prod(shape))).reshape(shape)
    kv = _kv_pairs(blob, kvd_off, kvd_len)
    return arr, {
        "vk_format": VK_FORMAT_NAMES[vk],
        "dimension": "3D" if depth else "2D array" if layers else "2D",
        "levels": max(levels, 1),
        "supercompression": {v: k for k, v in SUPERCOMPRESSION.items()}[scheme],
        "type_size": type_size,
        "key_value": kv,
    }


def read_ktx2(path: Path) -> LoadedFile:
    arr, facts = decode(bounded.read_bytes(path))
    kv = facts.pop("key_value")
    facts.update({k: v for k, v in kv.items() if k.startswith("KTX")})
    loaded = LoadedFile(path, "ktx2", as_table_array(arr), {}, None, facts)
    if "lutbake:metadata" in kv:
        try:
            meta = bounded.loads_json(kv["lutbake:metadata"])
        except ValueError as e:
            raise ReadError(f"{path}: key/value lutbake:metadata is not valid JSON ({e})") from None
        loaded.attrs = string_attrs(meta, path, "key/value lutbake:metadata")
        loaded.meta_source = "KTX2 key/value data"
        return loaded
    return with_sidecar(loaded)
