"""Read every file lutbake writes, and the tables engines ship: one reader per format, each beside its writer
(lutbake.io.exr, npy, png, dds, ktx2, header; the sidecar reader here), chosen by the file's first bytes (its magic
number), never by its extension. What they return and the sidecar they share: lutbake.io.sidecar.

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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..axes import IMAGE_DIMS, MAPPINGS, ORDERS, TEXELS, Axis
from ..errors import LutbakeError
from ..limits import MAX_AXIS_COUNT, MAX_FILE_BYTES
from ..textsafe import bounded as bounded_text
from ..textsafe import shorten
from . import bounded, dds, ktx2
from .cubemap import cube_kind
from .dds import read_dds
from .exr import EXR_MAGIC, read_any_exr
from .header import read_header
from .ktx1 import IDENTIFIER as KTX1_IDENTIFIER
from .ktx2 import read_ktx2
from .npy import NPY_MAGIC, read_npy
from .png import PNG_MAGIC, read_png
from .sidecar import (
    NAME_CHARS,
    LoadedFile,
    ReadError,
    describes,
    is_report,
    load_sidecar,
    load_sidecar_json,
    sidecar_candidates,
    text_problem,
)

MAGIC_BYTES = 16  # enough to tell every format apart
MAX_TERMS = 32  # terms shown (lutbake records at most a dozen)
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
    "ktx1": "KTX 1.1",
    "h": "C header",
    "npz": "NumPy .npz archive",
    "text": "text array (JS, TS, WGSL, Rust or C source)",
    "sidecar": "lutbake .json sidecar",
    "report": "lutbake bake report (--report)",
}


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
        (KTX1_IDENTIFIER, "ktx1"),
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
    cube = cube_kind(path)  # an environment table's cube map (lutbake.io.cubemap): no (z,) y, x, C table
    if cube is not None:
        raise ReadError(
            f"{path}: a cube map with mips ({FORMAT_NAMES[cube]}), no (z,) y, x, C table: `lutbake inspect` describes "
            "it, `lutbake audit` checks a prefiltered one, Python reads its pixels with lutbake.io.cube_read.read_cube"
        )
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
            doc = load_sidecar_json(side)
            if isinstance(doc, dict) and describes(doc, path) and doc.get("format") not in GENERIC_FORMATS:
                return _engine_values(path, load_sidecar(side, doc), f"sidecar {side.name}")
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


def read_sidecar(path: Path) -> LoadedFile:
    """A sidecar: its attributes, with the pixels of the data file it names (beside it) when present.
    A bake report (``lutbake bake --report``) reads as format "report": facts only, no pixels."""
    doc = load_sidecar_json(path)
    if is_report(doc):
        return LoadedFile(path, "report", None, {}, None, doc, ["a bake report: it lists tables and holds no pixels"])
    doc = load_sidecar(path, doc)
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
    "exr": read_any_exr,
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
    problem = text_problem(value)
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
