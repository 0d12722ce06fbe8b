"""Read an environment: a lat-long (equirectangular) EXR or Radiance HDR through OpenImageIO, or a cube map (a KTX 2.0,
KTX 1.1, DDS or lutbake EXR cube: lutbake.io.cube_read, its mip 0), refused cleanly when hostile (not a regular file,
too large for the memory budget, EXR headers past the caps, not 2:1, non-finite or negative radiance) before or right
after the pixels are read. ``read_environment`` tells them apart by the file's first bytes (lutbake.io.cubemap.
cube_kind), never by its name.

The image is taken as it is stored: row 0 the top (+Y, lutbake.environment.latlong's convention), its first three
channels as linear RGB radiance (one channel: grey). Its bytes' sha256 is what a content hash covers.

Radiance is >= 0. Captured HDRs hold slightly negative values where their filtering or lossy compression rang (every
CC0 map of Debian's blender-data does: at most -0.004, in 3 to 8 980 of 524 288 texels); those are set to 0 and
counted (``LatLong.negatives``, ``most_negative``), so the record says what was changed. A NaN or an infinity
is refused.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

from . import bounded
from .exr import _oiio

EXTENSIONS = (".exr", ".hdr")


def environment_problem(path) -> str | None:
    """Why ``path`` cannot be an environment lutbake reads (before its pixels are read), or None."""
    problem = bounded.regular_file_problem(path)
    if problem:
        return problem
    if not str(path).lower().endswith(EXTENSIONS):
        return f"is not an EXR or Radiance HDR file (extension {', '.join(EXTENSIONS)})"
    if str(path).lower().endswith(".exr"):
        return bounded.exr_header_problem(path)
    return None


@dataclass(frozen=True)
class LatLong:
    """A read environment: ``image`` (h, 2h, 3) float32 >= 0, the sha256 of the file's bytes, how many values
    were negative (set to 0) and the most negative one (0.0 when none)."""

    image: np.ndarray
    sha256: str
    negatives: int
    most_negative: float


def read_latlong(path) -> LatLong:
    """The lat-long environment in ``path`` (module docstring). ValueError says why not."""
    problem = environment_problem(path)
    if problem:
        raise ValueError(f"{path}: {problem}")
    data = bounded.read_bytes(path, what="an environment file")
    digest = hashlib.sha256(data).hexdigest()
    oiio = _oiio()
    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise ValueError(f"{path}: OpenImageIO cannot read it: {oiio.geterror()}")
    try:
        spec = inp.spec()
        w, h, nch = spec.width, spec.height, spec.nchannels
        if w != 2 * h:
            raise ValueError(f"{path}: {w} x {h} is not a lat-long image (width = 2 x height)")
        bounded.check_memory((h, w, max(nch, 3)), 4, f"{path}")
        pixels = inp.read_image(0, 0, 0, min(nch, 3), "float")
    finally:
        inp.close()
    if pixels is None:
        raise ValueError(f"{path}: OpenImageIO cannot read its pixels: {oiio.geterror()}")
    img = np.asarray(pixels, np.float32).reshape(h, w, -1)
    if img.shape[2] == 1:
        img = np.repeat(img, 3, axis=2)
    elif img.shape[2] == 2:
        raise ValueError(f"{path}: 2 channels; an environment has 1 (grey) or 3 or more (RGB first)")
    if not np.all(np.isfinite(img)):
        raise ValueError(f"{path}: holds a NaN or an infinite radiance")
    negative = img < 0
    most = float(img.min()) if negative.any() else 0.0
    return LatLong(np.maximum(img, 0), digest, int(negative.sum()), most)


@dataclass(frozen=True)
class CubeEnvironment:
    """A cube map read as an environment: ``faces`` its mip 0 (6, n, n, 3) float64 >= 0 in lutbake.environment.cube's
    face table, texel-constant; ``orientation`` the world its lookup vectors stand for (``d3d_left_handed`` where
    lutbake's record says so, else ``gl``); the sha256 of the file's bytes; the negative values set to 0 (count and
    the most negative); the container and pixel format; the mips the file holds (only mip 0 is the source)."""

    faces: np.ndarray
    sha256: str
    negatives: int
    most_negative: float
    container: str
    pixel_format: str
    orientation: str
    mips: int


def read_environment(path) -> LatLong | CubeEnvironment:
    """The environment in ``path``: a cube map (``CubeEnvironment``) where its first bytes say so, else a lat-long
    (read_latlong). ValueError says why not."""
    from .cubemap import cube_kind

    problem = bounded.regular_file_problem(path)
    if problem:
        raise ValueError(f"{path}: {problem}")
    if cube_kind(path) is None:
        return read_latlong(path)
    from .cube_read import read_cube
    from .integrity import sha256_file

    cube = read_cube(path)
    faces = cube.mips[0]
    if not np.all(np.isfinite(faces)):
        raise ValueError(f"{path}: its mip 0 holds a NaN or an infinite radiance")
    negative = faces < 0
    convention = str((cube.record or {}).get("face_convention", ""))
    return CubeEnvironment(
        np.maximum(faces, 0.0),
        sha256_file(path),
        int(negative.sum()),
        float(faces.min()) if negative.any() else 0.0,
        cube.container,
        cube.pixel_format,
        "d3d_left_handed" if convention.startswith("d3d_left_handed") else "gl",
        len(cube.mips),
    )
