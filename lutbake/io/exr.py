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

from ..table import CHANNEL_LETTERS, Table, attr_text, metadata
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


def _open(path: Path):
    oiio = _oiio()
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such file")
    if not path.is_file():
        raise ValueError(f"{path}: not a file")
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(f"{path}: not a readable image ({oiio.geterror()})")
    if inp.format_name() != "openexr":
        inp.close()
        raise ValueError(f"{path}: not an EXR file (OpenImageIO reads it as {inp.format_name()!r})")
    return inp


def _lutbake_attrs(spec) -> dict[str, str]:
    return {
        p.name[len(PREFIX) :]: p.value if isinstance(p.value, str) else attr_text(p.value)
        for p in spec.extra_attribs
        if p.name.startswith(PREFIX)
    }


def _read_parts(path) -> tuple[list[np.ndarray], list[dict[str, str]], list[dict]]:
    """Every part's pixels (float32, (y, x, C), channels in R, G, B, A order), lutbake attributes,
    and file facts (pixel type, compression, part name)."""
    path = Path(path)
    inp = _open(path)
    pixels, attrs, facts = [], [], []
    try:
        k = 0
        while inp.seek_subimage(k, 0):
            spec = inp.spec()
            a = _lutbake_attrs(spec)
            if "kind" not in a:
                raise ValueError(
                    f"{path}: not a lutbake EXR (part {k} has no lutbake:kind attribute; was it written by lutbake?)"
                )
            names = list(spec.channelnames)
            want = [c for c in CHANNEL_LETTERS if c in names]
            if len(want) != len(names) or not names:
                raise ValueError(f"{path}: part {k} has channels {names}; lutbake writes R, G, B, A only")
            arr = inp.read_image(k, 0, 0, len(names), "float")
            if arr is None:
                raise ValueError(f"{path}: cannot read pixels of part {k}: {inp.geterror()}")
            arr = np.asarray(arr, dtype=np.float32).reshape(spec.height, spec.width, len(names))
            arr = arr[..., [names.index(c) for c in want]]
            pixels.append(np.ascontiguousarray(arr))
            attrs.append(a)
            facts.append(
                {
                    "format": str(spec.format),
                    "compression": spec.getattribute("compression"),
                    "name": spec.getattribute("name") or spec.getattribute("oiio:subimagename"),
                    "channels": want,
                }
            )
            k += 1
    finally:
        inp.close()
    shapes = {p.shape for p in pixels}
    if len(shapes) != 1:
        raise ValueError(f"{path}: parts have different shapes {sorted(shapes)}")
    return pixels, attrs, facts


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


# ------------------------------------------------------------------------------------- describing

_PROVENANCE = ("terms", "estimator", "samples", "seed", "error_estimate", "version", "warp_version")


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def _json(path: Path, attrs: dict[str, str], key: str):
    try:
        return json.loads(attrs[key])
    except KeyError:
        raise ValueError(f"{path}: lutbake EXR without lutbake:{key}") from None
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: lutbake:{key} is not valid JSON ({e})") from None


def describe_exr(path) -> str:
    """The human-readable report ``lutbake inspect FILE`` prints: kind, axes, channels,
    reconstruction, provenance and per-channel statistics."""
    path = Path(path)
    pixels, part_attrs, facts = _read_parts(path)
    attrs = {k: v for k, v in part_attrs[0].items() if k not in PER_PART}
    axes = _json(path, attrs, "axes")
    channels = _json(path, attrs, "channels")
    data = np.stack(pixels) if len(pixels) > 1 or "slice_index" in part_attrs[0] else pixels[0]

    lines = [f"{path}"]
    h, w, nch = pixels[0].shape
    layout = f"{len(pixels)} parts (one per z slice) of {w} x {h}" if data.ndim == 4 else f"{w} x {h}"
    lines.append(f"  kind: {attrs['kind']}" + (f"   table: {attrs['table']}" if "table" in attrs else ""))
    lines.append(
        f"  image: {layout}, {nch} channel(s) {','.join(facts[0]['channels'])}, "
        f"{facts[0]['format']}, {facts[0]['compression']} compression"
    )
    lines.append("  row 0 = y index 0, column 0 = x index 0 (no flip)")

    lines.append("axes:")
    for ax in axes:
        values = ax.get("values") or []
        rng = ax.get("range", ["?", "?"])
        lines.append(
            f"  {ax.get('name')}: {ax.get('dim')} ({ax.get('image')}), count {ax.get('count')}, "
            f"range [{_fmt(rng[0])}, {_fmt(rng[1])}]"
        )
        lines.append(
            f"    texel {ax.get('texel')} ({ax.get('texel_formula')}), "
            f"mapping {ax.get('mapping')} ({ax.get('mapping_formula')})"
        )
        if values:
            lines.append(f"    index 0 = {_fmt(values[0])}, index {len(values) - 1} = {_fmt(values[-1])}")
        if ax.get("uv_formula"):
            lines.append(f"    order {ax.get('order')}; sample at {ax.get('uv_formula')}")
        alpha = ax.get("alpha")
        if alpha:
            lines.append(f"    alpha {_fmt(min(alpha))} .. {_fmt(max(alpha))} ({ax.get('alpha_formula')})")
    if data.ndim == 4:
        slices = ", ".join(f"{f['name']}={a.get('slice_value', '?')}" for f, a in zip(facts, part_attrs))
        lines.append(f"  parts: {slices}")

    lines.append("channels:")
    for c in facts[0]["channels"]:
        lines.append(f"  {c} = {channels.get(c, '(no meaning recorded)')}")
    lines.append("reconstruction:")
    lines.extend(f"  {line}" for line in attrs.get("reconstruction", "(none recorded)").splitlines())

    lines.append("provenance:")
    for key in _PROVENANCE:
        if key in attrs:
            lines.append(f"  {key}: {attrs[key]}")
    if "config" in attrs:
        n = len(attrs["config"].splitlines())
        lines.append(f"  config: {n} line(s) of TOML in lutbake:config")
    shown = {"kind", "table", "axes", "channels", "channel_names", "reconstruction", "config", *_PROVENANCE}
    for key in sorted(set(attrs) - shown):
        value = attrs[key]
        lines.append(f"  {key}: {value if len(value) <= 200 else value[:200] + ' ...'}")

    lines.append("statistics:")
    flat = data.reshape(-1, data.shape[-1]).astype(np.float64)
    for i, c in enumerate(facts[0]["channels"]):
        col = flat[:, i]
        lines.append(f"  {c}: min {_fmt(col.min())}  max {_fmt(col.max())}  mean {_fmt(col.mean())}")
    return "\n".join(lines) + "\n"
