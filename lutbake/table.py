"""The baked table: one object that writers and checks see, its shape checks and its metadata record; and the baked
cube map with mips (the environment kinds' output, written by lutbake.io.cubemap)."""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

from .axes import Axis


@dataclass
class Table:
    """``data`` has shape (y, x, channels) for 2D kinds, (z, y, x, channels) for 3D kinds:
    the axes list follows the array's dimensions in order (slowest first), the channel axis last."""

    name: str
    kind: str
    data: np.ndarray
    axes: list[Axis]
    channels: dict[str, str]
    reconstruction: str
    attributes: dict[str, str] = field(default_factory=dict)  # provenance, written as lutbake:*

    @property
    def shape(self) -> tuple[int, ...]:
        return self.data.shape

    def channel(self, key: str) -> np.ndarray:
        return self.data[..., list(self.channels).index(key)]


@dataclass
class CubeTable:
    """A cube map with mips, the output of an environment kind (lutbake.kinds.environment): ``mips[m]`` is
    (6, n, n, 3) float64, face +X, -X, +Y, -Y, +Z, -Z (lutbake.environment.cube), row t, column s, RGB, n = the
    face size >> m. ``record``: what the bake holds (face convention, mip curve, roughness and alpha per mip,
    weighting, error estimate per mip, the source's sha256 ...; JSON values); ``inputs``: what its values depend on
    besides its config (the bytes of the environment it was baked from, as lutbake.kinds.base.Kind.inputs gives them
    for its content hash); ``attributes``: its provenance (config, versions, content hash), strings as a Table's;
    ``sh``: the L2 SH document an irradiance table writes beside the cube (``<name>_sh.json``), else None."""

    name: str
    kind: str
    mips: list[np.ndarray]
    record: dict
    reconstruction: str
    inputs: bytes = b""
    attributes: dict[str, str] = field(default_factory=dict)
    sh: dict | None = None

    @property
    def shape(self) -> str:
        """ "6x16x16x3, 5 mips": what ``lutbake bake`` prints as a cube table's shape."""
        n = self.mips[0].shape[1]
        return f"6x{n}x{n}x{self.mips[0].shape[-1]}, {len(self.mips)} mip{'s' if len(self.mips) != 1 else ''}"


CHANNEL_LETTERS = ("R", "G", "B", "A")
DTYPES = {"float32": np.float32, "half": np.float16}
# attributes lutbake writes itself; Table.attributes may not shadow them
RESERVED = frozenset(
    {"kind", "table", "axes", "channels", "channel_names", "reconstruction", "slice_index", "slice_value", "data_hash"}
)


def attr_text(value) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, (dict, list, tuple)):
        return json.dumps(value, sort_keys=isinstance(value, dict))
    return str(value)


def pixels(table: Table, dtype: str) -> np.ndarray:
    """The array every writer writes (float32 or float16, C-contiguous, (z,) y, x, C), after every check of the
    table's shape against its axes and channels; ValueError names the table and what is wrong."""
    if dtype not in DTYPES:
        raise ValueError(f"table {table.name!r}: dtype must be one of {sorted(DTYPES)}, got {dtype!r}")
    data = np.asarray(table.data)
    if data.ndim not in (3, 4):
        raise ValueError(f"table {table.name!r}: data must be (y, x, C) or (z, y, x, C), got shape {data.shape}")
    nch = data.shape[-1]
    if not 1 <= nch <= 4:
        raise ValueError(f"table {table.name!r}: a table holds 1 to 4 channels, the data has {nch}")
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
        out = np.ascontiguousarray(data, dtype=DTYPES[dtype])
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


def metadata(table: Table) -> dict[str, str]:
    """The lutbake attributes every format carries (the EXR header's lutbake:* strings, the sidecars' JSON)."""
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
        attrs[str(key)] = attr_text(value)
    return attrs
