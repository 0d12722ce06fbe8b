"""KTX 2.0 writer, per the Khronos KTX File Format Specification 2.0 and the Khronos Data Format
Specification 1.3 (basic data format descriptor). Uncompressed, one mip level, no supercompression:
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

import numpy as np

from .dds import PIXEL_FORMATS, gpu_channels, layout_name

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
    pixels: np.ndarray, metadata: dict[str, str] | None = None, array: bool = False, writer: str = "lutbake"
) -> bytes:
    """KTX2 bytes for a (y, x, C) or (z, y, x, C) float16/float32 array."""
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
    level = data.astype(data.dtype.newbyteorder("<"), copy=False).tobytes()
    head = IDENTIFIER + struct.pack("<9I", VK_FORMAT[(dtype, nch)], type_size, width, height, depth, layers, 1, 1, 0)
    head += struct.pack("<IIIIQQ", dfd_off, len(dfd), kvd_off, len(kvd), 0, 0)
    head += struct.pack("<QQQ", level_off, len(level), len(level))
    assert len(head) == header_len
    return head + dfd + kvd + b"\0" * (level_off - end) + level
