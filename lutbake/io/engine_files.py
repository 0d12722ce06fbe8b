"""The values of the files lutbake writes in an engine's own layout, read back with their sidecar (``<file>.json``:
the table's axes, channels and conventions), so ``lutbake inspect`` and ``preview`` show them like any table.

| sidecar ``format`` | file | values read | table shape (as the EXR) |
| --- | --- | --- | --- |
| ``ltc_dds`` | <name>_1.dds + <name>_2.dds | both DDS textures (lutbake.io.dds) | (2, N, N, 4): ltc_1, ltc_2 |
| ``ltc_aniso_dds`` | <name>_t0.dds, _t1, ... | the file's 3D texture (lutbake.io.ltc_aniso_textures) | (N², N, N, 4) |
| ``js`` (kind ltc) | three.js module | ``LTC_MAT_1``, ``LTC_MAT_2`` | (2, N, N, 4) |
| ``c`` | Blender EEVEE .cc | ``ltc_mat_<lobe>``, ``ltc_mag_<lobe>``, ``ltc_disk_integral`` | (2, N, N, 4) |
| ``cs`` | Unity HDRP .cs | ``s_LtcMatrixData_BRDF_<LOBE>`` (FP16 bits) | (N, N, 4): HDRP's texel, its own channels |
| ``babylon_fuzz`` | one DDS | r, g, b through Babylon's mix() (lutbake.layouts.babylon) | (N, N, 3): A, B, R_i |
| ``babylon_ltc`` | Babylon's areaLightsLTC.bin | 8 FP16 per texel: ltc_1 RGBA, ltc_2 RGBA | (2, N, N, 4) |
| ``openpbr_h`` | OpenPBR header | ``OpenPBR_*_Array`` (UNORM16 codes / 65535) | the table's (metal: tiled over IOR) |
| ``js``, ``wgsl``, ``rs`` | code arrays | the one array, shape from its ``lutbake:shape`` line | the table's |

What the engine layout does not hold reads as the engine writes it: ltc_2.z (lutbake's fit error) is 0 in every LTC
layout (lutbake.io.ltc.engine_textures); the OpenPBR metal arrays hold one IOR slice (lutbake.io.openpbr.METAL_SLICE)
and are shown on every IOR slice, as the table does not depend on the IOR. ``read_engine`` returns the data and the
attributes to show (the sidecar's, with axes and channels replaced where the file's layout differs: cs), or raises
ValueError naming what is missing.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

from .bounded import check_texels, read_bytes, read_text
from .ltc_aniso_textures import SIDECAR_FORMATS, member_view
from .text_arrays import literal_values, parse_text_array, strip_comments

HDRP_CHANNELS = {
    "R": ("m00_over_m22", "M^-1_00 / M^-1_22 (HDRP texel .x; FP16, saturated to +-65504)"),
    "G": ("m20_over_m22", "M^-1_20 / M^-1_22 (HDRP texel .y)"),
    "B": ("m11_over_m22", "M^-1_11 / M^-1_22 (HDRP texel .z)"),
    "A": ("m02_over_m22", "M^-1_02 / M^-1_22 (HDRP texel .w)"),
}


def _dims(attrs: dict) -> dict[str, int]:
    """Axis counts by image dimension (z, y, x) from the sidecar's lutbake.axes."""
    return {a["dim"]: int(a["count"]) for a in json.loads(attrs["axes"])}


def array_body(text: str, name: str) -> str:
    """The body of the array literal declared as ``name`` (``name[..] = {...}``, ``name = new T([...])``,
    ``name = new T[..] {...}``, ``name: array<f32, N> = array<f32, N>(...)``), comments removed."""
    code = strip_comments(text)
    # bounded gaps (linear time on any text): a declaration's type and "new T[..]" are short
    m = re.search(
        rf"\b{re.escape(name)}\b[^=;]{{0,256}}=[^;{{\[(]{{0,256}}?(?:new\s{{1,16}}\w{{1,64}}\s{{0,16}}"
        rf"(?:\[[^\]]{{0,64}}\]\s{{0,16}})?)?[({{\[]",
        code,
    )
    if m is None:
        raise ValueError(f"no array {name!r}")
    end = code.find(";", m.end())
    return code[m.end() : end if end >= 0 else len(code)]


def _values(text: str, name: str, shape: tuple[int, ...]) -> np.ndarray:
    check_texels(shape, f"array {name!r} (the sidecar's axes)", channels=1, itemsize=8)  # parsed as float64
    n = int(np.prod(shape))
    arr, _ = literal_values(array_body(text, name), n)
    if arr.size != n:
        raise ValueError(f"array {name!r} holds {arr.size} values, the sidecar's axes need {n}")
    return arr.reshape(shape)


def _declared(text: str, prefix: str) -> str:
    m = re.search(rf"\b({re.escape(prefix)}\w{{0,128}})\s{{0,64}}[\[=]", strip_comments(text))
    if m is None:
        raise ValueError(f"no array named {prefix}*")
    return m.group(1)


def _ltc_dds(path: Path, doc: dict, dims: dict) -> np.ndarray:
    from . import dds

    files = doc.get("files") or [path.name, path.name.replace("_1.dds", "_2.dds")]
    slices = []
    for name in files:
        other = path.with_name(name)
        if not other.is_file():
            raise ValueError(f"its second texture {name} is not beside it")
        slices.append(dds.decode(read_bytes(other))[0].astype(np.float32))
    return np.stack(slices)


def _babylon_ltc(path: Path, doc: dict, dims: dict) -> np.ndarray:
    shape = (dims["y"], dims["x"], 2, 4)
    check_texels((2, *shape[:2]), "Babylon's areaLightsLTC.bin (the sidecar's axes)", channels=4, itemsize=2)
    raw = read_bytes(path)
    if len(raw) != 2 * int(np.prod(shape)):
        raise ValueError(f"{len(raw)} bytes, the sidecar's axes need {2 * int(np.prod(shape))} (8 FP16 per texel)")
    return np.frombuffer(raw, "<f2").reshape(shape).transpose(2, 0, 1, 3)


def _ltc_js(path: Path, doc: dict, dims: dict) -> np.ndarray:
    text = read_text(path)
    shape = (dims["y"], dims["x"], 4)
    return np.stack([_values(text, "LTC_MAT_1", shape), _values(text, "LTC_MAT_2", shape)])


def _ltc_c(path: Path, doc: dict, dims: dict) -> np.ndarray:
    text = read_text(path)
    ny, nx = dims["y"], dims["x"]
    mat = _values(text, _declared(text, "ltc_mat_"), (ny, nx, 4))
    mag = _values(text, _declared(text, "ltc_mag_"), (ny, nx, 2))
    disk = _values(text, "ltc_disk_integral", (ny, nx, 1))
    return np.stack([mat, np.concatenate([mag, np.zeros((ny, nx, 1)), disk], axis=-1)])


def _hdrp_cs(path: Path, doc: dict, dims: dict) -> np.ndarray:
    text = read_text(path)
    name = _declared(text, "s_LtcMatrixData_BRDF_")
    bits = _values(text, name, (dims["y"], dims["x"], 4))
    return bits.astype(np.uint16).view(np.float16).astype(np.float32)


def _openpbr_h(path: Path, doc: dict, dims: dict, attrs: dict) -> np.ndarray:
    from .openpbr import UNORM_ONE, camel

    text = read_text(path)
    names = json.loads(attrs["channel_names"])
    shape = tuple(dims[d] for d in ("z", "y", "x") if d in dims)
    channels = []
    for letter in "RGBA":
        if letter not in names:
            continue
        ch = names[letter]
        own = shape[1:] if ch.startswith("ideal_metal") else shape  # the metal array: one IOR slice
        codes = _values(text, f"OpenPBR_{camel(ch)}_Array", own)
        channels.append(np.broadcast_to(codes / UNORM_ONE, shape))
    return np.stack(channels, axis=-1)


def _code_array(path: Path, doc: dict, dims: dict) -> np.ndarray:
    text = read_text(path)
    m = re.search(r"lutbake:shape[ \t]{0,8}=[ \t]{0,8}\[([\d, \t]{1,64})\]", text)
    if m is None:
        raise ValueError("no 'lutbake:shape = [...]' line")
    shape = tuple(int(s) for s in m.group(1).split(",") if s.strip())
    return parse_text_array(text, shape)[0]


def _babylon_fuzz(path: Path, doc: dict, dims: dict) -> np.ndarray:
    from ..layouts.babylon import BABYLON_FUZZ
    from . import dds

    stored = dds.decode(read_bytes(path))[0].astype(np.float64)
    if stored.shape[:2] != (dims["y"], dims["x"]) or stored.shape[-1] < 3:
        raise ValueError(f"its texture is {stored.shape}, the sidecar's axes need ({dims['y']}, {dims['x']}, 4)")
    return BABYLON_FUZZ.decode(stored)


def _babylon_fuzz_attrs(attrs: dict, doc: dict) -> str:
    """Babylon's channels and shader line in place of ltc_code's (the texture axis dropped); the note: the decode
    and the values outside the mix() ranges the writer reported."""
    from ..layouts.babylon import BABYLON_FUZZ

    attrs["axes"] = json.dumps([a for a in json.loads(attrs["axes"]) if a["dim"] != "z"])
    attrs["channel_names"] = json.dumps({k: c.name for k, c in zip("RGB", BABYLON_FUZZ.channels)})
    attrs["channels"] = json.dumps({k: f"{c.name}: {c.meaning}" for k, c in zip("RGB", BABYLON_FUZZ.channels)})
    attrs["reconstruction"] = str(doc.get("shader", BABYLON_FUZZ.shader))
    outside = doc.get("outside_mix_ranges") or "none"
    if isinstance(outside, dict):
        outside = "; ".join(
            f"{name}: {v.get('texels')} texels, values [{v.get('min', 0):.4g}, {v.get('max', 0):.4g}] vs mix range "
            f"{v.get('range')}"
            for name, v in outside.items()
            if isinstance(v, dict)
        )
    return f"Babylon's r, g, b decoded by getFuzzBRDFLookup's mix() as (A, B, R_i); outside the mix ranges: {outside}"


READERS = {
    "babylon_fuzz": _babylon_fuzz,
    "babylon_ltc": _babylon_ltc,
    "ltc_dds": _ltc_dds,
    "c": _ltc_c,
    "cs": _hdrp_cs,
    "wgsl": _code_array,
    "rs": _code_array,
    "threejs_dfg": _code_array,
}


def read_engine(path: Path, doc: dict) -> tuple[np.ndarray, dict[str, str], str]:
    """(float32 data (y, x, C) or (z, y, x, C), attributes to show, a note) of an engine-layout file whose sidecar
    ``doc`` (format, lutbake attributes) names it; ValueError when the file does not hold what the sidecar says."""
    fmt, attrs = doc.get("format"), dict(doc["lutbake"])
    if fmt in SIDECAR_FORMATS:  # one of an ltc_aniso table's three 3D textures, shown alone with its own record
        data, attrs, note = member_view(path, doc)
        return np.ascontiguousarray(data, dtype=np.float32), attrs, note
    dims = _dims(attrs)
    if fmt == "openpbr_h":
        data = _openpbr_h(path, doc, dims, attrs)
        note = "UNORM16 codes / 65535; the metal array (one IOR slice) shown on every IOR slice"
    elif fmt == "js":
        data = (_ltc_js if attrs.get("kind") == "ltc" else _code_array)(path, doc, dims)
        note = "three.js LTC_MAT_1 / LTC_MAT_2" if attrs.get("kind") == "ltc" else "its array, shaped by lutbake:shape"
    elif fmt in READERS:
        data = READERS[fmt](path, doc, dims)
        note = {
            "ltc_dds": f"slices {' and '.join(doc.get('files') or [])}",
            "c": "ltc_mat, ltc_mag and ltc_disk_integral as ltc_2 = (magnitude, fresnel, 0, disk)",
            "cs": "HDRP's texel (M^-1_00, M^-1_20, M^-1_11, M^-1_02) / M^-1_22 of ltc_1; ltc_2 is not in this file",
            "babylon_ltc": "Babylon's LTC1 and LTC2 texels (FP16)",
        }.get(fmt, "its array, shaped by lutbake:shape")
    else:
        raise ValueError(f"lutbake cannot read values of the engine format {fmt!r}")
    if fmt == "cs":  # one slice in HDRP's own packing: the texture axis and ltc_code's channels do not apply
        attrs["axes"] = json.dumps([a for a in json.loads(attrs["axes"]) if a["dim"] != "z"])
        attrs["channel_names"] = json.dumps({k: v[0] for k, v in HDRP_CHANNELS.items()})
        attrs["channels"] = json.dumps({k: v[1] for k, v in HDRP_CHANNELS.items()})
    if fmt == "babylon_fuzz":
        note = _babylon_fuzz_attrs(attrs, doc)
    if attrs.get("kind") == "ltc" and fmt not in ("cs", "babylon_fuzz"):
        note += "; ltc_2.z (the fit error) is 0 in engine layouts (lutbake:fit_error_* hold its statistics)"
    return np.ascontiguousarray(data, dtype=np.float32), attrs, note
