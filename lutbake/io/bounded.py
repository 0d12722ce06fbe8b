"""Bounded reading of files someone may have sent: every reader of lutbake goes through here, so a hostile file
costs at most a table's worth of memory and time, and fails with one ValueError line that says what the file
claims and what the cap is (issue 38).

- **Sizes first.** A header's declared dimensions are checked against ``MAX_READ_TEXELS`` (a LUT is at most
  lutbake.config.MAX_TEXELS texels, times a few slices for engine layouts) *before* any pixel buffer is allocated
  (check_texels); compressed data is decompressed in a stream that stops at the size the header declares
  (zstd_decompress: a frame with no content size, or one that inflates past its claim, is refused).
- **NumPy.** ``.npy`` headers are parsed with a bounded header size, numeric dtypes only (no object, no
  structured dtype), their data size checked against the file's; ``.npz`` members are checked by their declared
  uncompressed size, which zipfile enforces while reading (load_npy, load_npz).
- **Text.** Text and JSON files are read only up to a size cap (read_text, load_json); JSON nested too deeply is a
  ValueError, not a RecursionError.
- **Regular files only.** A FIFO, a device or a directory is named as what it is (regular_file_problem).
"""

from __future__ import annotations

import contextlib
import contextvars
import io
import json
import math
import os
import stat
import tokenize
import zipfile

import numpy as np

from ..limits import (
    MAX_CHANNELS,
    MAX_EXR_ALL_HEADERS,
    MAX_EXR_ATTRIBUTES,
    MAX_EXR_HEADER_BYTES,
    MAX_EXR_PARTS,
    MAX_JSON_BYTES,
    MAX_JSON_DEPTH,
    MAX_READ_BYTES,
    MAX_READ_MEMORY,
    MAX_READ_TEXELS,
    MAX_TEXT_BYTES,
)

NPY_HEADER_LIMIT = 10000  # numpy's own default max_header_size
# Memory: one budget for what a read and its command's work on the values take together, computed from the shape and
# the stored dtype before anything is allocated (check_memory). Bytes per value, measured as max RSS over the values
# of a 2048 x 2048 RGBA float32 file (KTX2, npy, EXR, PNG16; lutbake 1 GiB files alike): the reader holds the stored
# values plus a float32 table (READ_BYTES + the stored item size); the command adds PROCESSING_BYTES.
READ_BYTES = 4  # the float32 table beside the stored values (an EXR: OpenImageIO's float buffer is the stored copy)
PROCESSING_BYTES = {
    "inspect": 0,
    "preview": 16,
    "audit": 100,
}  # measured totals: inspect 4-8, preview 20-22, audit 99-102
_COMMAND = contextvars.ContextVar("lutbake_read_command", default="inspect")

_FILE_TYPES = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def what_is(mode: int) -> str:
    return next((name for test, name in _FILE_TYPES if test(mode)), "a special file")


def regular_file_problem(path, follow: bool = True) -> str | None:
    """Why ``path`` is not a regular file lutbake may open ("no such file", "is a FIFO (named pipe)", ...), or
    None. ``follow=False``: a symlink is refused too (the values cache opens only its own files)."""
    try:
        st = os.stat(path) if follow else os.lstat(path)
    except FileNotFoundError:
        return "is a dangling symlink" if os.path.islink(path) else "no such file"
    except OSError as e:
        return f"cannot read: {e.strerror or e}"
    if stat.S_ISLNK(st.st_mode):
        return "is a symlink"
    if not stat.S_ISREG(st.st_mode):
        return f"is {what_is(st.st_mode)}, not a regular file"
    return None


def _open_regular(path, limit: int, what: str):
    """An open binary file at ``path`` (regular files only: O_NONBLOCK, so a FIFO never blocks the open), and its
    size, which must be at most ``limit``."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ValueError(f"is {what_is(st.st_mode)}, not a regular file")
        if st.st_size > limit:
            raise ValueError(f"is {st.st_size} bytes; {what} is at most {limit} bytes")
        return os.fdopen(fd, "rb"), st.st_size
    except BaseException:
        os.close(fd)
        raise


def read_bytes(path, limit: int = MAX_READ_BYTES, what: str = "a table file") -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them (ValueError otherwise)."""
    f, size = _open_regular(path, limit, what)
    with f:
        data = f.read(size + 1)  # read(n) allocates n bytes up front: the file's size, never the cap
    if len(data) > size:
        raise ValueError(f"grew past {size} bytes while being read")
    return data


def read_text(path, limit: int = MAX_TEXT_BYTES, what: str = "a text table", errors: str = "strict") -> str:
    """The UTF-8 text of ``path`` (a leading BOM dropped), at most ``limit`` bytes."""
    return read_bytes(path, limit, what).decode("utf-8", errors).removeprefix("\ufeff")


def json_depth_problem(text: str, limit: int = MAX_JSON_DEPTH) -> str | None:
    """Arrays/objects nested deeper than ``limit`` in JSON ``text``, found in one linear pass before parsing."""
    depth = 0
    in_string = escaped = False
    for ch in text:
        if in_string:
            if escaped:
                escaped = False
            elif ch == "\\":
                escaped = True
            elif ch == '"':
                in_string = False
        elif ch == '"':
            in_string = True
        elif ch in "[{":
            depth += 1
            if depth > limit:
                return f"JSON nested more than {limit} deep"
        elif ch in "]}":
            depth -= 1
    return None


def loads_json(text: str, limit: int = MAX_JSON_DEPTH):
    """json.loads with a nesting bound: ValueError (never RecursionError) for JSON nested past ``limit``."""
    problem = json_depth_problem(text, limit) if text.count("[") + text.count("{") > limit else None
    if problem:
        raise ValueError(problem)
    try:
        return json.loads(text)
    except RecursionError:
        raise ValueError(f"JSON nested more than {limit} deep") from None


def load_json(path, limit: int = MAX_JSON_BYTES):
    """The JSON document in the regular file ``path`` (at most ``limit`` bytes, MAX_JSON_DEPTH deep)."""
    return loads_json(read_text(path, limit, "a JSON sidecar"))


def check_texels(shape, what: str = "the file", channels: int | None = None, itemsize: int = 4) -> None:
    """ValueError unless ``shape`` (its texels: every dimension but the last, channels, when ``channels`` is None)
    is a table lutbake may hold: at most MAX_READ_TEXELS texels and MAX_CHANNELS channels, none empty, and its
    values stored as ``itemsize`` bytes fit the memory budget (check_memory)."""
    dims = [int(d) for d in shape]
    if channels is None:
        dims, channels = dims[:-1], dims[-1] if dims else 1
    texels = math.prod(dims)
    shown = " x ".join(map(str, dims + [channels]))
    if any(d < 1 for d in dims) or channels < 1:
        raise ValueError(f"{what} declares {shown}: an empty table")
    if texels > MAX_READ_TEXELS:
        raise ValueError(
            f"{what} declares {shown} ({texels} texels); a table lutbake reads is at most {MAX_READ_TEXELS} texels "
            f"(2 x lutbake.config.MAX_TEXELS): refused before reading"
        )
    if channels > MAX_CHANNELS:
        raise ValueError(f"{what} declares {shown}: {channels} channels (a table has 1 to {MAX_CHANNELS})")
    check_memory(dims + [channels], itemsize, what)


@contextlib.contextmanager
def reading_for(command: str):
    """Reads inside are budgeted for ``command`` ("inspect", "preview", "audit"): its PROCESSING_BYTES per value."""
    token = _COMMAND.set(command)
    try:
        yield
    finally:
        _COMMAND.reset(token)


def check_memory(shape, itemsize: int, what: str = "the file") -> None:
    """ValueError unless reading ``shape`` values stored as ``itemsize`` bytes each, and the current command's work on
    them (reading_for), fits MAX_READ_MEMORY: refused before anything is allocated, naming the shape and the bytes."""
    values = math.prod(int(d) for d in shape)
    command = _COMMAND.get()
    per_value = itemsize + READ_BYTES + PROCESSING_BYTES[command]
    need = values * per_value
    if need > MAX_READ_MEMORY:
        raise ValueError(
            f"{what} declares {' x '.join(map(str, shape))} ({values} values of {itemsize} bytes): {command} would "
            f"need about {need / (1 << 30):.1f} GiB ({per_value} bytes a value, measured), more than the "
            f"{MAX_READ_MEMORY >> 30} GiB a read may take: refused before reading"
        )


def zstd_decompress(data: bytes, size: int) -> bytes:
    """One zstd frame expanded to exactly ``size`` bytes, streamed: never more than ``size`` + 1 bytes are made,
    whatever the frame declares (or omits) as its content size. ValueError for a truncated or corrupt frame."""
    import zstandard

    out = bytearray(size + 1)  # filled in place: the declared size once (BytesIO + getvalue held it twice)
    view, got = memoryview(out), 0
    try:
        with zstandard.ZstdDecompressor().stream_reader(io.BytesIO(data), read_across_frames=False) as reader:
            while got <= size:
                n = reader.readinto(view[got : min(got + (1 << 20), size + 1)])
                if not n:
                    break
                got += n
    except zstandard.ZstdError as e:
        raise ValueError(f"its zstd data cannot be decompressed ({e})") from None
    finally:
        view.release()
    if got != size:
        more = "more than" if got > size else "only"
        raise ValueError(
            f"its zstd data expands to {more} {got} bytes; the header declares {size} (truncated or forged)"
        )
    del out[size:]  # the one byte of slack: bytearray shrinks in place
    return out


# ------------------------------------------------------------------------------------------------ EXR

# OpenEXR file layout (openexr.com, "OpenEXR File Layout"): magic 76 2f 31 01, a 4-byte version field (bit 12:
# multi-part), then per part a header of attributes ``name\0 type\0 int32 size, value``, ended by a NUL; a multi-part
# file ends its list of headers with an empty header (one more NUL)
EXR_MULTIPART = 0x1000
EXR_NAME_BYTES = 256  # an attribute's name or type is at most 255 bytes (long names)


def exr_header_problem(path) -> str | None:
    """What is past the caps in the headers of the EXR at ``path`` (attributes and bytes per part, parts), read by a
    linear walk of the attribute list before OpenImageIO parses them (its header parsing is super-linear: 10 000
    attributes took 0.7 s, 40 000 took 8 s); None when within them. A malformed list is left to OpenImageIO."""
    f, size = _open_regular(path, MAX_READ_BYTES, "an EXR")
    with f:
        blob = f.read(min(size, 8 + MAX_EXR_ALL_HEADERS + 1))
    if len(blob) < 8:
        return None
    multipart = int.from_bytes(blob[4:8], "little") & EXR_MULTIPART
    pos, part = 8, 0
    while pos < len(blob):
        start, count = pos, 0
        while pos < len(blob) and blob[pos] != 0:
            name_end = blob.find(b"\0", pos, pos + EXR_NAME_BYTES)
            type_end = blob.find(b"\0", name_end + 1, name_end + 1 + EXR_NAME_BYTES) if name_end >= 0 else -1
            if type_end < 0 or type_end + 5 > len(blob):
                return None  # malformed or cut: OpenImageIO says what is wrong
            pos = type_end + 5 + int.from_bytes(blob[type_end + 1 : type_end + 5], "little", signed=True)
            count += 1
            if count > MAX_EXR_ATTRIBUTES or pos - start > MAX_EXR_HEADER_BYTES:
                held = f"more than {MAX_EXR_ATTRIBUTES}" if count > MAX_EXR_ATTRIBUTES else f"{count}"
                return (
                    f"part {part}'s header holds {held} attributes in {pos - start} bytes or more; an EXR header "
                    "lutbake reads holds at most "
                    f"{MAX_EXR_ATTRIBUTES} attributes in {MAX_EXR_HEADER_BYTES} bytes: refused before parsing it"
                )
            if pos <= type_end:
                return None
        pos, part = pos + 1, part + 1
        if not multipart or pos >= len(blob) or blob[pos] == 0:
            return None
        if part >= MAX_EXR_PARTS or pos > 8 + MAX_EXR_ALL_HEADERS:
            return (
                f"its headers run past {part} parts and {pos - 8} bytes; an EXR lutbake reads has at most "
                f"{MAX_EXR_PARTS} parts and {MAX_EXR_ALL_HEADERS} bytes of headers: refused before parsing them"
            )
    return None


# ---------------------------------------------------------------------------------------------- NumPy


def _npy_header(f, where: str) -> tuple[tuple[int, ...], np.dtype, bool]:
    """(shape, dtype, fortran_order) of the .npy stream ``f`` positioned at its start; the stream is left at the
    data. Only numeric dtypes (bool, integers, floats) are tables; anything else is a ValueError."""
    from numpy.lib import format as npformat

    try:
        version = npformat.read_magic(f)
        if version == (1, 0):
            shape, fortran, dtype = npformat.read_array_header_1_0(f, max_header_size=NPY_HEADER_LIMIT)
        elif version in ((2, 0), (3, 0)):
            shape, fortran, dtype = npformat.read_array_header_2_0(f, max_header_size=NPY_HEADER_LIMIT)
        else:
            raise ValueError(f"npy format version {version}")
    except (ValueError, SyntaxError, TypeError, tokenize.TokenError, MemoryError, RecursionError, EOFError) as e:
        first = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise ValueError(f"{where}: not a readable .npy header ({first[:120]})") from None
    if dtype.hasobject or dtype.fields is not None or dtype.subdtype is not None or dtype.kind not in "biuf":
        raise ValueError(f"{where}: .npy of dtype {str(dtype)[:80]} holds no plain numbers (a table is int or float)")
    if not isinstance(shape, tuple) or not all(isinstance(d, int) and d >= 0 for d in shape):
        raise ValueError(f"{where}: .npy shape {str(shape)[:80]} is not a shape")
    return shape, dtype, fortran


def _npy_data(f, shape, dtype, fortran, available: int, where: str, table: bool = True) -> np.ndarray:
    """The array data after a header; ``table``: (y, x[, C]) or (z, y, x, C), else any array of at most 4
    dimensions (an engine's arrays, e.g. OpenPBR's 32^3 energy tables) whose values count as texels."""
    if len(shape) == 2 or not table and 1 <= len(shape) <= 4:
        check_texels(shape, where, channels=1, itemsize=dtype.itemsize)
    elif table and 3 <= len(shape) <= 4:
        check_texels(shape, where, itemsize=dtype.itemsize)
    else:
        raise ValueError(f"{where}: array of shape {shape} is not a table (2 to 4 dimensions)")
    nbytes = math.prod(shape) * dtype.itemsize
    if nbytes > available:
        raise ValueError(f"{where}: its header declares {shape} {dtype} ({nbytes} bytes), the file holds {available}")
    data = f.read(nbytes)
    if len(data) != nbytes:
        raise ValueError(f"{where}: truncated: {len(data)} of the {nbytes} data bytes its header declares")
    arr = np.frombuffer(data, dtype=dtype)
    return arr.reshape(shape[::-1]).transpose() if fortran else arr.reshape(shape)


def load_npy(path, limit: int = MAX_READ_BYTES) -> np.ndarray:
    """The array of the ``.npy`` file ``path``: header bounded and checked (numeric dtype, 2 to 4 dimensions, at most
    MAX_READ_TEXELS texels) before its data is read; no pickles."""
    f, size = _open_regular(path, limit, "a .npy table")
    with f:
        shape, dtype, fortran = _npy_header(f, "the .npy")
        return _npy_data(f, shape, dtype, fortran, size - f.tell(), "the .npy")


def load_npz(path, member: str | None = None, limit: int = MAX_READ_BYTES) -> tuple[np.ndarray, str]:
    """(array, member name) of an ``.npz``: ``member``, else ``table``, else its only array. The member's declared
    uncompressed size is checked against ``limit`` before it is inflated (zipfile stops at that size)."""
    f, _ = _open_regular(path, limit, "an .npz archive")
    with f:
        try:
            with zipfile.ZipFile(f) as z:
                names = [n for n in z.namelist() if n.endswith(".npy")]
                if not names:
                    raise ValueError("an .npz without arrays")
                want = (member or "table") + ".npy"
                name = want if want in names else names[0]
                if member is None and want not in names and len(names) > 1:
                    raise ValueError(f"an .npz of {len(names)} arrays and none named 'table'")
                info = z.getinfo(name)
                if info.file_size > limit:
                    raise ValueError(f"member {name} declares {info.file_size} bytes uncompressed; the cap is {limit}")
                with z.open(info) as m:
                    shape, dtype, fortran = _npy_header(m, f"member {name}")
                    arr = _npy_data(m, shape, dtype, fortran, info.file_size, f"member {name}")
        except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, NotImplementedError, OSError) as e:
            raise ValueError(f"not a readable .npz ({e})") from None
    return arr, name[: -len(".npy")]


def load_npz_all(path, limit: int = MAX_READ_BYTES, max_members: int = 64) -> dict[str, np.ndarray]:
    """Every array of an ``.npz`` (at most ``max_members``, their declared sizes together at most ``limit``)."""
    f, _ = _open_regular(path, limit, "an .npz archive")
    out = {}
    with f:
        try:
            with zipfile.ZipFile(f) as z:
                infos = [i for i in z.infolist() if i.filename.endswith(".npy")]
                total = sum(i.file_size for i in infos)
                if len(infos) > max_members or total > limit:
                    raise ValueError(
                        f"an .npz of {len(infos)} arrays declaring {total} bytes; at most {max_members} arrays and "
                        f"{limit} bytes are read"
                    )
                for info in infos:
                    with z.open(info) as m:
                        where = f"member {info.filename}"
                        shape, dtype, fortran = _npy_header(m, where)
                        arr = _npy_data(m, shape, dtype, fortran, info.file_size, where, table=False)
                        out[info.filename[: -len(".npy")]] = arr
        except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, NotImplementedError, OSError) as e:
            raise ValueError(f"not a readable .npz ({e})") from None
    return out


def gunzip(raw: bytes, limit: int = MAX_TEXT_BYTES) -> bytes:
    """gzip data expanded, at most ``limit`` bytes (a gzip bomb is refused after ``limit`` bytes, not after all)."""
    import gzip

    try:
        with gzip.GzipFile(fileobj=io.BytesIO(raw)) as g:
            out = g.read(limit + 1)
    except (OSError, EOFError) as e:
        raise ValueError(f"not readable gzip data ({e})") from None
    if len(out) > limit:
        raise ValueError(f"its gzip data expands past {limit} bytes (the cap of a text table)")
    return out
