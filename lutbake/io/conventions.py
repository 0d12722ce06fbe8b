"""The conventions every non-EXR output carries: the ``<file>.json`` sidecar (``write_conventions``, the last step
of each writer) and the comment block of the source-code outputs (``convention_lines``, C header, JS, WGSL, Rust,
the LTC engine files). Imported by every writer of lutbake.io; imports none of them."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..table import Table, metadata
from .atomic import atomic_write_bytes_hashed
from .integrity import legacy_sidecar, write_sidecar


def write_conventions(
    table: Table, path: Path, fmt: str, extra: dict | None = None, *, digests: dict[str, str]
) -> None:
    """The last step of every non-EXR write: ``<file>.json`` naming the sha256 of the bytes written (``digests``:
    file name -> sha256, lutbake.io.integrity.sidecar_document); a pre-issue-11 ``<stem>.json`` that described this
    file is removed (it would contradict the new one)."""
    write_sidecar(path, fmt, metadata(table), digests, extra)
    old = legacy_sidecar(path)
    if old is not None:
        old.unlink(missing_ok=True)


def write_with_sidecar(table: Table, path, data: bytes, fmt: str, extra: dict | None = None) -> Path:
    """Write ``data`` to ``path`` atomically, then its sidecar naming the sha256 of ``data``: a one-file output."""
    path = Path(path)
    write_conventions(table, path, fmt, extra, digests={path.name: atomic_write_bytes_hashed(path, data)})
    return path


def write_set_with_sidecar(table: Table, path, files: dict[str, bytes], fmt: str, extra: dict | None = None) -> Path:
    """An output of several files (lutbake.io.file_sets): ``files`` (name -> bytes, beside ``path``, ``path.name``
    among them) each written atomically, ``path`` last, then the sidecar of ``path`` listing every file (``files``,
    in the order given) with the sha256 of each: one unit, as a cube and its SH (lutbake.io.cubemap.write_cube)."""
    path = Path(path)
    if path.name not in files:
        raise ValueError(f"table {table.name!r}: the file set {sorted(files)} lacks its first file {path.name}")
    digests = {n: atomic_write_bytes_hashed(path.with_name(n), blob) for n, blob in files.items() if n != path.name}
    digests[path.name] = atomic_write_bytes_hashed(path, files[path.name])
    write_conventions(table, path, fmt, {"files": list(files), **(extra or {})}, digests=digests)
    return path


def c_ident(name: str) -> str:
    """``name`` as a C/JS/Rust identifier: other characters become _, a leading digit gets a _ before it."""
    s = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return s if not s[0].isdigit() else "_" + s


def convention_lines(table: Table, pixels: np.ndarray, dtype: str, ident: str, values: str | None = None) -> list[str]:
    """The conventions comment block every source-code output carries (C header, JS/TS, WGSL, Rust), one
    line per item, without comment markers: array layout, axes (texel, mapping, order, uv), channels,
    reconstruction, provenance and the config."""
    dims = pixels.shape
    lines = [
        "",
        f"kind: {table.kind}",
        f"array: {ident}["
        + " * ".join(str(n) for n in dims)
        + "], flat: element "
        + ("((z * H + y) * W + x) * C + c" if pixels.ndim == 4 else "(y * W + x) * C + c")
        + " (rows y, columns x, channels c)",
        f"lutbake:shape = [{', '.join(str(n) for n in dims)}]",
        "row 0 = table row 0 (y index 0); column 0 = x index 0. Upload row 0 first (OpenGL: t = 0 at row 0).",
        "values: "
        + (
            values
            or (
                "IEEE 754 binary16 bit patterns (uint16_t); upload as GL_HALF_FLOAT / DXGI *_FLOAT"
                if dtype == "half"
                else "float32"
            )
        ),
        "",
        "axes:",
    ]
    for ax in table.axes:
        d = ax.describe()
        lines += [
            f"  {d['name']}: {d['dim']} ({d['image']}), count {d['count']}, texel {d['texel']} "
            f"({d['texel_formula']}), order {d['order']}",
            f"    mapping {d['mapping']}: {d['mapping_formula']}"
            + (f", clamped to {d['clamp']}" if d.get("clamp") else ""),
            f"    index 0 = {d['values'][0]:.9g}, index {d['count'] - 1} = {d['values'][-1]:.9g}",
            f"    sample at {d['uv_formula']}",
        ]
    lines += ["channels:"] + [f"  {c} = {n}: {m}" for c, (n, m) in zip("RGBA", table.channels.items())]
    lines += ["reconstruction:", *(f"  {line}" for line in table.reconstruction.splitlines()), "", "provenance:"]
    for k in ("terms", "estimator", "samples", "seed", "version", "warp_version"):
        if k in table.attributes:
            lines.append(f"  {k}: {table.attributes[k]}")
    lines.append("config:")
    lines += [f"  {line}" for line in table.attributes.get("config", "").splitlines()]
    return lines
