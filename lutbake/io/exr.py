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

import json
from pathlib import Path

import numpy as np

from ..limits import MAX_EXR_CHANNELS
from ..runtime.warp_runtime import stderr_silenced
from ..table import CHANNEL_LETTERS, Table, metadata
from ..table import pixels as checked_pixels
from . import bounded
from .atomic import atomic_write
from .integrity import HASH_KEY, PLACEHOLDER, seal_exr
from .sidecar import LoadedFile, text_problem

PREFIX = "lutbake:"
EXR_MAGIC = b"\x76\x2f\x31\x01"
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
    """Write ``parts`` (part name, header attrs, (y, x, C) array) as a single- or multi-part EXR. Parts may differ in
    size (a cube's mips, lutbake.io.cubemap): each keeps its own data window, and every part takes the first part's
    display window (OpenEXR requires one for all parts)."""
    oiio = _oiio()
    h0, w0 = parts[0][2].shape[:2]
    specs = []
    for name, attrs, pixels in parts:
        h, w, nch = pixels.shape
        spec = _spec(oiio, w, h, nch, fmt, attrs)
        if (h, w) != (h0, w0):
            spec.full_width, spec.full_height = w0, h0
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


def read_any_exr(path: Path) -> LoadedFile:
    """Any EXR (any tool's: any channels, every part; 3D: a part per z) as a LoadedFile, its lutbake attributes from
    the header (lutbake.io.readers dispatches to it)."""
    parts = exr_parts(path)
    shapes = {p[0].shape for p in parts}
    if len(shapes) != 1:
        raise ValueError(f"its parts have different shapes {sorted(shapes)}")
    attrs = {k: v for k, v in parts[0][1].items() if k not in ("slice_index", "slice_value")}
    problem = text_problem(attrs)
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


def _read_parts(path) -> tuple[list[np.ndarray], list[dict[str, str]], list[dict]]:
    """Every part's pixels (float32, (y, x, C), channels in R, G, B, A order), lutbake attributes,
    and file facts (pixel type, compression, part name), of an EXR lutbake wrote."""
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
