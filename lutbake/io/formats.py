"""Every output format of a baked table, behind one dispatcher: ``write_table(table, out_dir, format, dtype)``.

| format | file | pixel types | metadata |
| --- | --- | --- | --- |
| ``exr`` (default) | <name>.exr | float32 / half | ``lutbake:*`` header attributes (lutbake.io.exr) |
| ``npy`` | <name>.npy + <name>.npy.json | float32 / float16 array, table shape | sidecar JSON of the same attributes |
| ``png16`` | <name>.png + <name>.png.json | 16-bit UNORM, linear | no sRGB/iCCP chunk; gAMA = 1.0 where written |
| ``dds`` | <name>.dds + <name>.dds.json | R16G16_FLOAT, R32G32_FLOAT, RGBA16F/32F ... | DX10 header (lutbake.io.dds) |
| ``ktx2`` | <name>.ktx2 + <name>.ktx2.json | VK_FORMAT_R16G16_SFLOAT, ... | key/value data (lutbake.io.ktx2) |
| ``h`` | <name>.h + <name>.h.json | half-float bits (uint16_t) or float | the conventions in a comment block |
Row 0 of every file is table row 0 (no flip); column 0 is x index 0. Every write is atomic; the sidecar
``<file>.json`` is written last and names the sha256 of the data file (lutbake.io.integrity). An output of several
files (ltc_dds's pair; ``ktx2`` / ``dds`` of kind ltc_aniso: three 3D textures, ``KIND_WRITERS``) has one sidecar
naming every file's sha256 (lutbake.io.file_sets).
"""

from __future__ import annotations

from pathlib import Path

from ..table import Table, metadata
from ..table import pixels as checked_pixels
from . import code_arrays, dds, ktx2, ltc, ltc_aniso_textures, openpbr
from .atomic import unit_lock
from .conventions import write_with_sidecar
from .exr import write_exr
from .file_sets import set_files
from .header import write_header
from .npy import write_npy
from .png import write_png16

FORMATS = {
    "exr": "OpenEXR via OpenImageIO, float32 or half, lutbake:* header attributes (default)",
    "npy": "NumPy .npy (float32 / float16, the table's shape) + .json sidecar with the conventions",
    "png16": "16-bit linear PNG (UNORM, values must lie in [0, 1]; no sRGB tag) + .json sidecar",
    "dds": "DDS with DX10 header: R16G16_FLOAT / R32G32_FLOAT / RGBA16F / RGBA32F, 2D or 3D + .json sidecar",
    "ktx2": "KTX 2.0: VK_FORMAT_R16G16_SFLOAT / R32G32_SFLOAT / RGBA16/32, 2D or 3D, metadata in key/value data",
    "h": "C/C++ header: half-float bits (dtype half) or floats (float32), conventions in a comment block",
    "openpbr_h": "OpenPBR's energy-table header: UNORM16 uint16_t arrays under its names (layout openpbr only)",
}
EXTENSIONS = {
    "exr": ".exr",
    "npy": ".npy",
    "png16": ".png",
    "dds": ".dds",
    "ktx2": ".ktx2",
    "h": ".h",
    "openpbr_h": ".h",
    "ktx1": ".ktx",  # the environment_specular kind's Filament KTX 1 (lutbake.io.cubemap), no table format
}


def write_dds(table: Table, path, dtype: str = "float32") -> Path:
    pixels = checked_pixels(table, dtype)
    path = Path(path)
    fmt = dds.DXGI_NAMES[dds.DXGI[(dtype, 4 if pixels.shape[-1] == 3 else pixels.shape[-1])]]
    extra = {"dxgi_format": fmt, "dimension": "TEXTURE3D" if pixels.ndim == 4 else "TEXTURE2D"}
    return write_with_sidecar(table, path, dds.encode(pixels), "dds", extra)


def write_ktx2(table: Table, path, dtype: str = "float32", array: bool = False) -> Path:
    from .. import __version__

    pixels = checked_pixels(table, dtype)
    path = Path(path)
    data = ktx2.encode(pixels, metadata(table), array=array, writer=f"lutbake {__version__}")
    return write_with_sidecar(table, path, data, "ktx2", {"array": array})


def write_openpbr(table: Table, path, dtype: str = "float32") -> Path:
    return openpbr.write_openpbr_header(table, path, dtype)


WRITERS = {
    "exr": write_exr,
    "npy": write_npy,
    "png16": write_png16,
    "dds": write_dds,
    "ktx2": write_ktx2,
    "h": write_header,
    "openpbr_h": write_openpbr,
    **ltc.WRITERS,  # the LTC engine layouts (kind ltc only): lutbake.io.ltc
    **code_arrays.WRITERS,  # JS / WGSL / Rust arrays and zstd KTX2 (lutbake.io.code_arrays); its js serves ltc too
}
FORMAT_KINDS = {"threejs_dfg": ("dfg",)}  # formats that hold one kind's tables only (the rest: any kind)
FORMATS = {**FORMATS, **code_arrays.FORMATS}  # what a table of any kind can be written as (lutbake.kinds.base)
CUBE_ONLY_FORMATS = {"ktx1": "KTX 1 cube as Filament's cmgen writes it (environment_specular only: lutbake.io.ktx1)"}
ALL_FORMATS = {**FORMATS, **ltc.FORMATS, **CUBE_ONLY_FORMATS}  # every format: the --format option; each kind's
# ``format`` key allows a subset (lutbake.kinds.allowed_formats), which the config check and its message use
EXTENSIONS = {**EXTENSIONS, **ltc.EXTENSIONS, **code_arrays.EXTENSIONS}


KIND_WRITERS = {  # (kind, format) -> its writer where a kind writes a format its own way (lutbake.io.file_sets)
    ("ltc_aniso", "ktx2"): ltc_aniso_textures.write_ktx2_textures,
    ("ltc_aniso", "dds"): ltc_aniso_textures.write_dds_textures,
}


def data_files(name: str, fmt: str, kind: str | None = None, options: dict | None = None) -> list[str]:
    """The data files a table ``name`` of ``kind`` writes in ``fmt``: ``<name><ext>``, or a file set's members
    (lutbake.io.file_sets: ltc_dds's pair, an ltc_aniso table's three textures per lobe of its ``options``), the
    first the one its sidecar describes."""
    return set_files(name, kind, fmt, options) or [f"{name}{EXTENSIONS[fmt]}"]


def output_path(out_dir, name: str, fmt: str, kind: str | None = None) -> Path:
    """The file whose metadata says whether the output is up to date: the data file, a file set's first member."""
    return Path(out_dir) / data_files(name, fmt, kind)[0]


def written_files(
    name: str, fmt: str, outputs: tuple[str, ...] = (), kind: str | None = None, options: dict | None = None
) -> list[str]:
    """The names of the files a table ``name`` of ``kind`` (its ``options``) writes in ``fmt``: its data file(s), the
    files its kind writes beside them (``outputs``: suffixes after the name, lutbake.kinds.base.Kind.outputs), then
    its sidecar (every format but EXR, whose header holds the conventions)."""
    files = data_files(name, fmt, kind, options)
    return files + [name + suffix for suffix in outputs] + ([] if fmt == "exr" else [files[0] + ".json"])


def write_table(table: Table, out_dir, fmt: str = "exr", dtype: str = "float32") -> Path:
    """Write ``table`` to ``out_dir/<name>.<ext>`` in ``fmt`` (FORMATS; a file set: output_path), atomically, under
    the output's unit lock (lutbake.io.atomic.unit_lock: a concurrent writer of the same path never slips between its
    data and its sidecar). Returns the path."""
    if fmt not in WRITERS:
        raise ValueError(f"table {table.name!r}: unknown format {fmt!r}; valid: {', '.join(WRITERS)}")
    path = output_path(out_dir, table.name, fmt, table.kind)
    with unit_lock(path):
        return KIND_WRITERS.get((table.kind, fmt), WRITERS[fmt])(table, path, dtype=dtype)
