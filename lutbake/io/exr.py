"""EXR writer/reader for baked tables, through OpenImageIO.

File layout (the contract engines and ``lutbake inspect`` rely on):

- Channels ``R``, ``G``, ``B``, ``A`` in the order of ``Table.channels`` (1 to 4 channels; a 2-channel
  table is written as ``R``, ``G`` only). Pixel type float32 or half, zip compression (lossless).
- Image row 0 holds y index 0 and column 0 holds x index 0: no vertical flip, whatever engines do.
- A 2D table (data (y, x, C)) is one single-part EXR. A fourth axis (kind ``btf``) is flattened into the
  rows: its dim is ``y_block`` and image row = (y_block index) * (count of the y axis) + (y index).
  A 3D table (data (z, y, x, C)) is a multi-part
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
- ``lutbake:data_hash`` (every part): the sha256 of the file's bytes with these 64 hex digits set to ``0``
  (lutbake.io.integrity); a rerun skips the table only if it matches, so a truncated or garbled file is
  baked again.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..table import CHANNEL_LETTERS, Table, metadata
from ..table import pixels as checked_pixels
from .atomic import atomic_write
from .integrity import HASH_KEY, PLACEHOLDER, seal_exr

PREFIX = "lutbake:"
EXR_TYPES = {"float32": "float", "half": "half"}
COMPRESSION = "zip"
PER_PART = frozenset({"slice_index", "slice_value"})


def _oiio():
    import OpenImageIO as oiio  # imported lazily: importing lutbake must not require it

    return oiio


# --------------------------------------------------------------------------------------- writing


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
    data = checked_pixels(table, dtype)
    fmt = EXR_TYPES[dtype]
    attrs = {**metadata(table), HASH_KEY: PLACEHOLDER.decode()}  # sealed with the file's hash before the rename
    if data.ndim == 3:
        parts = [(None, attrs, data)]
    else:
        z_axis = next(a for a in table.axes if a.dim == "z")
        z_values = z_axis.values()
        parts = [
            (
                f"slice_{k}",
                {**attrs, "slice_index": str(k), "slice_value": f"{float(z_values[k]):.9g}"},
                data[k],
            )
            for k in range(data.shape[0])
        ]

    def write(tmp):
        _write_oiio(tmp, parts, fmt)
        seal_exr(tmp)

    return atomic_write(path, write)


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
    for k, (_, attrs, facts) in enumerate(parts):
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
