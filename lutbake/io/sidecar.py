"""What every reader of lutbake.io returns and the ``.json`` sidecar they share: :class:`LoadedFile` (pixels as stored,
lutbake attributes, container facts), :class:`ReadError` (one line that names the file once), the float32 table
array of any reader's pixels, and the sidecar beside a data file (where it may be, whether it names the file, its
attributes checked as strings that are text)."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import MESSAGE_LIMIT, LutbakeError
from ..textsafe import bounded as bounded_text
from ..textsafe import shorten
from . import bounded
from .file_sets import members

NAME_CHARS = 120  # characters of a name from a file (kind, table, channel, term) shown by preview and inspect


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


def as_table_array(arr: np.ndarray) -> np.ndarray:
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


def is_report(doc) -> bool:
    return isinstance(doc, dict) and "lutbake" not in doc and {"lutbake_version", "tables"} <= set(doc)


def load_sidecar_json(path: Path):
    try:
        return bounded.load_json(path)
    except json.JSONDecodeError as e:
        raise ReadError(f"{path}: sidecar is not valid JSON ({e})") from None
    except (ValueError, UnicodeDecodeError) as e:
        raise ReadError(f"{path}: not a readable sidecar: {e}") from None
    except OSError as e:
        raise ReadError(f"{path}: cannot read: {e.strerror or e}") from None


def load_sidecar(path: Path, doc=None) -> dict:
    doc = load_sidecar_json(path) if doc is None else doc
    if not isinstance(doc, dict):
        raise ReadError(f"{path}: a sidecar is a JSON object with a 'lutbake' object, got {type(doc).__name__}")
    if "lutbake" not in doc:
        raise ReadError(f"{path}: JSON without a 'lutbake' object: not a lutbake sidecar")
    doc["lutbake"] = string_attrs(doc["lutbake"], path, "key 'lutbake'")
    return doc


def string_attrs(meta, where: Path, what: str) -> dict[str, str]:
    if not isinstance(meta, dict):
        raise ReadError(
            f"{where}: {what} must be a JSON object of lutbake attributes, got {type(meta).__name__} "
            f"{json.dumps(meta)[:40]}"
        )
    bad = [k for k, v in meta.items() if not isinstance(v, str)]
    if bad:
        raise ReadError(f"{where}: {what}: attribute {bad[0]!r} must be a string, got {type(meta[bad[0]]).__name__}")
    problem = text_problem(meta)
    if problem:
        raise ReadError(f"{where}: {what}: {problem}")
    return dict(meta)


_SURROGATE = re.compile("[\ud800-\udfff]")  # valid in JSON ("\\ud800"), never text: no terminal or font takes it


def text_problem(value, where: str = "") -> str | None:
    """Where a JSON value (its keys and strings, at any depth) holds a lone UTF-16 surrogate, or None."""
    if isinstance(value, str):
        m = _SURROGATE.search(value)
        return f"{where or 'a string'} holds a lone surrogate (U+{ord(m.group()):04X}): not text" if m else None
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        name = f"{where}[{key}]" if isinstance(key, int) else f"{where}.{key}" if where else f"{key}"
        name = bounded_text(_SURROGATE.sub("?", str(name)), NAME_CHARS)
        problem = (text_problem(key, f"key {name!r}") if isinstance(key, str) else None) or text_problem(item, name)
        if problem:
            return problem
    return None


def sidecar_candidates(path: Path) -> list[Path]:
    """Where the sidecar of a data file may be: <name>.<ext>.json, then <name>.json; for a later file of a file set
    (lutbake.io.file_sets: ltc_dds's <stem>_2.dds, an ltc_aniso table's <stem>_t1.ktx2), the set's sidecar
    <stem>_1.dds.json, <stem>_t0.ktx2.json (it lists every file in ``files``)."""
    out = [path.with_name(path.name + ".json"), path.with_suffix(".json")]
    first = members(path)[:1]
    if first and first[0] != path:
        out.append(first[0].with_name(first[0].name + ".json"))
    return out


def describes(doc: dict, path: Path) -> bool:
    """Whether a sidecar names ``path`` as its data file (``file``) or one of its files (``files``)."""
    files = doc.get("files")
    return doc.get("file") == path.name or (isinstance(files, list) and path.name in files)


def with_sidecar(loaded: LoadedFile) -> LoadedFile:
    """Attach the attributes of the sidecar that names this file (a sidecar naming another file is skipped)."""
    for side in sidecar_candidates(loaded.path):
        if not side.is_file() or side == loaded.path or is_report(load_sidecar_json(side)):
            continue
        doc = load_sidecar(side)
        named = doc.get("file")
        if named is not None and not describes(doc, loaded.path):
            loaded.notes.append(f"{side.name} describes {named}, not this file")
            continue
        loaded.attrs, loaded.meta_source = doc["lutbake"], f"sidecar {side.name}"
        loaded.facts["sidecar_format"] = doc.get("format", "")
        return loaded
    if not loaded.notes:
        loaded.notes.append(f"no sidecar ({' or '.join(p.name for p in sidecar_candidates(loaded.path))})")
    return loaded
