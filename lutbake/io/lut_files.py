"""Read any LUT file lutbake can audit into a float64 (rows, columns, channels) array.

``read_lut(path, shape=None) -> LutFile``. Formats, recognised by content (lutbake.io.readers.sniff, the recognition
``inspect`` uses), never by the file's name:
- EXR: OpenImageIO (any tool's: float or half, RG/RGB/RGBA, layer-prefixed or other channel names, one part); the
  ``lutbake:*`` attributes when present.
- PNG: OpenImageIO, the raw UNORM codes (8 or 16 bit), value = code / (2^bits - 1), **no transfer function**.
- DDS: DX10 header, R16G16_FLOAT ... RGBA32F (lutbake.io.dds); KTX2: lutbake.io.ktx2.decode (plain or zstd).
- NumPy npy, npz: an integer array is UNORM codes (value = code / dtype max), a float array values (npz: the
  array named ``table``, else its only one).
- text (``.h .hpp .inc .js .ts .mjs .wgsl .rs`` sources): the numbers of the first brace/bracket array: hex
  ``0x....`` literals are IEEE half bits, decimal literals floats.
``storage`` records how the file stores a value (unorm8/16, half, float32), which the audit's quantisation check uses.
A text array's layout must be declared: ``#define *_HEIGHT/_WIDTH/_CHANNELS`` (lutbake's C header), the
``lutbake:shape`` line of lutbake's JS/WGSL/Rust comment block, or ``shape=(rows, columns, channels)``.
Row 0 of the result is the first row stored in the file (no flip). A JSON sidecar beside the file
(lutbake's ``<file>.json``, or a ``<stem>.json`` provenance note) is returned in ``sidecar``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import bounded
from .text_arrays import parse_text_array

READABLE = ("exr", "png", "dds", "ktx2", "npy", "npz", "h", "text")  # lutbake.io.readers.sniff's formats audit reads


@dataclass
class LutFile:
    path: Path
    data: np.ndarray  # float64 (rows, columns, channels), file row order
    storage: str  # "unorm8", "unorm16", "half", "float32", ...: how the file stores a value
    attrs: dict = field(default_factory=dict)  # lutbake:* attributes (without the prefix) when present
    sidecar: dict = field(default_factory=dict)

    @property
    def unorm_bits(self) -> int | None:
        return int(self.storage[5:]) if self.storage.startswith("unorm") else None


def _unorm(codes: np.ndarray) -> tuple[np.ndarray, str]:
    bits = codes.dtype.itemsize * 8
    values = codes.astype(np.float64)
    values /= float((1 << bits) - 1)  # in place: one float64 image, not two
    return values, f"unorm{bits}"


def _float_storage(arr: np.ndarray) -> str:
    return "half" if arr.dtype == np.float16 else "float32" if arr.dtype == np.float32 else "float64"


def _read_png(path: Path) -> tuple[np.ndarray, str]:
    import OpenImageIO as oiio

    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)  # the stored codes: a grey+alpha or RGBA table is not premultiplied
    inp = oiio.ImageInput.open(str(path), config)
    if inp is None:
        raise ValueError(f"{path}: cannot open PNG: {oiio.geterror()}")
    try:
        spec = inp.spec()
        bounded.check_texels((spec.height, spec.width, spec.nchannels), "the PNG header", itemsize=spec.format.size())
        native = oiio.UINT16 if spec.format.size() == 2 else oiio.UINT8
        codes = inp.read_image(native)  # raw codes: OIIO applies no transfer function on read
    finally:
        inp.close()
    if codes is None:
        raise ValueError(f"{path}: cannot read PNG pixels")
    return _unorm(np.asarray(codes))


def _read_exr(path: Path) -> tuple[np.ndarray, dict, str]:
    """Any tool's 2D EXR: (values (y, x, C), lutbake attributes or {}, storage "half" / "float32"). Channels R, G, B,
    A in that order, also under a layer prefix (``dfg.R``, ``dfg.G``: file order is alphabetical); other names
    (``Y``, ``scale``, ``bias``) in file order. A multi-part file is a 3D table, which audit does not compare."""
    from .exr import exr_parts

    try:
        parts = exr_parts(path)
    except ValueError as e:
        raise ValueError(f"{path}: not a readable EXR ({e})") from None
    if len(parts) != 1:
        raise ValueError(f"{path}: {len(parts)} parts (a 3D table, one part per slice); audit compares 2D tables")
    arr, attrs, facts = parts[0]
    suffixes = [c.rpartition(".")[2] for c in facts["channels"]]
    if len(set(suffixes)) == len(suffixes) and set(suffixes) <= set("RGBA"):
        arr = arr[..., [suffixes.index(c) for c in "RGBA" if c in suffixes]]
    storage = "half" if facts["pixel_type"] == "half" else "float32"
    return arr.astype(np.float64), attrs, storage


def read_lut(path, shape=None) -> LutFile:
    """Read ``path`` (see the module docstring). ``shape``: (rows, columns, channels) of a text array
    whose file does not declare it."""
    from .readers import FORMAT_NAMES, sniff

    path = Path(path)
    fmt = sniff(path)  # ReadError (a ValueError) for a missing file, a FIFO, a directory, an unknown format
    if fmt not in READABLE:
        raise ValueError(
            f"{path}: a {FORMAT_NAMES[fmt]}: audit reads "
            + ", ".join(FORMAT_NAMES[f] for f in READABLE)
            + (" (audit the data file the sidecar names)" if fmt == "sidecar" else "")
        )
    try:
        return _read_lut(path, fmt, shape)
    except ValueError as e:
        text = str(e)
        raise ValueError(text if text.startswith(str(path)) else f"{path}: {text}") from None


def _read_lut(path: Path, fmt: str, shape) -> LutFile:
    from .dds import decode as dds_decode
    from .ktx2 import decode as ktx2_decode

    attrs, sidecar = {}, {}
    for side in (path.with_name(path.name + ".json"), path.with_suffix(".json")):  # lutbake's, then refs style
        if side.is_file() and side != path:
            try:
                sidecar = bounded.load_json(side)
            except (ValueError, UnicodeDecodeError, OSError) as e:
                raise ValueError(f"its sidecar {side.name} is not readable JSON: {e}") from None
            if not isinstance(sidecar, dict) or not isinstance(sidecar.get("lutbake", {}), dict):
                raise ValueError(f"its sidecar {side.name} is not a JSON object with a 'lutbake' object")
            attrs = sidecar.get("lutbake", {})
            break
    if fmt == "exr":
        data, exr_attrs, storage = _read_exr(path)
        attrs = exr_attrs or attrs
    elif fmt == "png":
        data, storage = _read_png(path)
    elif fmt == "dds":
        arr, _ = dds_decode(bounded.read_bytes(path))
        data, storage = arr.astype(np.float64), _float_storage(arr)
    elif fmt == "ktx2":
        arr, facts = ktx2_decode(bounded.read_bytes(path))
        kv = facts["key_value"]
        data, storage = arr.astype(np.float64), _float_storage(arr)
        if "lutbake:metadata" in kv:
            attrs = bounded.loads_json(kv["lutbake:metadata"])
            if not isinstance(attrs, dict):
                raise ValueError("its KTX2 key/value lutbake:metadata is not a JSON object")
    elif fmt in ("npy", "npz"):
        if fmt == "npz":  # one array: named "table" (tests/data), else the only one
            arr, _ = bounded.load_npz(path)
        else:
            arr = bounded.load_npy(path)
        if np.issubdtype(arr.dtype, np.unsignedinteger):
            data, storage = _unorm(arr)
        else:
            data, storage = arr.astype(np.float64), _float_storage(arr)
    else:
        try:
            data, storage = parse_text_array(bounded.read_text(path, errors="replace"), shape)
        except ValueError as e:
            raise ValueError(f"{path}: {e}") from None
    data = np.asarray(data, dtype=np.float64)
    if data.ndim == 2:
        data = data[..., None]
    if data.ndim != 3:
        raise ValueError(f"{path}: a 2D table (rows, columns, channels) is needed, got shape {data.shape}")
    return LutFile(path, data, storage, attrs, sidecar)
