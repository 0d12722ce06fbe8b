"""Cube maps with mips, the environment's files: KTX 2.0, DDS and EXR, each with lutbake's record of the bake
(face convention, mip curve, roughness and alpha per mip, weighting, error estimate per mip, the source's sha256).

- **KTX 2.0**: faceCount 6, levelCount M, VK_FORMAT_R16G16B16A16_SFLOAT (A = 1), R32G32B32A32_SFLOAT, or the
  packed E5B9G9R9_UFLOAT_PACK32 (``rgb9e5``) and B10G11R11_UFLOAT_PACK32 (``b10g11r11``), encoded exactly
  (lutbake.io.encodings); the level index lists level 0 first, the level images are stored smallest first (KTX 2.0
  §3.9, §3.10); inside a level the faces +X, -X, +Y, -Y, +Z, -Z, each row 0 first. The record: key
  ``lutbake:metadata`` (JSON); ``KTXorientation`` ``rd``.
- **DDS**: DX10 header, DXGI_FORMAT_R16G16B16A16_FLOAT / R32G32B32A32_FLOAT / R9G9B9E5_SHAREDEXP /
  R11G11B10_FLOAT, TEXTURE2D with DDS_RESOURCE_MISC_TEXTURECUBE, arraySize 1, mipMapCount M, DDSCAPS2_CUBEMAP and
  the six face bits; data face by face (+X first), each face's mips largest first (Direct3D's subresource order). The
  record: ``<file>.json``.
- **EXR**: one part per mip, named ``mip_<m>``, the six faces stacked top to bottom (+X, -X, +Y, -Y, +Z, -Z; 6n rows
  of n), RGB; every part's display window is mip 0's (OpenEXR shares it between parts), its data window its own,
  at the origin. The record: ``lutbake:*`` attributes in every part.
- **KTX 1** (``ktx1``): Filament's image-based light, the layout cmgen writes (lutbake.io.ktx1): R11F_G11F_B10F
  (cmgen's), RGB16F or RGB32F, level 0 first, faces +X first, with the SH Filament's shader takes as key ``sh``.

Faces are written as lutbake.environment.cube's table gives them (OpenGL / KTX orientation); ``face_convention`` in
the record says so. Values must be finite and within the format's range (half 65504, RGB9E5 65408, B10G11R11 65024 /
64512; the packed formats store a negative value as 0): anything else is refused, never written. lutbake.io.cube_read
reads the pixels back (``read_cube``).
"""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path

import numpy as np

from . import bounded
from .atomic import atomic_write
from .encodings import ENCODERS
from .ktx1 import IDENTIFIER as KTX1_IDENTIFIER
from .ktx2 import IDENTIFIER, _dfd, _kvd

VK_RGBA = {"half": 97, "float32": 109}  # VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT
DXGI_RGBA = {"half": 10, "float32": 2}  # DXGI_FORMAT_R16G16B16A16_FLOAT, DXGI_FORMAT_R32G32B32A32_FLOAT
NUMPY = {"half": np.float16, "float32": np.float32}
DDSD = 0x1 | 0x2 | 0x4 | 0x8 | 0x1000 | 0x20000  # CAPS HEIGHT WIDTH PITCH PIXELFORMAT MIPMAPCOUNT
DDSCAPS = 0x1000 | 0x8 | 0x400000  # TEXTURE, COMPLEX, MIPMAP
DDSCAPS2_CUBE = 0x200 | 0xFC00  # CUBEMAP and the six faces
DDS_MISC_TEXTURECUBE = 0x4
VK_PACKED = {"rgb9e5": 123, "b10g11r11": 122}  # VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, VK_FORMAT_B10G11R11_UFLOAT_PACK32
DXGI_PACKED = {"rgb9e5": 67, "b10g11r11": 26}  # DXGI_FORMAT_R9G9B9E5_SHAREDEXP, DXGI_FORMAT_R11G11B10_FLOAT
VK_NAMES = {
    97: "VK_FORMAT_R16G16B16A16_SFLOAT",
    109: "VK_FORMAT_R32G32B32A32_SFLOAT",
    123: "VK_FORMAT_E5B9G9R9_UFLOAT_PACK32",
    122: "VK_FORMAT_B10G11R11_UFLOAT_PACK32",
}
DXGI_NAMES = {
    10: "DXGI_FORMAT_R16G16B16A16_FLOAT",
    2: "DXGI_FORMAT_R32G32B32A32_FLOAT",
    67: "DXGI_FORMAT_R9G9B9E5_SHAREDEXP",
    26: "DXGI_FORMAT_R11G11B10_FLOAT",
}
# KDF 1.3 basic descriptor samples (bitOffset, bitLength - 1, channel | qualifiers, lower, upper) of the packed
# formats: E5B9G9R9 (KDF 1.3 §5.19's shared-exponent example: a mantissa and an EXPONENT (0x20) sample per channel,
# as `ktx create` writes Bevy's pisa_*_rgb9e5_zstd.ktx2) and B10G11R11 (KTX-Software lib/dfdutils/createdfd.c
# createDFDPacked, s_UFLOAT: FLOAT (0x80), lower 0.0f, upper 1.0f)
PACKED_SAMPLES = {
    "rgb9e5": [s for c in range(3) for s in ((9 * c, 8, c, 0, 8448), (27, 4, c | 0x20, 15, 31))],
    "b10g11r11": [(0, 10, 0x80, 0, 0x3F800000), (11, 10, 0x81, 0, 0x3F800000), (22, 9, 0x82, 0, 0x3F800000)],
}
MAX_RECORD_BYTES = 1 << 20  # lutbake's record of a cube is a few KiB


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


def level_texels(mips: list[np.ndarray], dtype: str) -> list[np.ndarray]:
    """Each mip as the texels stored: (6, n, n, 4) half / float32 with A = 1 (``rgba``), or (6, n, n) uint32 of a
    packed format (``rgb9e5``, ``b10g11r11``: lutbake.io.encodings); ValueError for a value the format cannot hold."""
    if dtype not in ENCODERS:
        return rgba(mips, dtype)
    out = []
    for m, a in enumerate(mips):
        a = np.asarray(a, np.float64)
        if a.ndim != 4 or a.shape[0] != 6 or a.shape[1] != a.shape[2] or a.shape[3] != 3:
            raise ValueError(f"mip {m}: a cube mip is (6, n, n, 3), got {a.shape}")
        try:
            out.append(ENCODERS[dtype](a))
        except ValueError as e:
            raise ValueError(f"mip {m}: {e}") from None
    return out


def packed_dfd(dtype: str) -> bytes:
    """The basic data format descriptor of a packed 32-bit format (PACKED_SAMPLES), prefixed by dfdTotalSize; RGBSDA,
    BT.709, linear."""
    samples = PACKED_SAMPLES[dtype]
    block = 24 + 16 * len(samples)
    words = [0, 2 | (block << 16), 1 | (1 << 8) | (1 << 16), 0, 4, 0]
    for offset, length, channel, lower, upper in samples:
        words += [offset | (length << 16) | (channel << 24), 0, lower, upper]
    body = struct.pack(f"<{len(words)}I", *words)
    return struct.pack("<I", 4 + len(body)) + body


def encode_ktx2_cube(mips: list[np.ndarray], metadata: dict, dtype: str = "half") -> bytes:
    """KTX 2.0 bytes of a cube with ``len(mips)`` levels (module docstring)."""
    levels = level_texels(mips, dtype)
    size = levels[0].shape[1]
    type_size = 2 if dtype == "half" else 4  # a packed format's typeSize is its 32-bit word's (KTX 2.0 §3.3)
    dfd = packed_dfd(dtype) if dtype in VK_PACKED else _dfd(4, type_size)
    kvd = _kvd(
        {"KTXorientation": "rd", "KTXwriter": "lutbake", "lutbake:metadata": json.dumps(metadata, sort_keys=True)}
    )
    header_len = 12 + 13 * 4 + 2 * 8 + 3 * 8 * len(levels)
    kvd_off = header_len + len(dfd)
    pos = kvd_off + len(kvd)
    align = 4 if dtype in VK_PACKED else math.lcm(4 * type_size, 4)
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
    vk = VK_PACKED.get(dtype) or VK_RGBA[dtype]
    head = IDENTIFIER + struct.pack("<9I", vk, type_size, size, size, 0, 0, 6, len(levels), 0)
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
    levels = level_texels(mips, dtype)
    size = levels[0].shape[1]
    pitch = size * levels[0][0, 0].nbytes
    pixelformat = struct.pack("<II4sIIIII", 32, 0x4, b"DX10", 0, 0, 0, 0, 0)
    header = struct.pack("<IIIIIII", 124, DDSD, size, size, pitch, 0, len(levels)) + b"\0" * 44 + pixelformat
    header += struct.pack("<IIIII", DDSCAPS, DDSCAPS2_CUBE, 0, 0, 0)
    dx10 = struct.pack("<IIIII", DXGI_PACKED.get(dtype) or DXGI_RGBA[dtype], 3, DDS_MISC_TEXTURECUBE, 1, 0)
    data = b"".join(
        levels[m][f].astype(levels[m].dtype.newbyteorder("<")).tobytes() for f in range(6) for m in range(len(levels))
    )
    return b"DDS " + header + dx10 + data


def _as_text(metadata: dict) -> dict[str, str]:
    """The record as strings (EXR attributes, the sidecar's ``lutbake`` object): JSON text for every value that is
    not a string."""
    return {k: v if isinstance(v, str) else json.dumps(v, sort_keys=True) for k, v in metadata.items()}


def write_cube(
    mips: list[np.ndarray],
    path,
    metadata: dict,
    fmt: str,
    dtype: str = "half",
    files: dict[str, bytes] | None = None,
    sh: np.ndarray | None = None,
) -> Path:
    """Write a cube with mips to ``path`` in ``fmt`` (ktx2, dds, exr, ktx1), atomically, as one verified unit
    (lutbake.io.integrity): ``files`` (name -> bytes: other files of the output beside ``path``, an irradiance
    table's SH) are written first; then the cube; then, for ktx2 and dds, the sidecar ``<path>.json`` naming the
    sha256 of every file, written last; an EXR carries ``lutbake:data_hash`` and ``lutbake:files_sha256`` instead.
    Values that are not strings are written as JSON text in EXR attributes and the sidecar (every ``lutbake:*`` value
    is a string), as one JSON object in KTX 2.0's and KTX 1's ``lutbake:metadata``. ``ktx1`` is Filament's IBL file
    (lutbake.io.ktx1: ``dtype`` r11g11b10f, half or float32; ``sh`` the (9, 3) coefficients of lutbake.environment.sh
    form ``filament``, written as its ``sh`` key)."""
    from .atomic import atomic_write_bytes_hashed, unit_lock
    from .integrity import HASH_KEY, PLACEHOLDER, seal_exr, write_sidecar

    if fmt not in CUBE_FORMATS:
        raise ValueError(f"cube format must be one of {sorted(CUBE_FORMATS)}, got {fmt!r}")
    path = Path(path)
    text = _as_text(metadata)
    if dtype in ENCODERS and fmt not in ("ktx2", "dds"):
        raise ValueError(f"dtype {dtype!r} is written in ktx2 and dds cubes only, not {fmt}")
    levels = level_texels(mips, "float32" if dtype == "r11g11b10f" else dtype)  # every value checked before any file
    data = b""  # an EXR is written part by part below
    if fmt == "ktx1":
        from .ktx1 import encode_ktx1_cube

        data = encode_ktx1_cube(mips, dtype, sh, metadata)
    elif fmt == "ktx2":
        data = encode_ktx2_cube(mips, metadata, dtype)
    elif fmt == "dds":
        data = encode_dds_cube(mips, dtype)
    with unit_lock(path):
        digests = {name: atomic_write_bytes_hashed(path.with_name(name), blob) for name, blob in (files or {}).items()}
        if fmt == "exr":
            from .exr import EXR_TYPES, _write_oiio

            attrs = {**text, "files_sha256": json.dumps(digests, sort_keys=True), HASH_KEY: PLACEHOLDER.decode()}
            parts = [
                (f"mip_{m}", attrs, np.ascontiguousarray(a[..., :3].reshape(-1, a.shape[2], 3)))
                for m, a in enumerate(levels)
            ]

            def write(tmp):
                _write_oiio(tmp, parts, EXR_TYPES[dtype])
                seal_exr(tmp)

            return atomic_write(path, write)
        digests[path.name] = atomic_write_bytes_hashed(path, data)
        write_sidecar(path, CUBE_FORMATS[fmt], text, digests, {"files": sorted(digests)})
        return path


CUBE_FORMATS = {
    "ktx2": "ktx2_cube",
    "dds": "dds_cube",
    "exr": "exr_cube",
    "ktx1": "ktx1_cube",
}  # format -> the sidecar's ``format``


def cube_metadata(table) -> dict:
    """Everything a cube file of ``table`` (lutbake.table.CubeTable) records: kind, table, reconstruction, the
    bake's record, its provenance."""
    return {
        "kind": table.kind,
        "table": table.name,
        "reconstruction": table.reconstruction,
        **table.record,
        **table.attributes,
    }


def write_cube_table(table, path, fmt: str, dtype: str = "half") -> Path:
    """Write ``table`` (lutbake.table.CubeTable) to ``path`` (write_cube), with its SH document beside it where it has
    one (``record["sh_file"]``); a ktx1 cube carries its record's SH of form ``filament`` as its key ``sh``."""
    files = {}
    if table.sh is not None:
        files[table.record["sh_file"]] = (json.dumps(table.sh, indent=1) + "\n").encode()
    filament = fmt == "ktx1" and table.record.get("sh_form") == "filament"  # the KTX 1's key sh (lutbake.io.ktx1)
    sh = np.asarray(table.record["sh"], np.float64) if filament else None
    return write_cube(table.mips, path, cube_metadata(table), fmt, dtype, files, sh)


# ------------------------------------------------------------------------------------------------- reading


def _decoded(text: dict) -> dict:
    """The record from strings: JSON text of a list or an object decoded, the rest kept (the provenance strings of a
    KTX 2.0 record too: ``ibl``)."""
    if not isinstance(text, dict):
        raise ValueError("its lutbake record is not a JSON object")
    out = {}
    for k, v in text.items():
        if isinstance(v, str) and v[:1] in "[{":
            try:
                v = bounded.loads_json(v)
            except ValueError:
                pass
        out[k] = v
    return out


def cube_kind(path) -> str | None:
    """ "ktx2", "dds", "exr" or "ktx1" where ``path`` is a cube file lutbake writes (a KTX 2.0 or KTX 1.1 with
    numberOfFaces 6, a DDS with the cube caps, an EXR whose parts are named mip_<m>), else None: read from the first
    bytes (and, for an EXR, its part names). A path that is no regular file (a FIFO would block the open) is None."""
    if bounded.regular_file_problem(path):
        return None
    try:
        with open(path, "rb") as f:
            head = f.read(DDS_HEADER_BYTES)
    except OSError:
        return None
    if head[:12] == IDENTIFIER and len(head) >= 48:
        return "ktx2" if struct.unpack_from("<I", head, 36)[0] == 6 else None
    if head[:12] == KTX1_IDENTIFIER and len(head) >= 64:
        return "ktx1" if struct.unpack_from("<I", head, 52)[0] == 6 else None
    if head[:4] == b"DDS " and len(head) >= DDS_HEADER_BYTES:
        return "dds" if struct.unpack_from("<I", head, 4 + 108)[0] & 0x200 else None
    if head[:4] == b"\x76\x2f\x31\x01":
        try:
            return "exr" if _exr_parts(path)[0][0] == "mip_0" else None
        except Exception:  # noqa: BLE001 - any EXR OpenImageIO cannot list is no cube of lutbake's
            return None
    return None


DDS_HEADER_BYTES = 4 + 124 + 20  # magic, DDS_HEADER, DDS_HEADER_DXT10


def _exr_parts(path) -> list[tuple[str, int, str, dict[str, str]]]:
    """(part name, face size, pixel type, lutbake attributes) of every part of an EXR, headers only."""
    from .exr import _exr_attrs, _oiio

    problem = bounded.exr_header_problem(path)
    if problem:
        raise ValueError(problem)
    oiio = _oiio()
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(oiio.geterror() or "OpenImageIO cannot open it")
    parts = []
    try:
        k = 0
        while inp.seek_subimage(k, 0):
            spec = inp.spec()
            name = spec.getattribute("name") or spec.getattribute("oiio:subimagename") or ""
            parts.append((str(name), spec.width, str(spec.format), _exr_attrs(spec)))
            k += 1
    finally:
        inp.close()
    return parts


def read_cube_record(path) -> dict:
    """The record of a cube file lutbake wrote (KTX 2.0, DDS with its ``.json`` sidecar, EXR), and its container's
    facts, without its pixels: ``{"format", "pixel_format", "size", "mips",
    "record", "metadata"}``, ``record`` the lutbake record with its JSON values decoded, ``metadata`` where it was
    read. ValueError says what is wrong."""
    path = Path(path)
    fmt = cube_kind(path)
    if fmt is None:
        raise ValueError(f"{path}: not a cube file lutbake writes (KTX 2.0 faceCount 6, DDS cube, EXR mip_<m> parts)")
    if fmt == "ktx2":
        from .ktx2 import _kv_pairs

        with open(path, "rb") as f:
            head = f.read(80)
            vk, _, width, _, _, _, _, levels, _ = struct.unpack_from("<9I", head, 12)
            kvd_off, kvd_len = struct.unpack_from("<II", head, 56)
            if kvd_len > MAX_RECORD_BYTES:
                raise ValueError(f"{path}: {kvd_len} bytes of KTX2 key/value data; lutbake's record is a few KiB")
            f.seek(kvd_off)
            kvd = f.read(kvd_len)
        if len(kvd) != kvd_len:
            raise ValueError(f"{path}: the KTX2 key/value data runs past the file")
        record = _decoded(bounded.loads_json(_kv_pairs(kvd, 0, kvd_len).get("lutbake:metadata", "{}")))
        return _described(fmt, VK_NAMES.get(vk, f"vkFormat {vk}"), width, levels, record, "KTX2 key lutbake:metadata")
    if fmt == "ktx1":
        return _ktx1_described(path)
    if fmt == "dds":
        with open(path, "rb") as f:
            head = f.read(DDS_HEADER_BYTES)
        _, _, height, width, _, _, mips = struct.unpack_from("<7I", head, 4)
        dxgi = struct.unpack_from("<I", head, 128)[0]
        from .integrity import sidecar_path
        from .sidecar import load_sidecar_json

        side = sidecar_path(path)
        doc = load_sidecar_json(side) if side.is_file() else None
        if not isinstance(doc, dict) or not isinstance(doc.get("lutbake"), dict):
            raise ValueError(f"{path}: a DDS cube without lutbake's record (its sidecar {side.name} is missing)")
        pixel = DXGI_NAMES.get(dxgi, f"DXGI {dxgi}")
        return _described(fmt, pixel, width, mips, _decoded(doc["lutbake"]), f"sidecar {side.name}")
    parts = _exr_parts(path)
    return _described(fmt, parts[0][2], parts[0][1], len(parts), _decoded(parts[0][3]), "EXR header (every part)")


def _ktx1_described(path: Path) -> dict:
    """read_cube_record of a KTX 1.1 cube (lutbake.io.ktx1): the header and key/value data only."""
    from .ktx1 import FORMATS, HEADER, key_values

    with open(path, "rb") as f:
        fields = HEADER.unpack(f.read(HEADER.size))
        if fields[13] > MAX_RECORD_BYTES:
            raise ValueError(f"{path}: {fields[13]} bytes of KTX1 key/value data; lutbake's record is a few KiB")
        kv = f.read(fields[13])
    record = _decoded(bounded.loads_json(key_values(kv).get("lutbake:metadata", "{}")))
    pixel = next((f"{name} (glInternalFormat {f[3]:#x})" for name, f in FORMATS.items() if f[3] == fields[5]), "?")
    return _described("ktx1", pixel, fields[7], fields[12], record, "KTX1 key lutbake:metadata")


def _described(fmt: str, pixel: str, size: int, mips: int, record: dict, where: str) -> dict:
    if not isinstance(record, dict):
        raise ValueError("its lutbake record is not a JSON object")
    return {"format": fmt, "pixel_format": pixel, "size": size, "mips": mips, "record": record, "metadata": where}
