"""``lutbake inspect FILE``: what a table file holds, in words, for every format lutbake reads
(lutbake.io.readers). With lutbake metadata: kind, axes, channels, reconstruction, provenance and
per-channel statistics; without (a LUT an engine ships): format, size, channels and value ranges. A cube file lutbake
writes (an environment kind's KTX 2.0, DDS or EXR, lutbake.io.cubemap): its record (``describe_cube``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..textsafe import bounded as bounded_text
from . import bounded
from .readers import FORMAT_NAMES, NAME_CHARS, LoadedFile, ReadError, read, table_view

PROVENANCE = ("terms", "estimator", "samples", "seed", "error_estimate", "version", "warp_version")
SHOWN = {"kind", "table", "axes", "channels", "channel_names", "reconstruction", "config", "plugins", *PROVENANCE}
LONG_VALUE = 200  # characters of any other attribute shown
MAX_PLUGINS = 64  # plugin records listed


def _plugin_lines(text: str | None) -> list[str]:
    """The lutbake:plugins record (lutbake.registry.Record.provenance): the plugin records the table was baked with."""
    if not text:
        return []
    try:
        records = json.loads(text)
    except ValueError:
        return [f"  plugins: {bounded_text(text)}"]
    if not isinstance(records, list):
        return [f"  plugins: {bounded_text(text)}"]
    lines = ["  plugins:"]
    for r in records[:MAX_PLUGINS]:
        if isinstance(r, dict):
            r = {str(k): bounded_text(str(v), NAME_CHARS) for k, v in r.items()}
            lines.append(
                f"    {r.get('family', '?')} {r.get('name', '?')!r} from {r.get('origin', '?')}, "
                f"line {r.get('line', '?')} ({r.get('functions', '')}); source sha256 {r.get('sha256', '?')}"
            )
    return lines


def _fmt(x: float) -> str:
    return f"{x:.6g}"


CONTAINERS = {  # format -> what its container says, from LoadedFile.facts
    "exr": lambda f: f"{f.get('pixel_type')} pixels, {f.get('compression')} compression",
    "dds": lambda f: f"DXGI {f['dxgi_format']}, {f['dimension']}, {f['mips']} mip level(s)",
    "ktx2": lambda f: f"{f['vk_format']}, {f['dimension']} texture, orientation {f.get('KTXorientation', '?')}",
    "png": lambda f: f"{f['bit_depth']}-bit, linear values = {f['encoding']}",
    "npy": lambda f: f"dtype {f['dtype']}, shape {tuple(f['shape'])}",
    "h": lambda f: f"array {f['array']} of {f['element_type']}",
    "engine": lambda f: f"{f.get('format')}" + (f", values: {f['engine_values']}" if "engine_values" in f else ""),
    "report": lambda f: f"{len(f.get('tables') or [])} table(s)",
}


def _container(loaded: LoadedFile) -> str:
    f = loaded.facts
    if loaded.format in CONTAINERS:
        return CONTAINERS[loaded.format](f)
    if "data_file" in f:
        return f"describes {f['data_file']} ({f['data_format']})"
    return "no data file"


def _image_line(data: np.ndarray) -> str:
    if data.ndim == 4:
        z, h, w, nch = data.shape
        return f"{z} slices of {w} x {h}, {nch} channel(s)"
    h, w, nch = data.shape
    return f"{w} x {h}, {nch} channel(s)"


def _statistics(data: np.ndarray, names: list[str]) -> list[str]:
    lines = ["statistics:"]
    flat = data.reshape(-1, data.shape[-1])  # a view: no float64 copy of the table (it doubled inspect's memory)
    for i, name in enumerate(names):
        col = flat[:, i]
        mean = col.mean(dtype=np.float64)
        lines.append(f"  {name}: min {_fmt(float(col.min()))}  max {_fmt(float(col.max()))}  mean {_fmt(mean)}")
    return lines


def _report_lines(doc: dict) -> list[str]:
    counts = doc.get("counts") if isinstance(doc.get("counts"), dict) else {}
    lines = [
        f"  lutbake {doc.get('lutbake_version')}, exit status {doc.get('exit_status')}"
        + (f", interrupted by {doc['interrupted_by']}" if doc.get("interrupted_by") else ""),
        "  " + ", ".join(f"{v} {k}" for k, v in counts.items()),
        "tables:",
    ]
    for t in doc.get("tables") if isinstance(doc.get("tables"), list) else []:
        if isinstance(t, dict):
            secs = t.get("seconds")
            lines.append(
                f"  {t.get('status', '?'):<11} {t.get('path') or t.get('name')}"
                + (f"  {secs:.2f} s" if isinstance(secs, (int, float)) else "")
                + (f"  error estimate {t['error_estimate']}" if t.get("error_estimate") else "")
                + (f"  ({t['message']})" if t.get("message") else "")
            )
    return lines


CUBE_FORMATS = {
    "ktx2": "KTX 2.0 cube",
    "dds": "DDS cube",
    "exr": "OpenEXR cube (a part per mip)",
    "ktx1": "KTX 1.1 cube",
}
CUBE_SHOWN = (
    "ndf",
    "face_convention",
    "orientation",
    "weighting",
    "mip_curve",
    "roughness_definition",
    "mip0",
    "split_sum",
    "source_convention",
)
IBL_ORDER = ("engine", "ndf", "masking", "roughness", "mip_curve", "lobe")  # lutbake.layouts.base.IBL.record
CUBE_HIDDEN = {
    "kind",
    "table",
    "reconstruction",
    "ibl",
    "roughness",
    "alpha",
    "lobes",
    "error_estimate_per_mip",
    "config",
    "data_hash",
    "files_sha256",
}


def _text(value) -> str:
    """A record value as one bounded, escaped line (JSON for lists and objects)."""
    return bounded_text(value if isinstance(value, str) else json.dumps(value, sort_keys=True), LONG_VALUE)


def _mip_rows(record: dict, sizes: list[int]) -> list[str]:
    """One line per mip: its face size, roughness r, alpha, lobe and error estimate, as far as the record has them."""
    columns = {k: record.get(k) if isinstance(record.get(k), list) else [] for k in ("roughness", "alpha", "lobes")}
    errors = record.get("error_estimate_per_mip") if isinstance(record.get("error_estimate_per_mip"), list) else []

    def cell(values, m, fmt=_fmt):
        return fmt(values[m]) if m < len(values) and isinstance(values[m], (int, float)) else "-"

    lines = ["mips:", "  mip  size   roughness r  alpha        lobe        error estimate"]
    for m, n in enumerate(sizes):
        lobe = bounded_text(columns["lobes"][m], NAME_CHARS) if m < len(columns["lobes"]) else "-"
        lines.append(
            f"  {m:<4} {n:<6} {cell(columns['roughness'], m):<12} {cell(columns['alpha'], m):<12} {lobe:<11} "
            f"{cell(errors, m, lambda x: f'{x:.2e}')}"
        )
    return lines


def describe_cube(path) -> str:
    """The report ``lutbake inspect`` prints for a cube file: its container and pixel format, and, for one lutbake
    wrote, whether its bytes match the sha256 recorded with them, the record (kind, face convention, mip curve,
    roughness and alpha per mip, the weighting, the error estimate per mip, the source's sha256, the engine's ibl
    conventions), the reconstruction (the engine's shader line first) and the provenance; then each mip's pixel
    statistics (lutbake.io.cube_read), or why its pixels cannot be read."""
    from .cube_read import read_cube
    from .cubemap import read_cube_record

    path = Path(path)
    try:
        found = read_cube_record(path)
    except (ValueError, OSError, UnicodeDecodeError) as e:
        found, why = None, e
    try:
        cube, unread = read_cube(path), None
    except (ValueError, OSError) as e:
        cube, unread = None, e
    if found is None and cube is None:
        raise ReadError(f"{path}: not a readable cube file: {why}") from None
    lines = _record_lines(path, found) if found and found["record"] else _foreign_lines(path, cube)
    lines.append("pixels (linear RGB as a shader reads them; mean weighted by texel solid angle):")
    if cube is None:
        lines.append(f"  not read: {bounded_text(str(unread), LONG_VALUE)}")
    else:
        lines += _pixel_lines(cube)
    return "\n".join(lines) + "\n"


def _foreign_lines(path: Path, cube) -> list[str]:
    """The head of the report of a cube file without lutbake's record (an engine's)."""
    facts = ", ".join(f"{k} {_text(v)}" for k, v in sorted(cube.facts.items()) if k != "sh")
    lines = [
        str(path),
        f"  format: {CUBE_FORMATS.get(cube.container, cube.container)}, {cube.pixel_format}"
        f"{' (sRGB-decoded)' if cube.transfer == 'srgb' else ''}, {cube.size} x {cube.size} faces, "
        f"{len(cube.mips)} mip(s)",
        "  no lutbake record (a file lutbake did not write): roughness per mip, curve and orientation unknown "
        "(lutbake audit FILE --curve NAME fits them)",
        "  faces: +X -X +Y -Y +Z -Z, each row t = 0 first, column s = 0 first (the KTX / GL / D3D face table)",
    ]
    if facts:
        lines.append(f"  container: {facts}")
    if "sh" in cube.facts:
        lines.append(f"  sh (its 'sh' key, Filament's irradiance form): {_text(' '.join(cube.facts['sh'].split()))}")
    return lines


def _pixel_lines(cube) -> list[str]:
    """Per mip and channel: min, max and the solid-angle-weighted mean."""
    from ..environment.cube import texel_solid_angles

    lines = ["  mip  size   channel  min          max          mean"]
    for m, mip in enumerate(cube.mips):
        w = texel_solid_angles(mip.shape[1])[None, :, :, None]
        mean = (mip * w).sum(axis=(0, 1, 2)) / (6 * w.sum())
        for c, letter in enumerate("RGB"):
            head = f"  {m:<4} {mip.shape[1]:<6}" if c == 0 else " " * 13
            lines.append(
                f"{head} {letter:<8} {_fmt(mip[..., c].min()):<12} {_fmt(mip[..., c].max()):<12} {_fmt(mean[c])}"
            )
    return lines


def _record_lines(path: Path, found: dict) -> list[str]:
    """The head of the report of a cube file lutbake wrote: container, integrity, record, mips, reconstruction,
    provenance."""
    from .integrity import verified_attributes

    record = found["record"]
    size, mips = found["size"], found["mips"]
    sizes = [max(1, size >> m) for m in range(mips)]
    intact = verified_attributes(path) is not None
    lines = [
        str(path),
        f"  format: {CUBE_FORMATS[found['format']]}, {found['pixel_format']}, {size} x {size} faces, {mips} mip(s)",
        f"  metadata: {found['metadata']}",
        "  integrity: "
        + (
            "its bytes (and its other files) match the sha256 recorded with them"
            if intact
            else "its bytes do not match the sha256 recorded with them (changed or half-written: a bake redoes it)"
        ),
        f"  kind: {_text(record.get('kind', '?'))}   table: {_text(record.get('table', path.stem))}",
        "  faces: +X -X +Y -Y +Z -Z, each row t = 0 first, column s = 0 first (A = 1 where stored)",
    ]
    lines += [f"  {key}: {_text(record[key])}" for key in CUBE_SHOWN if key in record]
    zeroed = str(record.get("source_negative_values_zeroed", "0"))
    lines.append(
        f"  source: {_text(record.get('source', '?'))}, sha256 {_text(record.get('source_sha256', '?'))}"
        + (f", {_text(zeroed)} negative values set to 0" if zeroed != "0" else "")
    )
    ibl = record.get("ibl")
    if isinstance(ibl, str):
        try:
            ibl = json.loads(ibl)
        except ValueError:
            pass
    if isinstance(ibl, dict):
        shown = [(k, ibl[k]) for k in IBL_ORDER if k in ibl]
        lines.append(
            "  ibl conventions (every file of the engine's run): " + ", ".join(f"{k} {_text(v)}" for k, v in shown)
        )
        if "source" in ibl:
            lines.append(f"    from {_text(ibl['source'])}")
    if "sh" in record:
        where = record.get("sh_file") or f"the file's key {str(record.get('sh_key', '?')).split(':')[0]}"
        lines.append(f"  sh ({_text(record.get('sh_form', '?'))}, also in {_text(where)}): " + _text(record["sh"]))
    lines += _mip_rows(record, sizes)
    lines.append("reconstruction:")
    lines += [f"  {line}" for line in bounded_text(record.get("reconstruction", "(none recorded)")).splitlines()]
    lines.append("provenance:")
    shown = (
        set(CUBE_SHOWN)
        | CUBE_HIDDEN
        | {"source", "source_sha256", "source_negative_values_zeroed", "sh", "sh_form", "sh_file", "sh_key"}
    )
    if isinstance(record.get("config"), str):
        lines.append(f"  config: {len(record['config'].splitlines())} line(s) of TOML")
    for key in sorted(set(record) - shown):
        value = _text(record[key])
        lines.append(f"  {bounded_text(key, NAME_CHARS)}: {value}")
    return lines


SH_KEYS = ("basis", "form", "coefficients")  # lutbake.kinds.environment's <name>_sh.json


def _sh_document(path: Path) -> dict | None:
    """The L2 SH document an irradiance table writes (``<name>_sh.json``), or None for any other file."""
    if path.suffix != ".json" or not path.is_file():
        return None
    try:
        doc = bounded.load_json(path)
    except (ValueError, OSError, UnicodeDecodeError):
        return None
    return doc if isinstance(doc, dict) and all(k in doc for k in SH_KEYS) and "lutbake" not in doc else None


def describe_sh(path: Path, doc: dict) -> str:
    """What ``lutbake inspect`` prints for an irradiance table's SH document."""
    lines = [str(path), "  format: L2 spherical harmonics (JSON) of an environment_irradiance table"]
    lines += [f"  {k}: {_text(doc[k])}" for k in ("form", "form_meaning", "basis", "integration", "source") if k in doc]
    lines.append(f"  source_sha256: {_text(doc.get('source_sha256', '?'))}")
    coefficients = doc["coefficients"] if isinstance(doc["coefficients"], list) else []
    lines.append(f"coefficients ({len(coefficients)} x RGB):")
    lines += [f"  {k}: {_text(c)}" for k, c in enumerate(coefficients[:MAX_SH])]
    return "\n".join(lines) + "\n"


MAX_SH = 64  # coefficients listed (L2: 9)


def describe(path) -> str:
    """The report ``lutbake inspect FILE`` prints (raises readers.ReadError, naming the file once); a cube file lutbake
    wrote, or its sidecar: describe_cube."""
    from .cubemap import cube_kind

    path = Path(path)
    for candidate in (path, path.with_name(path.name.removesuffix(".json"))):
        if cube_kind(candidate) is not None:
            return describe_cube(candidate)
    sh = _sh_document(path)
    if sh is not None:
        return describe_sh(path, sh)
    loaded = read(path)
    lines = [str(path), f"  format: {FORMAT_NAMES[loaded.format]}, {_container(loaded)}"]
    if loaded.format == "report":
        return "\n".join(lines + _report_lines(loaded.facts)) + "\n"
    if loaded.data is None:
        lines.append(f"  metadata only: {loaded.notes[0]}")
        lines += [f"  {k}: {v if len(v) <= LONG_VALUE else v[:LONG_VALUE] + ' ...'}" for k, v in loaded.attrs.items()]
        return "\n".join(lines) + "\n"
    view = table_view(loaded)
    if view.kind is None:
        lines.append(f"  image: {_image_line(view.data)}")
        lines.append(
            "  no lutbake metadata (" + "; ".join(loaded.notes or ["none in the file"]) + "): "
            "axes, channel meanings and provenance unknown"
        )
        letters = loaded.facts.get("channels") or list("RGBA"[: view.data.shape[-1]])
        return "\n".join(lines + _statistics(view.data, [str(c) for c in letters])) + "\n"

    attrs = loaded.attrs
    lines.append(f"  metadata: {loaded.meta_source}")
    lines.append(f"  kind: {view.kind}   table: {view.name}")
    lines.append(
        f"  image: {_image_line(view.data)}"
        + (
            f" (+{loaded.data.shape[-1] - view.data.shape[-1]} padding channel(s) in the file)"
            if loaded.data.shape[-1] > view.data.shape[-1]
            else ""
        )
    )
    lines.append("  row 0 = y index 0, column 0 = x index 0 (no flip)")
    lines.append("axes:")
    raw_axes = json.loads(attrs["axes"])
    for ax, d in zip(view.axes, raw_axes):
        values = ax.values()
        lines.append(
            f"  {ax.name}: {ax.dim} ({d.get('image', ax.dim)}), count {ax.count}, range [{_fmt(ax.lo)}, {_fmt(ax.hi)}]"
        )
        lines.append(
            f"    texel {ax.texel} ({d.get('texel_formula', '')}), mapping {ax.mapping} "
            f"({d.get('mapping_formula', '')})"
        )
        lines.append(f"    index 0 = {_fmt(values[0])}, index {ax.count - 1} = {_fmt(values[-1])}")
        lines.append(f"    order {ax.order}; sample at {d.get('uv_formula') or 'u = ' + ax.uv_formula()}")
        alpha = ax.alpha()
        if alpha is not None:
            lines.append(f"    alpha {_fmt(alpha.min())} .. {_fmt(alpha.max())} ({d.get('alpha_formula', '')})")
    parts = loaded.facts.get("parts") or []
    if len(parts) > 1:
        lines.append("  parts: " + ", ".join(f"{name}={value}" for name, value in parts))
    lines.append("channels:")
    for letter, name, meaning in zip("RGBA", view.channel_names, view.meanings):
        lines.append(f"  {letter} = {meaning or name}")
    lines.append("reconstruction:")
    lines.extend(f"  {line}" for line in (view.reconstruction or "(none recorded)").splitlines())
    lines.append("provenance:")
    lines += [f"  {key}: {attrs[key]}" for key in PROVENANCE if key in attrs]
    if "config" in attrs:
        lines.append(f"  config: {len(attrs['config'].splitlines())} line(s) of TOML")
    lines += _plugin_lines(attrs.get("plugins"))
    for key in sorted(set(attrs) - SHOWN):
        value = attrs[key]
        lines.append(f"  {key}: {value if len(value) <= LONG_VALUE else value[:LONG_VALUE] + ' ...'}")
    if view.kind == "ltc" and view.data.ndim == 4:  # the two textures' channels mean different things
        lines.append("statistics:")
        for k, name in enumerate(("ltc_1 (slice 0)", "ltc_2 (slice 1)")[: len(view.data)]):
            lines += [f"  {name}:"] + ["  " + x for x in _statistics(view.data[k], view.channel_names)[1:]]
        return "\n".join(lines) + "\n"
    return "\n".join(lines + _statistics(view.data, view.channel_names)) + "\n"
