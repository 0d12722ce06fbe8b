"""EXR writer/reader for baked tables, through OpenImageIO.

File layout (the contract engines and ``lutbake inspect`` rely on):

- Channels ``R``, ``G``, ``B``, ``A`` in the order of ``Table.channels`` (1 to 4 channels; a 2-channel
  table is written as ``R``, ``G`` only). Pixel type float32 or half, zip compression (lossless).
- Image row 0 holds y index 0 and column 0 holds x index 0: no vertical flip, whatever engines do.
- A 2D table (data (y, x, C)) is one single-part EXR. A fourth axis (kind ``btf``) is flattened into the
  rows: its dim is ``y_block`` and image row = (y_block index) * (count of the y axis) + (y index). A 3D table (data (z, y, x, C)) is a multi-part
  EXR with one part per z index, named ``slice_<k>`` and carrying ``lutbake:slice_index`` and
  ``lutbake:slice_value`` (the z axis value at that index).
- Every part carries the string attributes ``lutbake:kind``, ``lutbake:table`` (the table's name),
  ``lutbake:axes`` (JSON list of ``Axis.describe()``), ``lutbake:channels`` (JSON object
  ``{"R": "<channel name>: <meaning>", ...}``), ``lutbake:channel_names`` (JSON object
  ``{"R": "<channel name>", ...}``), ``lutbake:reconstruction``, and every item of
  ``Table.attributes`` as ``lutbake:<key>`` (terms, estimator, samples, seed, config, versions ...).
  All ``lutbake:*`` attributes are strings.
- Values are always finite: a NaN or Inf (including a float32 value that overflows half) is an
  error, never written.
- Writes are atomic: the file is written to a temporary sibling, fsynced, then renamed onto the
  target, so an interrupted or failed write never leaves a half-written file or clobbers the old one.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..table import Table
from .atomic import atomic_write

PREFIX = "lutbake:"
CHANNEL_LETTERS = ("R", "G", "B", "A")
DTYPES = {"float32": ("float", np.float32), "half": ("half", np.float16)}
COMPRESSION = "zip"
# attributes lutbake writes itself; Table.attributes may not shadow them
RESERVED = frozenset(
    {"kind", "table", "axes", "channels", "channel_names", "reconstruction", "slice_index", "slice_value"}
)
PER_PART = frozenset({"slice_index", "slice_value"})


def _oiio():
    import OpenImageIO as oiio  # imported lazily: importing lutbake must not require it

    return oiio


# --------------------------------------------------------------------------------------- writing


def _attr_text(value) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, (dict, list, tuple)):
        return json.dumps(value, sort_keys=isinstance(value, dict))
    return str(value)


def _check_table(table: Table, dtype: str) -> np.ndarray:
    """The array to write (float32 or float16, C-contiguous, (z,) y, x, C), after every check."""
    if dtype not in DTYPES:
        raise ValueError(f"table {table.name!r}: dtype must be one of {sorted(DTYPES)}, got {dtype!r}")
    data = np.asarray(table.data)
    if data.ndim not in (3, 4):
        raise ValueError(f"table {table.name!r}: data must be (y, x, C) or (z, y, x, C), got shape {data.shape}")
    nch = data.shape[-1]
    if not 1 <= nch <= 4:
        raise ValueError(f"table {table.name!r}: an EXR holds 1 to 4 channels, the data has {nch}")
    if len(table.channels) != nch:
        raise ValueError(
            f"table {table.name!r}: {len(table.channels)} channel names {list(table.channels)} for {nch} data channels"
        )
    if data.dtype.kind not in "fiu":
        raise ValueError(f"table {table.name!r}: data must be numeric, got dtype {data.dtype}")
    sizes = {"z": data.shape[0] if data.ndim == 4 else 1, "y": data.shape[-3], "x": data.shape[-2]}
    dims = [a.dim for a in table.axes]
    if len(set(dims)) != len(dims):
        raise ValueError(f"table {table.name!r}: two axes share an image dimension: {dims}")
    blocks = [a for a in table.axes if a.dim == "y_block"]
    if blocks:  # a 4th axis flattened into the rows: row = block index * (y count) + y index
        y_axes = [a for a in table.axes if a.dim == "y"]
        if not y_axes or sizes["y"] % blocks[0].count:
            raise ValueError(
                f"table {table.name!r}: a y_block axis needs a y axis and {sizes['y']} rows divisible "
                f"by its count {blocks[0].count}"
            )
        sizes["y_block"] = blocks[0].count
        sizes["y"] //= blocks[0].count
    for axis in table.axes:
        if axis.dim not in sizes:
            raise ValueError(f"table {table.name!r}: axis {axis.name!r} has unknown dim {axis.dim!r}")
        if axis.count != sizes[axis.dim]:
            raise ValueError(
                f"table {table.name!r}: axis {axis.name!r} ({axis.dim}) has count {axis.count} "
                f"but the data has {sizes[axis.dim]} along {axis.dim} (shape {data.shape})"
            )
    if data.ndim == 4 and "z" not in dims:
        raise ValueError(f"table {table.name!r}: a 3D table needs an axis with dim 'z'")
    clash = RESERVED.intersection(table.attributes)
    if clash:
        raise ValueError(f"table {table.name!r}: attributes {sorted(clash)} are reserved (lutbake writes them itself)")

    with np.errstate(over="ignore", invalid="ignore"):
        out = np.ascontiguousarray(data, dtype=DTYPES[dtype][1])
    bad = ~np.isfinite(out)
    if bad.any():
        names = list(table.channels)
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        src = data[idx]
        what = "NaN" if np.isnan(src) else ("Inf" if np.isinf(src) else f"{float(src)!r} (overflows {dtype})")
        raise ValueError(
            f"table {table.name!r}: {int(bad.sum())} non-finite value(s) in {dtype}; first at index "
            f"{idx} (channel {names[idx[-1]]!r}): {what}. Refusing to write a table with NaN/Inf."
        )
    return out


def _header(table: Table) -> dict[str, str]:
    letters = CHANNEL_LETTERS[: len(table.channels)]
    attrs = {
        "kind": table.kind,
        "table": table.name,
        "axes": json.dumps([a.describe() for a in table.axes]),
        "channels": json.dumps(
            {c: f"{name}: {meaning}" for c, (name, meaning) in zip(letters, table.channels.items())},
            ensure_ascii=False,
        ),
        "channel_names": json.dumps(dict(zip(letters, table.channels)), ensure_ascii=False),
        "reconstruction": table.reconstruction,
    }
    for key, value in table.attributes.items():
        attrs[str(key)] = _attr_text(value)
    return attrs


def _spec(oiio, width: int, height: int, nch: int, fmt: str, attrs: dict[str, str]):
    spec = oiio.ImageSpec(width, height, nch, fmt)
    spec.channelnames = CHANNEL_LETTERS[:nch]
    spec.attribute("compression", COMPRESSION)
    for key, value in attrs.items():
        spec.attribute(PREFIX + key, value)
    return spec


def _write_oiio(path: Path, parts: list[tuple[str | None, dict[str, str], np.ndarray]], fmt: str) -> None:
    """Write ``parts`` (part name, header attrs, (y, x, C) array) as a single- or multi-part EXR."""
    oiio = _oiio()
    h, w, nch = parts[0][2].shape
    specs = []
    for name, attrs, _ in parts:
        spec = _spec(oiio, w, h, nch, fmt, attrs)
        if name is not None:
            spec.attribute("name", name)  # the EXR part name
        specs.append(spec)
    out = oiio.ImageOutput.create(str(path))
    if out is None:
        raise OSError(f"OpenImageIO cannot create an EXR writer for {path}: {oiio.geterror()}")
    try:
        ok = out.open(str(path), specs) if len(specs) > 1 else out.open(str(path), specs[0])
        if not ok:
            raise OSError(f"cannot open {path} for writing: {out.geterror()}")
        for k, (spec, (_, _, pixels)) in enumerate(zip(specs, parts)):
            if k > 0 and not out.open(str(path), spec, "AppendSubimage"):
                raise OSError(f"cannot start part {k} of {path}: {out.geterror()}")
            if not out.write_image(pixels):
                raise OSError(f"cannot write pixels of part {k} to {path}: {out.geterror()}")
    finally:
        closed = out.close()
    if not closed:
        raise OSError(f"cannot finish writing {path}: {out.geterror()}")


def write_exr(table: Table, path, dtype: str = "float32") -> Path:
    """Write ``table`` to ``path`` as an EXR (float32 or half), atomically. Returns the path.

    Raises ValueError (naming the table) before touching the disk if the table is malformed or holds
    any NaN/Inf (or a value that overflows half); OSError if the file cannot be written. On any error
    an existing file at ``path`` is left untouched and no temporary file remains.
    """
    path = Path(path)
    pixels = _check_table(table, dtype)
    fmt = DTYPES[dtype][0]
    attrs = _header(table)
    if pixels.ndim == 3:
        parts = [(None, attrs, pixels)]
    else:
        z_axis = next(a for a in table.axes if a.dim == "z")
        z_values = z_axis.values()
        parts = [
            (
                f"slice_{k}",
                {**attrs, "slice_index": str(k), "slice_value": f"{float(z_values[k]):.9g}"},
                pixels[k],
            )
            for k in range(pixels.shape[0])
        ]

    return atomic_write(path, lambda tmp: _write_oiio(tmp, parts, fmt))


# --------------------------------------------------------------------------------------- reading


def _read_parts(path) -> tuple[list[np.ndarray], list[dict[str, str]], list[dict]]:
    """Every part's pixels (float32, (y, x, C), channels in R, G, B, A order), lutbake attributes,
    and file facts (pixel type, compression, part name), of an EXR lutbake wrote."""
    from .readers import EXR_MAGIC, exr_parts

    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such file")
    if not path.is_file():
        raise ValueError(f"{path}: not a file")
    with open(path, "rb") as f:
        if f.read(len(EXR_MAGIC)) != EXR_MAGIC:
            raise ValueError(f"{path}: not an EXR file (no EXR magic number)")
    try:
        parts = exr_parts(path)
    except ValueError as e:
        raise ValueError(f"{path}: not a readable EXR ({e})") from None
    for k, (arr, attrs, facts) in enumerate(parts):
        if "kind" not in attrs:
            raise ValueError(
                f"{path}: not a lutbake EXR (part {k} has no lutbake:kind attribute; was it written by lutbake?)"
            )
        if not facts["channels"] or any(c not in CHANNEL_LETTERS for c in facts["channels"]):
            raise ValueError(f"{path}: part {k} has channels {facts['channels']}; lutbake writes R, G, B, A only")
    shapes = {p[0].shape for p in parts}
    if len(shapes) != 1:
        raise ValueError(f"{path}: parts have different shapes {sorted(shapes)}")
    return [p[0] for p in parts], [p[1] for p in parts], [{**p[2], "format": p[2]["pixel_type"]} for p in parts]


def read_exr(path) -> tuple[np.ndarray, dict[str, str]]:
    """Read a lutbake EXR: (data float32, attrs). data is (y, x, C) for a single-part file and
    (z, y, x, C) for a multi-part (3D, one part per slice) file, channels in R, G, B, A order, row 0 =
    y index 0. attrs holds the ``lutbake:*`` header attributes with the prefix removed; for a 3D table
    the per-slice ``slice_index``/``slice_value`` are left out (they are listed in the z axis)."""
    pixels, attrs, _ = _read_parts(path)
    if len(pixels) == 1 and "slice_index" not in attrs[0]:
        return pixels[0], attrs[0]
    order = [int(a.get("slice_index", k)) for k, a in enumerate(attrs)]
    if sorted(order) != list(range(len(order))):
        raise ValueError(f"{path}: slice indices {order} are not 0..{len(order) - 1}")
    data = np.stack([pixels[order.index(k)] for k in range(len(order))])
    common = {k: v for k, v in attrs[0].items() if k not in PER_PART}
    return data, common
