"""The 16-bit linear PNG format (``png16``): UNORM codes, no sRGB tag, the conventions in a ``.json`` sidecar; written
here, and any PNG read (16- or 8-bit, code / 65535 or / 255), through OpenImageIO."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..runtime.warp_runtime import stderr_silenced
from ..table import Table
from ..table import pixels as checked_pixels
from . import bounded
from .atomic import atomic_write_hashed
from .conventions import write_conventions
from .sidecar import LoadedFile, as_table_array, with_sidecar

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
PNG_SLACK = 1.0e-3  # values this close outside [0, 1] are integration noise (e.g. E = 1 + 3e-5): clipped


def write_png16(table: Table, path, dtype: str = "float32") -> Path:
    """16-bit UNORM PNG, code = round(value * 65535). 2 channels are written as RGB with B = 0 (as the
    glTF Sample Viewer's lut_ggx.png); a 3D table is refused (PNG has no depth). Values within PNG_SLACK
    outside [0, 1] are clipped; anything further out is an error (the format cannot hold it)."""
    import OpenImageIO as oiio

    pixels = checked_pixels(table, "float32")
    path = Path(path)
    if pixels.ndim != 3:
        raise ValueError(f"table {table.name!r}: png16 holds 2D tables only; use dds, ktx2, exr or npy for 3D")
    lo, hi = float(pixels.min()), float(pixels.max())
    if lo < -PNG_SLACK or hi > 1.0 + PNG_SLACK:
        names = list(table.channels)
        bad = [
            names[c]
            for c in range(pixels.shape[-1])
            if pixels[..., c].min() < -PNG_SLACK or pixels[..., c].max() > 1.0 + PNG_SLACK
        ]
        raise ValueError(
            f"table {table.name!r}: png16 stores [0, 1] only; channel(s) {bad} span [{lo:.6g}, {hi:.6g}] "
            "(use exr, dds, ktx2, npy or h)"
        )
    if pixels.shape[-1] == 2:
        pixels = np.concatenate([pixels, np.zeros(pixels.shape[:-1] + (1,), np.float32)], axis=-1)
    codes = np.round(np.clip(pixels.astype(np.float64), 0.0, 1.0) * 65535.0).astype(np.uint16)
    h, w, nch = codes.shape

    def write(tmp):
        spec = oiio.ImageSpec(w, h, nch, "uint16")
        spec.attribute("oiio:ColorSpace", "linear")  # OIIO then writes gAMA = 1.0, never an sRGB chunk
        spec.attribute(
            "ImageDescription",
            f"lutbake {table.kind} table {table.name}: linear values, code / 65535; conventions in the .json sidecar",
        )
        out = oiio.ImageOutput.create(str(tmp))
        if out is None or not out.open(str(tmp), spec):
            raise OSError(f"cannot write {path}: {oiio.geterror()}")
        ok = out.write_image(codes)
        ok = out.close() and ok
        if not ok:
            raise OSError(f"cannot write {path}: {out.geterror()}")

    digest = atomic_write_hashed(path, write)
    write_conventions(
        table,
        path,
        "png16",
        {
            "encoding": "uint16 code / 65535, linear (no transfer function)",
            "channels_in_file": "RGB (B = 0)" if len(table.channels) == 2 else "as table",
        },
        digests={path.name: digest},
    )
    return path


def read_png(path: Path) -> LoadedFile:
    import OpenImageIO as oiio

    with stderr_silenced():
        inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(oiio.geterror() or "OpenImageIO cannot open it")
    try:
        spec = inp.spec()
        bounded.check_texels((spec.height, spec.width, spec.nchannels), "the PNG header", itemsize=spec.format.size())
        bits = 16 if str(spec.format) == "uint16" else 8
        with stderr_silenced():
            arr = inp.read_image("uint16" if bits == 16 else "uint8")
        if arr is None:
            raise ValueError(inp.geterror())
        codes = np.asarray(arr).reshape(spec.height, spec.width, spec.nchannels)
    finally:
        inp.close()
    data = unorm_float32(codes, (1 << bits) - 1)
    facts = {"bit_depth": bits, "channels": list(spec.channelnames), "encoding": f"code / {(1 << bits) - 1}"}
    return with_sidecar(LoadedFile(path, "png", data, {}, None, facts))


UNORM_ROWS = 256  # rows converted at a time from UNORM codes (float64 division, rounded to float32)


def unorm_float32(codes: np.ndarray, one: int) -> np.ndarray:
    """float32 code / one, as the float64 division rounds it, a block of rows at a time (no float64 image)."""
    out = np.empty(codes.shape, np.float32)
    for r in range(0, codes.shape[0], UNORM_ROWS):
        out[r : r + UNORM_ROWS] = codes[r : r + UNORM_ROWS] / float(one)
    return as_table_array(out)
