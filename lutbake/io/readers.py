"""Read every file lutbake writes, and the tables engines ship: one reader per format, chosen by the
file's first bytes (its magic number), never by its extension.

| format | magic | pixels | lutbake metadata |
| --- | --- | --- | --- |
| EXR | ``76 2f 31 01`` | OpenImageIO, any channels, every part (3D: a part per z) | ``lutbake:*`` attributes |
| NumPy | ``\\x93NUMPY`` | ``np.load`` (no pickles), 2 to 4 dimensions | the ``.json`` sidecar |
| PNG | ``\\x89PNG\\r\\n\\x1a\\n`` | OpenImageIO; codes / 65535 (8-bit: / 255), linear | the ``.json`` sidecar |
| DDS | ``DDS `` | lutbake.io.dds.decode (DX10 float formats; OpenImageIO 3.x reads none) | the ``.json`` sidecar |
| KTX2 | ``«KTX 20»\\r\\n\\x1a\\n`` | lutbake.io.ktx2.decode | ``lutbake:metadata`` key/value, else sidecar |
| C header | text from ``/*``, ``//`` or ``#`` | its ``static const`` array and size macros | the ``.json`` sidecar |
| sidecar | text from ``{`` | the data file it names (``"file"``) | its ``"lutbake"`` object |
| npz, text array | ``PK\\x03\\x04``; other text | ``audit`` reads them (lutbake.io.lut_files), not ``read`` | sidecar |
| engine layout | DDS or text | lutbake.io.engine_files, by the sidecar's ``format`` (LTC, OpenPBR, JS) | the sidecar |

``read(path)`` returns a :class:`LoadedFile` (pixels as stored, including a GPU format's padding
channel); ``table_view(loaded)`` checks the metadata against the pixels and returns a
:class:`TableView` (axes rebuilt as :class:`lutbake.axes.Axis`, channels trimmed to the table's). A
file lutbake cannot read, or metadata that does not fit its pixels, raises :class:`ReadError`: one line
that names the file once and says what is wrong. A file without lutbake metadata still reads: format,
size, channels and values.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..axes import IMAGE_DIMS, MAPPINGS, ORDERS, TEXELS, Axis
from ..errors import MESSAGE_LIMIT, LutbakeError
from ..runtime.warp_runtime import stderr_silenced
from ..textsafe import bounded as bounded_text
from ..textsafe import shorten
from . import bounded, dds, ktx2
from .text_arrays import parse_numbers

PREFIX = "lutbake:"
MAGIC_BYTES = 16  # enough to tell every format apart
MAX_AXIS_COUNT = 1 << 20  # no lutbake axis is longer (the texel cap is 2^24 in all)
MAX_FILE_BYTES = 4 << 30  # a table is at most 2^24 texels x 4 channels x 4 bytes = 256 MiB; headers are text
NAME_CHARS = 120  # characters of a name from a file (kind, table, channel, term) shown by preview and inspect
MAX_TERMS = 32  # terms shown (lutbake records at most a dozen)
MAX_EXR_CHANNELS = 64  # channels of one EXR part (a table has 1 to 4; other tools add a few named ones)
EXR_MAGIC = b"\x76\x2f\x31\x01"
NPY_MAGIC = b"\x93NUMPY"
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
ZIP_MAGIC = b"PK\x03\x04"  # a NumPy .npz archive
TEXT_CONTROLS = b"\t\n\r\f"  # the control bytes a text array may hold
GENERIC_FORMATS = ("exr", "npy", "png16", "dds", "ktx2", "ktx2zst", "h")  # sidecar "format"s whose pixels lutbake reads
FORMAT_NAMES = {
    "engine": "engine-specific file",
    "exr": "OpenEXR",
    "npy": "NumPy .npy",
    "png": "PNG",
    "dds": "DDS",
    "ktx2": "KTX 2.0",
    "h": "C header",
    "npz": "NumPy .npz archive",
    "text": "text array (JS, TS, WGSL, Rust or C source)",
    "sidecar": "lutbake .json sidecar",
    "report": "lutbake bake report (--report)",
}


class ReadError(LutbakeError, ValueError):
    """A file lutbake cannot read, or metadata that does not fit the file: one line that names the file."""

    def __init__(self, message: str):
        line = "; ".join(part.strip() for part in str(message).splitlines() if part.strip())
        super().__init__(shorten(line, MESSAGE_LIMIT))


@dataclass
class LoadedFile:
    path: Path
    format: str  # a key of FORMAT_NAMES
    data: np.ndarray | None  # float32, (y, x, C) or (z, y, x, C), as stored; None: a sidecar whose data is missing
    attrs: dict[str, str]  # lutbake attributes without the prefix; {} when the file carries none
    meta_source: str | None  # where ``attrs`` came from ("EXR header", "sidecar dfg.json", ...)
    facts: dict = field(default_factory=dict)  # what the container says: pixel type, texture format, parts ...
    notes: list[str] = field(default_factory=list)  # why metadata is missing, and the like


@dataclass
class TableView:
    """A read table with its metadata checked against its pixels (``kind`` None: no lutbake metadata)."""

    loaded: LoadedFile
    data: np.ndarray  # float32, (y, x, C) or (z, y, x, C), channels trimmed to the table's
    axes: list[Axis]  # [] without metadata
    channel_names: list[str]  # one per channel of ``data``
    meanings: list[str]
    kind: str | None
    name: str
    terms: dict
    reconstruction: str

    @property
    def attrs(self) -> dict[str, str]:
        return self.loaded.attrs


def sniff(path: Path) -> str:
    """The format of ``path`` from its first bytes (FORMAT_NAMES), never its name: the one recognition ``inspect``,
    ``preview`` and ``audit`` (lutbake.io.lut_files) share; ReadError for anything else."""
    problem = bounded.regular_file_problem(path)  # "no such file", "is a FIFO (named pipe), not a file", ...
    if problem:
        raise ReadError(f"{path}: {problem}")
    with open(path, "rb") as f:
        head = f.read(MAGIC_BYTES)
    for magic, fmt in (
        (EXR_MAGIC, "exr"),
        (NPY_MAGIC, "npy"),
        (PNG_MAGIC, "png"),
        (dds.MAGIC, "dds"),
        (ktx2.IDENTIFIER, "ktx2"),
        (ZIP_MAGIC, "npz"),
    ):
        if head.startswith(magic):
            return fmt
    text = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    if text.startswith(b"{"):
        return "sidecar"
    if text.startswith((b"/*", b"//", b"#")):
        return "h"
    if text and all(b >= 0x20 or b in TEXT_CONTROLS for b in text):  # bytes >= 0x80: UTF-8
        return "text"
    shown = head[:8].hex(" ") if head else "nothing (an empty file)"
    raise ReadError(
        f"{path}: not a format lutbake reads (EXR, npy, PNG, DDS, KTX2, C header, .json sidecar): "
        f"it starts with {shown}"
    )


def read(path) -> LoadedFile:
    """Read any file lutbake writes (see the module docstring), dispatched by its magic bytes."""
    path = Path(path)
    fmt = sniff(path)
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        raise ReadError(f"{path}: {size} bytes is larger than any table lutbake writes ({MAX_FILE_BYTES} bytes)")
    if fmt not in READERS:  # recognised, but only audit reads its values (lutbake.io.lut_files)
        engine = _engine_sidecar(path)
        if engine is None:
            raise ReadError(f"{path}: a {FORMAT_NAMES[fmt]}: inspect and preview do not read it (lutbake audit does)")
        return engine
    try:
        loaded = READERS[fmt](path)
    except (ValueError, KeyError, TypeError, IndexError, OverflowError, UnicodeDecodeError, EOFError, OSError):
        engine = _engine_sidecar(path)
        if engine is None:
            return _read_or_raise(path, fmt)
        return engine
    if loaded.facts.get("sidecar_format", "exr") not in GENERIC_FORMATS:
        return _engine_sidecar(path) or loaded
    return loaded


def _engine_sidecar(path: Path) -> LoadedFile | None:
    """A file in an engine's own layout (``format`` = ltc_dds, openpbr_h, a .cs/.js/.cc module ...): its values
    (lutbake.io.engine_files) with its sidecar's metadata, or None when no sidecar names the file with such a format."""
    for side in sidecar_candidates(path):
        if side.is_file() and side != path:
            doc = _load_json(side)
            if isinstance(doc, dict) and _describes(doc, path) and doc.get("format") not in GENERIC_FORMATS:
                return _engine_values(path, _load_sidecar(side, doc), f"sidecar {side.name}")
    return None


def _engine_values(path: Path, doc: dict, source: str, fmt: str = "engine") -> LoadedFile:
    """An engine-layout file's values and metadata (its sidecar ``doc``); the metadata alone, with the reason,
    where its values cannot be read."""
    from .engine_files import read_engine

    facts = {k: v for k, v in doc.items() if k != "lutbake"}
    try:
        data, attrs, note = read_engine(path, doc)
    except (ValueError, KeyError, TypeError, IndexError, OSError, UnicodeDecodeError) as e:
        note = f"engine-specific format {doc.get('format')!r}: its values cannot be read ({e}); metadata only"
        return LoadedFile(path, fmt, None, doc["lutbake"], source, facts, [note])
    return LoadedFile(path, fmt, data, attrs, source, {**facts, "engine_values": note})


def _read_or_raise(path: Path, fmt: str) -> LoadedFile:
    try:
        return READERS[fmt](path)
    except (LutbakeError, MemoryError):
        raise
    except OSError as e:
        raise ReadError(f"{path}: cannot read: {e.strerror or e}") from None
    except (ValueError, KeyError, TypeError, IndexError, OverflowError, UnicodeDecodeError, EOFError) as e:
        raise ReadError(f"{path}: not a readable {FORMAT_NAMES[fmt]} file: {e}") from None


# ------------------------------------------------------------------------------------------ readers


def _as_table_array(arr: np.ndarray) -> np.ndarray:
    """float32 (y, x, C) or (z, y, x, C): a 2D array gains a channel axis."""
    if arr.dtype.kind not in "fiub":
        raise ValueError(f"array of dtype {arr.dtype} holds no numbers")
    if arr.ndim == 2:
        arr = arr[..., None]
    if arr.ndim not in (3, 4) or arr.shape[-1] > 4 or 0 in arr.shape:
        raise ValueError(
            f"array of shape {arr.shape} is not a table: lutbake reads (y, x), (y, x, C) or "
            "(z, y, x, C) with 1 to 4 channels"
        )
    return np.ascontiguousarray(arr, dtype=np.float32)


def _exr_attrs(spec) -> dict[str, str]:
    return {
        p.name[len(PREFIX) :]: p.value if isinstance(p.value, str) else json.dumps(p.value)
        for p in spec.extra_attribs
        if p.name.startswith(PREFIX)
    }


def exr_parts(path: Path) -> list[tuple[np.ndarray, dict[str, str], dict]]:
    """Every part of an EXR: (float32 pixels (y, x, C), lutbake attributes, facts). Channels R, G, B, A
    come in that order; any other channel names are kept in file order."""
    import OpenImageIO as oiio  # imported here: only EXR and PNG need it

    problem = bounded.exr_header_problem(path)  # before OpenImageIO parses the attributes (super-linear in their count)
    if problem:
        raise ValueError(problem)
    with stderr_silenced():  # libpng / OpenEXR print their own complaints; the ReadError says it once
        inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(oiio.geterror() or "OpenImageIO cannot open it")
    parts = []
    try:
        k, texels = 0, 0
        while inp.seek_subimage(k, 0):
            spec = inp.spec()
            names = list(spec.channelnames)
            texels += spec.width * spec.height * max(spec.depth, 1)  # every part so far: checked before any read
            if texels > bounded.MAX_READ_TEXELS or len(names) > MAX_EXR_CHANNELS:
                raise ValueError(
                    f"part {k} declares {spec.width} x {spec.height} texels x {len(names)} channels ({texels} texels "
                    f"in parts 0-{k}); a table lutbake reads is at most {bounded.MAX_READ_TEXELS} texels of "
                    f"at most {MAX_EXR_CHANNELS} channels: refused before reading"
                )
            bounded.check_memory((texels, len(names)), 4, f"the EXR (parts 0-{k}: texels x channels)")
            rgba = [c for c in "RGBA" if c in names]
            order = rgba + [c for c in names if c not in rgba] if rgba else names  # RGBA first (RGBA + Z: 5)
            with stderr_silenced():
                arr = inp.read_image(k, 0, 0, len(names), "float")
            if arr is None:
                raise ValueError(f"cannot read the pixels of part {k}: {inp.geterror()}")
            arr = np.asarray(arr, dtype=np.float32).reshape(spec.height, spec.width, len(names))
            if order != names:  # a copy only where the channels move (RGBA first)
                arr = np.ascontiguousarray(arr[..., [names.index(c) for c in order]])
            facts = {
                "pixel_type": str(spec.format),
                "compression": spec.getattribute("compression"),
                "part": spec.getattribute("name") or spec.getattribute("oiio:subimagename"),
                "channels": order,
            }
            parts.append((arr, _exr_attrs(spec), facts))
            k += 1
    finally:
        inp.close()
    if not parts:
        raise ValueError("no image part")
    return parts


def read_exr(path: Path) -> LoadedFile:
    parts = exr_parts(path)
    shapes = {p[0].shape for p in parts}
    if len(shapes) != 1:
        raise ValueError(f"its parts have different shapes {sorted(shapes)}")
    attrs = {k: v for k, v in parts[0][1].items() if k not in ("slice_index", "slice_value")}
    problem = _text_problem(attrs)
    if problem:
        raise ValueError(f"its lutbake attributes: {problem}")
    facts = {**parts[0][2], "parts": [(f["part"], a.get("slice_value")) for _, a, f in parts]}
    if len(parts) == 1 and "slice_index" not in parts[0][1]:
        data = parts[0][0]
    else:
        order = [int(a.get("slice_index", k)) for k, (_, a, _) in enumerate(parts)]
        if sorted(order) != list(range(len(order))):
            raise ValueError(f"slice indices {order} are not 0..{len(order) - 1}")
        data = np.stack([parts[order.index(k)][0] for k in range(len(order))])
    return LoadedFile(path, "exr", data, attrs, "EXR header" if attrs else None, facts)


def read_npy(path: Path) -> LoadedFile:
    arr = bounded.load_npy(path)
    data = _as_table_array(arr)
    return _with_sidecar(LoadedFile(path, "npy", data, {}, None, {"dtype": str(arr.dtype), "shape": list(arr.shape)}))


def read_png(path: Path) -> LoadedFile:
    import OpenImageIO as oiio

    with stderr_silenced():
        inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(oiio.geterror() or "OpenImageIO cannot open it")
    try:
        spec = inp.spec()
        bounded.check_texels((spec.height, spec.width, spec.nchannels), "the PNG header", itemsize=spec.format.size())
        bits = 16 if str(spec.format) == "uint16" else 8
        with stderr_silenced():
            arr = inp.read_image("uint16" if bits == 16 else "uint8")
        if arr is None:
            raise ValueError(inp.geterror())
        codes = np.asarray(arr).reshape(spec.height, spec.width, spec.nchannels)
    finally:
        inp.close()
    data = _unorm_float32(codes, (1 << bits) - 1)
    facts = {"bit_depth": bits, "channels": list(spec.channelnames), "encoding": f"code / {(1 << bits) - 1}"}
    return _with_sidecar(LoadedFile(path, "png", data, {}, None, facts))


UNORM_ROWS = 256  # rows converted at a time from UNORM codes (float64 division, rounded to float32)


def _unorm_float32(codes: np.ndarray, one: int) -> np.ndarray:
    """float32 code / one, as the float64 division rounds it, a block of rows at a time (no float64 image)."""
    out = np.empty(codes.shape, np.float32)
    for r in range(0, codes.shape[0], UNORM_ROWS):
        out[r : r + UNORM_ROWS] = codes[r : r + UNORM_ROWS] / float(one)
    return _as_table_array(out)


def read_dds(path: Path) -> LoadedFile:
    arr, facts = dds.decode(bounded.read_bytes(path))
    return _with_sidecar(LoadedFile(path, "dds", _as_table_array(arr), {}, None, facts))


def read_ktx2(path: Path) -> LoadedFile:
    arr, facts = ktx2.decode(bounded.read_bytes(path))
    kv = facts.pop("key_value")
    facts.update({k: v for k, v in kv.items() if k.startswith("KTX")})
    loaded = LoadedFile(path, "ktx2", _as_table_array(arr), {}, None, facts)
    if "lutbake:metadata" in kv:
        try:
            meta = bounded.loads_json(kv["lutbake:metadata"])
        except ValueError as e:
            raise ReadError(f"{path}: key/value lutbake:metadata is not valid JSON ({e})") from None
        loaded.attrs = _string_attrs(meta, path, "key/value lutbake:metadata")
        loaded.meta_source = "KTX2 key/value data"
        return loaded
    return _with_sidecar(loaded)


# Bounded patterns (linear time on any text, issue 38): a declaration's parts are short; the array's body is found
# with one str.find of its closing brace, never by a pattern that rescans the rest of the file from each candidate.
_DEFINE = re.compile(r"^#define[ \t]{1,64}(\w{1,128}?)_(DEPTH|HEIGHT|WIDTH|CHANNELS)[ \t]{1,64}(\d{1,12})[ \t]*$", re.M)
_ARRAY = re.compile(
    r"static\s{1,64}const\s{1,64}(uint16_t|float)\s{1,64}(\w{1,128})\s{0,64}\[[^\]\n]{0,1024}\]\s{0,64}=\s{0,64}\{"
)


def read_header(path: Path) -> LoadedFile:
    """A C header as lutbake writes it (lutbake.io.formats.header_text): size macros and one flat array
    of floats or binary16 bit patterns."""
    text = bounded.read_text(path, what="a C header")
    m = _ARRAY.search(text)
    if m is None:
        raise ValueError("no 'static const float|uint16_t NAME[...] = {...}' array")
    end = text.find("}", m.end())
    if end < 0:
        raise ValueError(f"array {m.group(2)} has no closing brace")
    ctype, ident = m.groups()
    body = text[m.end() : end]
    dims = {k: int(v) for macro, k, v in _DEFINE.findall(text) if macro == ident.upper()}
    if not {"HEIGHT", "WIDTH", "CHANNELS"} <= set(dims):
        raise ValueError(f"no {ident.upper()}_HEIGHT / _WIDTH / _CHANNELS macros for array {ident}")
    shape = tuple(dims[k] for k in ("DEPTH", "HEIGHT", "WIDTH", "CHANNELS") if k in dims)
    bounded.check_texels(shape, f"array {ident}'s macros", itemsize=8)  # parsed as float64
    try:
        data, _ = parse_numbers(body, math.prod(shape), bits=ctype == "uint16_t")
    except ValueError as e:
        raise ValueError(f"array {ident} (its macros say {' x '.join(map(str, shape))}): {e}") from None
    loaded = LoadedFile(
        path,
        "h",
        _as_table_array(data.reshape(shape)),
        {},
        None,
        {"array": ident, "element_type": ctype + (" (binary16 bits)" if ctype == "uint16_t" else "")},
    )
    return _with_sidecar(loaded)


def _is_report(doc) -> bool:
    return isinstance(doc, dict) and "lutbake" not in doc and {"lutbake_version", "tables"} <= set(doc)


def _load_json(path: Path):
    try:
        return bounded.load_json(path)
    except json.JSONDecodeError as e:
        raise ReadError(f"{path}: sidecar is not valid JSON ({e})") from None
    except (ValueError, UnicodeDecodeError) as e:
        raise ReadError(f"{path}: not a readable sidecar: {e}") from None
    except OSError as e:
        raise ReadError(f"{path}: cannot read: {e.strerror or e}") from None


def _load_sidecar(path: Path, doc=None) -> dict:
    doc = _load_json(path) if doc is None else doc
    if not isinstance(doc, dict):
        raise ReadError(f"{path}: a sidecar is a JSON object with a 'lutbake' object, got {type(doc).__name__}")
    if "lutbake" not in doc:
        raise ReadError(f"{path}: JSON without a 'lutbake' object: not a lutbake sidecar")
    doc["lutbake"] = _string_attrs(doc["lutbake"], path, "key 'lutbake'")
    return doc


def _string_attrs(meta, where: Path, what: str) -> dict[str, str]:
    if not isinstance(meta, dict):
        raise ReadError(
            f"{where}: {what} must be a JSON object of lutbake attributes, got {type(meta).__name__} "
            f"{json.dumps(meta)[:40]}"
        )
    bad = [k for k, v in meta.items() if not isinstance(v, str)]
    if bad:
        raise ReadError(f"{where}: {what}: attribute {bad[0]!r} must be a string, got {type(meta[bad[0]]).__name__}")
    problem = _text_problem(meta)
    if problem:
        raise ReadError(f"{where}: {what}: {problem}")
    return dict(meta)


_SURROGATE = re.compile("[\ud800-\udfff]")  # valid in JSON ("\\ud800"), never text: no terminal or font takes it


def _text_problem(value, where: str = "") -> str | None:
    """Where a JSON value (its keys and strings, at any depth) holds a lone UTF-16 surrogate, or None."""
    if isinstance(value, str):
        m = _SURROGATE.search(value)
        return f"{where or 'a string'} holds a lone surrogate (U+{ord(m.group()):04X}): not text" if m else None
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        name = f"{where}[{key}]" if isinstance(key, int) else f"{where}.{key}" if where else f"{key}"
        name = bounded_text(_SURROGATE.sub("?", str(name)), NAME_CHARS)
        problem = (_text_problem(key, f"key {name!r}") if isinstance(key, str) else None) or _text_problem(item, name)
        if problem:
            return problem
    return None


def sidecar_candidates(path: Path) -> list[Path]:
    """Where the sidecar of a data file may be: <name>.<ext>.json, then <name>.json; for the second texture of an
    ltc_dds pair (<stem>_2.dds), the pair's sidecar <stem>_1.dds.json (it lists both in ``files``)."""
    out = [path.with_name(path.name + ".json"), path.with_suffix(".json")]
    if path.name.endswith("_2.dds"):
        out.append(path.with_name(path.name[: -len("_2.dds")] + "_1.dds.json"))
    return out


def _describes(doc: dict, path: Path) -> bool:
    """Whether a sidecar names ``path`` as its data file (``file``) or one of its files (``files``)."""
    files = doc.get("files")
    return doc.get("file") == path.name or (isinstance(files, list) and path.name in files)


def _with_sidecar(loaded: LoadedFile) -> LoadedFile:
    """Attach the attributes of the sidecar that names this file (a sidecar naming another file is skipped)."""
    for side in sidecar_candidates(loaded.path):
        if not side.is_file() or side == loaded.path or _is_report(_load_json(side)):
            continue
        doc = _load_sidecar(side)
        named = doc.get("file")
        if named is not None and not _describes(doc, loaded.path):
            loaded.notes.append(f"{side.name} describes {named}, not this file")
            continue
        loaded.attrs, loaded.meta_source = doc["lutbake"], f"sidecar {side.name}"
        loaded.facts["sidecar_format"] = doc.get("format", "")
        return loaded
    if not loaded.notes:
        loaded.notes.append(f"no sidecar ({' or '.join(p.name for p in sidecar_candidates(loaded.path))})")
    return loaded


def read_sidecar(path: Path) -> LoadedFile:
    """A sidecar: its attributes, with the pixels of the data file it names (beside it) when present.
    A bake report (``lutbake bake --report``) reads as format "report": facts only, no pixels."""
    doc = _load_json(path)
    if _is_report(doc):
        return LoadedFile(path, "report", None, {}, None, doc, ["a bake report: it lists tables and holds no pixels"])
    doc = _load_sidecar(path, doc)
    named = doc.get("file")
    facts = {k: v for k, v in doc.items() if k != "lutbake"}
    generic = doc.get("format", "exr") in GENERIC_FORMATS
    if generic and isinstance(named, str) and named and Path(named).name == named and (path.parent / named).is_file():
        data_path = path.parent / named
        if sniff(data_path) == "sidecar":
            raise ReadError(f"{path}: names another sidecar ({named}) as its data file")
        inner = READERS[sniff(data_path)](data_path)
        facts = {**facts, "data_file": named, "data_format": FORMAT_NAMES[inner.format], **inner.facts}
        return LoadedFile(path, "sidecar", inner.data, doc["lutbake"], f"sidecar {path.name}", facts)
    note = f"its data file {named!r} is not beside it" if named else "it names no data file"
    if not generic and isinstance(named, str) and Path(named).name == named and (path.parent / named).is_file():
        inner = _engine_values(path.parent / named, doc, f"sidecar {path.name}", "sidecar")
        inner.path, inner.facts = path, {**inner.facts, "data_file": named, "data_format": FORMAT_NAMES["engine"]}
        return inner
    return LoadedFile(path, "sidecar", None, doc["lutbake"], f"sidecar {path.name}", facts, [note])


READERS = {
    "exr": read_exr,
    "npy": read_npy,
    "png": read_png,
    "dds": read_dds,
    "ktx2": read_ktx2,
    "h": read_header,
    "sidecar": read_sidecar,
}


# ------------------------------------------------------------------------------- metadata vs pixels


def _json_attr(loaded: LoadedFile, key: str, kind: type, default):
    where = f"{loaded.path}: {'lutbake:' if loaded.format == 'exr' else 'lutbake.'}{key}"
    if key not in loaded.attrs:
        if default is None:
            raise ReadError(f"{where} is missing (every lutbake table records it)")
        return default
    try:
        value = bounded.loads_json(loaded.attrs[key])
    except ValueError as e:  # JSONDecodeError, nesting, an integer of more than 4300 digits
        raise ReadError(f"{where} is not valid JSON ({shorten(str(e), 200)})") from None
    if not isinstance(value, kind):
        raise ReadError(f"{where} must be a JSON {'list' if kind is list else 'object'}, got {loaded.attrs[key][:60]}")
    problem = _text_problem(value)
    if problem:
        raise ReadError(f"{where}: {problem}")
    return value


def _number(x) -> bool:
    """A finite JSON number (an integer too large for a float, 10^400, is not one)."""
    if not isinstance(x, (int, float)) or isinstance(x, bool):
        return False
    try:
        return math.isfinite(float(x))
    except OverflowError:
        return False


def axis_from_meta(d: dict, where: str = "axis") -> Axis:
    """An Axis rebuilt from its ``lutbake:axes`` entry (Axis.describe()), every field checked."""

    def bad(msg):
        raise ReadError(f"{where}: {msg}")

    if not isinstance(d, dict):
        bad(f"each axis must be a JSON object, got {json.dumps(d)[:40]}")
    name = d.get("name")
    if not isinstance(name, str) or not name:
        bad(f"an axis needs a 'name' string, got {json.dumps(d)[:60]}")
    name = bounded_text(name, NAME_CHARS)
    where = f"{where} {name!r}"
    count = d.get("count")
    if isinstance(count, float) and count.is_integer():
        count = int(count)
    if not isinstance(count, int) or isinstance(count, bool) or not 1 <= count <= MAX_AXIS_COUNT:
        bad(f"count {count!r} is not an integer in [1, {MAX_AXIS_COUNT}]")
    choices = {"dim": IMAGE_DIMS, "texel": TEXELS, "mapping": MAPPINGS, "order": ORDERS}
    defaults = {"dim": None, "texel": "center", "mapping": "linear", "order": "lo_first"}
    v = {}
    for key, allowed in choices.items():
        v[key] = d.get(key, defaults[key])
        if v[key] not in allowed:
            bad(f"{key} {v[key]!r} is not one of {', '.join(allowed)}")
    rng = d.get("range", [0.0, 1.0])
    if not (isinstance(rng, list) and len(rng) == 2 and all(map(_number, rng))):
        bad(f"range {json.dumps(rng)[:40]} is not [lo, hi]")
    clamp = d.get("clamp")
    if clamp is not None and not (isinstance(clamp, list) and len(clamp) == 2 and all(map(_number, clamp))):
        bad(f"clamp {json.dumps(clamp)[:40]} is not [lo, hi]")
    listed = ()
    if v["mapping"] == "listed":
        vals = d.get("values")
        if not (isinstance(vals, list) and len(vals) == count and all(map(_number, vals))):
            bad(f"mapping 'listed' needs {count} numeric values")
        listed = tuple(float(x) for x in vals)
    return Axis(
        name,
        v["dim"],
        count,
        float(rng[0]),
        float(rng[1]),
        texel=v["texel"],
        mapping=v["mapping"],
        order=v["order"],
        clamp=tuple(clamp) if clamp else None,
        listed=listed,
    )


def _check_axes_fit(path: Path, axes: list[Axis], shape: tuple[int, ...]) -> None:
    """Every axis' count matches the pixels along its image dimension (a y_block axis divides the rows)."""
    sizes = {"z": shape[0] if len(shape) == 4 else 1, "y": shape[-3], "x": shape[-2]}
    words = {"z": "slices", "y": "rows", "x": "columns", "y_block": "row blocks"}
    dims = [a.dim for a in axes]
    if len(set(dims)) != len(dims):
        raise ReadError(f"{path}: lutbake axes: two axes share an image dimension: {dims}")
    blocks = [a for a in axes if a.dim == "y_block"]
    if blocks:
        if sizes["y"] % blocks[0].count:
            raise ReadError(f"{path}: lutbake axes: {sizes['y']} rows do not split into {blocks[0].count} row blocks")
        sizes["y_block"], sizes["y"] = blocks[0].count, sizes["y"] // blocks[0].count
    for a in axes:
        if a.count != sizes[a.dim]:
            raise ReadError(
                f"{path}: lutbake axes: axis {a.name!r} ({a.dim}) has count {a.count} but the image "
                f"has {sizes[a.dim]} {words[a.dim]} (shape {' x '.join(map(str, shape))})"
            )
    missing = [d for d in ("z", "y") if sizes[d] > 1 and d not in dims]
    if "x" not in dims or missing:
        raise ReadError(
            f"{path}: lutbake axes {[a.name for a in axes]} do not cover the image's "
            f"{', '.join(words[d] for d in ['x'] + missing)} (shape {' x '.join(map(str, shape))})"
        )


def table_view(loaded: LoadedFile) -> TableView:
    """The table in a read file, its metadata checked against its pixels (ReadError if they disagree)."""
    if loaded.data is None:
        raise ReadError(f"{loaded.path}: {loaded.notes[0] if loaded.notes else 'no pixels'}")
    data, path = loaded.data, loaded.path
    if not loaded.attrs:
        nch = data.shape[-1]
        letters = [str(c) for c in loaded.facts.get("channels") or ()][:nch] or list("RGBA"[:nch])
        letters += [f"#{c}" for c in range(len(letters), nch)]
        names = [f"channel {bounded_text(c, NAME_CHARS)}" for c in letters]
        return TableView(loaded, data, [], names, [""] * nch, None, path.stem, {}, "")
    if "kind" not in loaded.attrs:
        raise ReadError(f"{path}: lutbake metadata ({loaded.meta_source}) without 'kind'")
    axes_meta = _json_attr(loaded, "axes", list, None)
    where = f"{path}: {'lutbake:' if loaded.format == 'exr' else 'lutbake.'}axes"
    axes = [axis_from_meta(d, where) for d in axes_meta]
    _check_axes_fit(path, axes, data.shape)
    names = _json_attr(loaded, "channel_names", dict, {})
    meanings = _json_attr(loaded, "channels", dict, {})
    letters = [c for c in "RGBA" if c in names] or list("RGBA"[: data.shape[-1]])
    if len(letters) > data.shape[-1]:
        raise ReadError(f"{path}: lutbake channel_names lists {len(letters)} channels, the file holds {data.shape[-1]}")
    data = data[..., : len(letters)]  # drop a GPU format's padding (PNG B = 0, DDS/KTX2 A = 1)
    terms = _json_attr(loaded, "terms", dict, {})
    # every string from the file bounded and escaped here, before any figure or terminal line (textsafe.bounded:
    # a 50 MiB kind took gigabytes in matplotlib; control characters made it warn about missing glyphs)
    return TableView(
        loaded,
        data,
        axes,
        [bounded_text(names.get(c, f"channel {c}"), NAME_CHARS) for c in letters],
        [bounded_text(meanings.get(c, "")) for c in letters],
        bounded_text(loaded.attrs["kind"], NAME_CHARS),
        bounded_text(loaded.attrs.get("table", path.stem), NAME_CHARS),
        {bounded_text(k, NAME_CHARS): bounded_text(v, NAME_CHARS) for k, v in list(terms.items())[:MAX_TERMS]},
        bounded_text(loaded.attrs.get("reconstruction", "")),
    )


def read_table(path) -> TableView:
    """``table_view(read(path))``."""
    return table_view(read(path))
