"""An ``ltc_aniso`` table (lutbake.kinds.ltc_aniso) as the 3D textures its shader samples, three per lobe, one file
each: ``format = "ktx2"`` -> <name>_t0.ktx2, <name>_t1.ktx2, <name>_t2.ktx2 (2, 3 lobes: to _t5, _t8);
``format = "dds"`` -> <name>_t0.dds, ... (lutbake.io.file_sets), written as one unit: the other files, then
<name>_t0.*, then the sidecar <name>_t0.<ext>.json naming the sha256 of all of them (lutbake.io.integrity), so a
missing or edited texture makes the output not up to date.

Texture k (t0 = (M00, M01, M02, M10), t1 = (M11, M12, M20, M21), t2 = (M22, magnitude, fresnel, fit_error); two
or three lobes: (t0, t1, t2) lobe 1's, (t3, t4, t5) lobe 2's, (t6, t7, t8) lobe 3's, t2, t5, t8 = (M22, weight,
weight_fresnel, sum_error)) is
width N (phi_v), height N (theta_v), depth N^2 (layer = b + N a), RGBA, one level:
- **KTX 2.0** (lutbake.io.ktx2.encode): pixelDepth N^2, layerCount 0, faceCount 1, levelCount 1,
  VK_FORMAT_R16G16B16A16_SFLOAT (dtype half) / R32G32B32A32_SFLOAT (float32), the basic DFD (RGBSDA, BT.709, linear),
  ``KTXorientation`` ``rdi``, ``KTXwriter``, ``lutbake:metadata``: the table's record as this texture's (axes
  layer (z), theta_v (y), phi_v (x); its four channels; ``ltc_aniso_texture``), so each file reads alone.
- **DDS** (lutbake.io.dds.encode): DX10 header, D3D10_RESOURCE_DIMENSION_TEXTURE3D, DDSD_DEPTH, DDSCAPS2_VOLUME,
  depth N^2, one mip, DXGI_FORMAT_R16G16B16A16_FLOAT / R32G32B32A32_FLOAT; the record in the sidecar.
The texels in glTexImage3D's order (x = phi fastest, then theta, then layer): texture k's bytes are the EXR's part k
and the npy's ``[k]``, the same dtype, byte for byte. Values are checked finite (and within half's range) before any
file is written (lutbake.table.pixels).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..axes import IMAGE_DIMS
from ..table import Table, metadata
from ..table import pixels as checked_pixels
from . import bounded, dds, ktx2
from .conventions import write_set_with_sidecar
from .file_sets import MAX_LOBES, TEXTURES_PER_LOBE, file_set, members
from .sidecar import ReadError, load_sidecar

KIND = "ltc_aniso"
TEXTURES = {  # the shader's sampler -> its RGBA (docs/shaders/ltc_aniso.glsl; lutbake.ltc.aniso.texture_layout)
    "t0": ("M00", "M01", "M02", "M10"),
    "t1": ("M11", "M12", "M20", "M21"),
    "t2": ("M22", "magnitude", "fresnel", "fit_error"),
}
LOBE_TEXTURES = (
    TEXTURES["t0"],
    TEXTURES["t1"],
    ("M22", "weight", "weight_fresnel", "sum_error"),
)  # the sets of K > 1 lobes
CONTAINERS = {"ktx2": "KTX 2.0", "dds": "DDS"}
SIDECAR_FORMATS = {file_set(KIND, fmt)[1]: fmt for fmt in CONTAINERS}  # ltc_aniso_ktx2 -> ktx2, ...
SET_SIZES = tuple(TEXTURES_PER_LOBE * k for k in range(1, MAX_LOBES + 1))  # files of a set: three per lobe


def texture_names(count: int) -> dict[str, tuple[str, ...]]:
    """Each texture's RGBA names of a table of ``count`` textures: 3 (one lobe) TEXTURES, 3 K (K lobes) LOBE_TEXTURES
    K times (t0..t2 lobe 1, t3..t5 lobe 2, ...)."""
    if count == len(TEXTURES):
        return TEXTURES
    return {f"t{k}": LOBE_TEXTURES[k % len(LOBE_TEXTURES)] for k in range(count)}


def textures(table: Table, dtype: str) -> np.ndarray:
    """The textures of ``table``, (3 lobes, N^2, N, N, 4) (texture, layer, theta, phi, RGBA) of ``dtype``, every
    value checked (lutbake.table.pixels: finite, within half's range); ValueError names the table."""
    if table.kind != KIND:
        raise ValueError(f"table {table.name!r}: 3D texture files hold kind {KIND!r} tables, not {table.kind!r}")
    data = checked_pixels(table, dtype)
    layers = next(a.count for a in table.axes if a.dim == "y_block")
    return data.reshape(len(data), layers, data.shape[1] // layers, data.shape[2], 4)


def texture_record(attrs: dict[str, str], k: int, files: list[str]) -> dict[str, str]:
    """The record of texture ``k`` of a table whose record is ``attrs`` (lutbake.table.metadata): its axes (the
    table's without ``texture``, ``layer`` as z), its four channels and ``ltc_aniso_texture``; the rest the table's."""
    axes = [  # the table's z axis is the texture; its y_block axis (layer) the texture's depth
        {**d, "dim": "z", "image": IMAGE_DIMS["z"]} if d["dim"] == "y_block" else d
        for d in json.loads(attrs["axes"])
        if d["dim"] != "z"
    ]
    names = texture_names(len(files))[f"t{k}"]
    meanings, table_names = json.loads(attrs["channels"]), json.loads(attrs["channel_names"])
    meanings = {c: meanings[c].removeprefix(f"{table_names[c]}: ") for c in "RGBA"}  # "t0: M00; t1: M11; ..."
    record = dict(attrs)
    record["axes"] = json.dumps(axes)
    record["channel_names"] = json.dumps(dict(zip("RGBA", names)))
    record["channels"] = json.dumps({c: f"{n}: {meanings[c]}" for c, n in zip("RGBA", names)}, ensure_ascii=False)
    record["ltc_aniso_texture"] = (
        f"t{k} = ({', '.join(names)}): the shader's sampler3D t{k} (docs/shaders/ltc_aniso.glsl), width phi_v, height "
        f"theta_v, depth layer; the table's {len(files)} textures: {', '.join(files)}"
    )
    return record


def _write(table: Table, path, dtype: str, container: str) -> Path:
    from .. import __version__

    path = Path(path)
    suffixes, sidecar_format = file_set(KIND, container)
    stem = path.name[: -len(suffixes[0])]
    data = textures(table, dtype)
    names = [stem + s for s in suffixes[: len(data)]]
    attrs = metadata(table)
    if container == "ktx2":
        blobs = [
            ktx2.encode(t, texture_record(attrs, k, names), writer=f"lutbake {__version__}") for k, t in enumerate(data)
        ]
        extra = {"vk_format": ktx2.VK_FORMAT_NAMES[ktx2.VK_FORMAT[(dtype, 4)]]}
    else:
        blobs = [dds.encode(t) for t in data]
        extra = {"dxgi_format": dds.DXGI_NAMES[dds.DXGI[(dtype, 4)]], "dimension": "TEXTURE3D"}
    channels = texture_names(len(names))
    extra["textures"] = {name: f"t{k} = ({', '.join(channels[f't{k}'])})" for k, name in enumerate(names)}
    extra["texture_size"] = {"width": data.shape[3], "height": data.shape[2], "depth": data.shape[1]}
    return write_set_with_sidecar(table, path, dict(zip(names, blobs)), sidecar_format, extra)


def write_ktx2_textures(table: Table, path, dtype: str = "float32") -> Path:
    """<name>_t0.ktx2, _t1.ktx2, _t2.ktx2 (2, 3 lobes: to _t5, _t8) and the sidecar (module docstring); ``path`` the
    first."""
    return _write(table, path, dtype, "ktx2")


def write_dds_textures(table: Table, path, dtype: str = "float32") -> Path:
    """<name>_t0.dds, _t1.dds, _t2.dds (2, 3 lobes: to _t5, _t8) and the sidecar (module docstring); ``path`` the
    first."""
    return _write(table, path, dtype, "dds")


# ------------------------------------------------------------------------------------------------- reading


@dataclass
class TextureSet:
    """The textures read back: ``data`` (3 lobes, N^2, N, N, 4) as stored (float16 / float32), ``record`` the
    table's (the sidecar's ``lutbake`` object), ``files`` their paths, ``container`` ktx2 or dds."""

    data: np.ndarray
    record: dict[str, str]
    files: list[Path]
    container: str


def _set_of(path: Path) -> tuple[list[Path], dict]:
    """(the files, the sidecar document) of the texture set ``path`` (any of its files) belongs to: as many as the
    sidecar lists (three per lobe)."""
    files = members(path)
    if not files or not any(files[0].name.endswith(file_set(KIND, c)[0][0]) for c in CONTAINERS):
        raise ReadError(f"{path}: not one of an ltc_aniso table's textures (<name>_t0, _t1, ... .ktx2 or .dds)")
    side = files[0].with_name(files[0].name + ".json")
    if not side.is_file():
        raise ReadError(f"{path}: its set's sidecar {side.name} is missing (it lists the textures)")
    doc = load_sidecar(side)
    listed = doc.get("files")
    count = len(listed) if isinstance(listed, list) else 0
    if doc.get("format") not in SIDECAR_FORMATS or count not in SET_SIZES or listed != [f.name for f in files[:count]]:
        raise ReadError(f"{side}: not the sidecar of an ltc_aniso texture set {[f.name for f in files[:3]]} ...")
    if path.name not in listed:
        raise ReadError(f"{path}: not one of the textures its set's sidecar {side.name} lists ({', '.join(listed)})")
    return files[:count], doc


def texture_shape(record: dict[str, str]) -> tuple[int, int, int, int]:
    """(depth, height, width, 4) of each texture of a table whose record is ``record``: (N^2, N, N, 4)."""
    counts = {d["dim"]: int(d["count"]) for d in bounded.loads_json(record["axes"])}
    return counts["y_block"], counts["y"], counts["x"], 4


def decode_texture(path: Path, container: str, shape: tuple[int, ...]) -> tuple[np.ndarray, dict]:
    """(texels as stored, the container's facts) of one texture file, refused (ReadError naming ``path``) where it is
    no 3D RGBA texture of ``shape`` (depth, height, width, 4) or its data is cut short."""
    decode = ktx2.decode if container == "ktx2" else dds.decode
    try:
        arr, facts = decode(bounded.read_bytes(path))
    except (ValueError, OSError) as e:
        raise ReadError(f"{path}: not a readable {CONTAINERS[container]} texture: {e}") from None
    dimension = facts["dimension"].removeprefix("TEXTURE")  # DDS: TEXTURE2D, TEXTURE3D
    if dimension != "3D" or arr.shape != shape:
        got = f"a {dimension} texture of {' x '.join(map(str, arr.shape))}"
        raise ReadError(
            f"{path}: {got}; an ltc_aniso table's texture is 3D, depth x height x width x RGBA "
            f"{' x '.join(map(str, shape))} (layer = b + N a, theta_v, phi_v)"
        )
    return arr, facts


def read_textures(path) -> TextureSet:
    """The textures of the set ``path`` belongs to (any of <name>_t0, _t1, ... .ktx2 / .dds), each checked against
    the sidecar's axes (3D, N^2 x N x N x RGBA) and, for KTX2, its own record (the same bake: ``content_hash``);
    ReadError names the file that is wrong."""
    files, doc = _set_of(Path(path))
    container = SIDECAR_FORMATS[doc["format"]]
    record = doc["lutbake"]
    shape = texture_shape(record)
    data = []
    for f in files:
        arr, facts = decode_texture(f, container, shape)
        if container == "ktx2":
            own = bounded.loads_json(facts["key_value"].get("lutbake:metadata", "{}"))
            if own.get("content_hash") != record.get("content_hash"):
                raise ReadError(f"{f}: its record is not the sidecar's table (content_hash differs): another bake")
        data.append(arr)
    return TextureSet(np.stack(data), record, files, container)


def member_view(path: Path, doc: dict) -> tuple[np.ndarray, dict[str, str], str]:
    """(texels, record, note) of one file of a set, as ``lutbake inspect`` shows it: the texture alone, with its own
    record (texture_record); ``doc`` the set's sidecar."""
    files = doc["files"]
    k = files.index(path.name)
    container = SIDECAR_FORMATS[doc["format"]]
    arr, _ = decode_texture(path, container, texture_shape(doc["lutbake"]))
    note = (
        f"texture t{k} of {', '.join(files)} (one 3D texture; all of them: lutbake.io.ltc_aniso_textures.read_textures)"
    )
    return arr, texture_record(doc["lutbake"], k, files), note
