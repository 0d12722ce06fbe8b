"""Read any LUT file lutbake can audit into a float64 (rows, columns, channels) array.

``read_lut(path, shape=None, encoding=None) -> LutFile``. Formats, by extension:
- ``.exr``: OpenImageIO, float; the ``lutbake:*`` attributes when present.
- ``.png``: OpenImageIO, the raw UNORM codes (8 or 16 bit), value = code / (2^bits - 1), **no transfer function**.
- ``.dds``: DX10 header, R16G16_FLOAT ... RGBA32F (lutbake.io.dds); ``.ktx2``: lutbake.io.ktx2.decode (plain or zstd).
- ``.npy``, ``.npz``: an integer array is UNORM codes (value = code / dtype max), a float array values (npz: the
  array named ``table``, else its only one).
- ``.h .hpp .inc .js .ts .mjs .wgsl .rs``: the numbers of the first brace/bracket array: hex ``0x....`` literals
  are IEEE half bits, decimal literals floats.
``storage`` records how the file stores a value (unorm8/16, half, float32), which the audit's quantisation check uses.
A text array's layout must be declared: ``#define *_HEIGHT/_WIDTH/_CHANNELS`` (lutbake's C header), the
``lutbake:shape`` line of lutbake's JS/WGSL/Rust comment block, or ``shape=(rows, columns, channels)``.
Row 0 of the result is the first row stored in the file (no flip). A JSON sidecar beside the file
(lutbake's ``<file>.json``, or a ``<stem>.json`` provenance note) is returned in ``sidecar``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import bounded

TEXT_EXTENSIONS = (".h", ".hpp", ".inc", ".js", ".mjs", ".ts", ".wgsl", ".rs")
READABLE = (".exr", ".png", ".dds", ".ktx2", ".npy", ".npz") + TEXT_EXTENSIONS


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
    return codes.astype(np.float64) / float((1 << bits) - 1), f"unorm{bits}"


def _float_storage(arr: np.ndarray) -> str:
    return "half" if arr.dtype == np.float16 else "float32" if arr.dtype == np.float32 else "float64"


def _read_png(path: Path) -> tuple[np.ndarray, str]:
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(f"{path}: cannot open PNG: {oiio.geterror()}")
    try:
        spec = inp.spec()
        bounded.check_texels((spec.height, spec.width, spec.nchannels), "the PNG header")
        native = oiio.UINT16 if spec.format.size() == 2 else oiio.UINT8
        codes = inp.read_image(native)  # raw codes: OIIO applies no transfer function on read
    finally:
        inp.close()
    if codes is None:
        raise ValueError(f"{path}: cannot read PNG pixels")
    return _unorm(np.asarray(codes))


def _text_shape(text: str, shape) -> tuple[int, ...]:
    if shape is not None:
        return tuple(int(s) for s in shape)
    m = re.search(
        r"lutbake:shape[ \t]{0,8}[=:][ \t]{0,8}\[?[ \t]{0,8}(\d{1,9})\s{0,8},\s{0,8}(\d{1,9})\s{0,8},\s{0,8}(\d{1,9})",
        text,
    )
    if m:
        return tuple(int(g) for g in m.groups())
    dims = {
        k: int(v)
        for k, v in re.findall(r"#define[ \t]{1,64}\w{0,128}?_(HEIGHT|WIDTH|CHANNELS)[ \t]{1,64}(\d{1,9})", text)
    }
    if len(dims) == 3:
        return dims["HEIGHT"], dims["WIDTH"], dims["CHANNELS"]
    raise ValueError(
        "the array's layout is not declared in the file: give shape=(rows, columns, channels) "
        "(CLI: --shape ROWSxCOLUMNSxCHANNELS)"
    )


def strip_comments(text: str) -> str:
    """Source text without its /* ... */ and // comments, in one pass (linear time: an unclosed ``/*`` ends the
    text, it is never searched for again from each later ``/*``)."""
    out, pos, n = [], 0, len(text)
    block = line = 0  # the next "/*" and "//" at or after pos (-1: none left), each searched for again only once passed
    while pos < n:
        if 0 <= block < pos:
            block = text.find("/*", pos)
        if 0 <= line < pos:
            line = text.find("//", pos)
        if pos == 0:
            block, line = text.find("/*"), text.find("//")
        if block < 0 and line < 0:
            out.append(text[pos:])
            break
        start = min(x for x in (block, line) if x >= 0)
        out.append(text[pos:start])
        out.append(" ")
        if start == block:
            end = text.find("*/", start + 2)
            pos = n if end < 0 else end + 2
        else:
            end = text.find("\n", start)
            pos = n if end < 0 else end
    return "".join(out)


def literal_values(payload: str, n: int) -> tuple[np.ndarray, str]:
    """The first ``n`` numbers of an array literal's body (float64) and how they are stored: hex literals are
    IEEE 754 binary16 bit patterns ("half"), decimal literals floats ("float32")."""
    hexes = re.findall(r"0x([0-9a-fA-F]{1,4})\b", payload)
    if hexes:
        bits = np.array([int(h, 16) for h in hexes[:n]], dtype=np.uint16)
        return bits.view(np.float16).astype(np.float64), "half"
    payload = re.sub(r"_?f(?:32|64)\b", "", payload)  # Rust's 0.5_f32 / 1f64 type suffixes
    nums = re.findall(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?", payload)
    return np.array([float(x) for x in nums[:n]], dtype=np.float64), "float32"


_TOKENS = re.compile(r"[=;({\[]")
_NUMBER_START = re.compile(r"\s*(?:0x|[-+.\d])")


def literal_body(code: str) -> str | None:
    """The body of the first array literal of ``code`` (comments stripped): from the first number after the first
    ``{``, ``[`` or ``(`` that follows an ``=`` or a ``(`` in the same statement ("= {", "= [", "( [" in JS,
    "= array<f32, N>(" in WGSL), up to the next ``;``. One pass over the text (a tokenizer, not a backtracking
    pattern: 10^6 ``=`` take milliseconds)."""
    armed = False
    for m in _TOKENS.finditer(code):
        c = m.group()
        if c == ";":
            armed = False
        elif c == "=":
            armed = True
        else:
            if armed:
                num = _NUMBER_START.match(code, m.end())
                if num:
                    start = num.end() - len(num.group().lstrip())
                    end = code.find(";", start)
                    return code[start : end if end >= 0 else len(code)]
            armed = c == "("
    return None


def parse_text_array(text: str, shape=None) -> tuple[np.ndarray, str]:
    """The values of the first ``{...}`` / ``[...]`` array literal after its declaration (literal_values);
    comments are skipped."""
    body = literal_body(strip_comments(text))
    if body is None:
        raise ValueError("no array literal found")
    shp = _text_shape(text, shape)
    bounded.check_texels(shp, "the declared shape")
    n = int(np.prod(shp))
    arr, storage = literal_values(body, n)
    if arr.size != n:
        raise ValueError(f"the array holds {arr.size} values, the declared shape {shp} needs {n}")
    return arr.reshape(shp), storage


def read_lut(path, shape=None) -> LutFile:
    """Read ``path`` (see the module docstring). ``shape``: (rows, columns, channels) of a text array
    whose file does not declare it."""
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in READABLE:
        raise ValueError(f"{path}: cannot read '{ext}' files; readable: {', '.join(READABLE)}")
    problem = bounded.regular_file_problem(path)
    if problem:
        raise ValueError(f"{path}: {problem}")
    try:
        return _read_lut(path, ext, shape)
    except ValueError as e:
        text = str(e)
        raise ValueError(text if text.startswith(str(path)) else f"{path}: {text}") from None


def _read_lut(path: Path, ext: str, shape) -> LutFile:
    from .dds import decode as dds_decode
    from .exr import read_exr
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
    if ext == ".exr":
        data, attrs = read_exr(path)
        storage = "float32"
    elif ext == ".png":
        data, storage = _read_png(path)
    elif ext == ".dds":
        arr, _ = dds_decode(bounded.read_bytes(path))
        data, storage = arr.astype(np.float64), _float_storage(arr)
    elif ext == ".ktx2":
        arr, facts = ktx2_decode(bounded.read_bytes(path))
        kv = facts["key_value"]
        data, storage = arr.astype(np.float64), _float_storage(arr)
        if "lutbake:metadata" in kv:
            attrs = bounded.loads_json(kv["lutbake:metadata"])
            if not isinstance(attrs, dict):
                raise ValueError("its KTX2 key/value lutbake:metadata is not a JSON object")
    elif ext in (".npy", ".npz"):
        if ext == ".npz":  # one array: named "table" (tests/data), else the only one
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
