"""A cube map as the environment: the prefiltered cube of a source that is texel-constant on the cube's faces (each
texel the mean radiance over its footprint, as lutbake.environment.latlong takes a lat-long's texels), baked without
the lat-long pyramid:

- **Mips with a lobe** (GGX, irradiance): by spherical harmonics (lutbake.environment.harmonic), the a_lm of the cube
  exact to Gauss–Legendre precision (``harmonic.analyse_cube``: every texel's integral of Y*_lm against the face
  plane's area element), the kernel's g_l and the synthesis as for a lat-long source. A lobe narrower than the
  harmonics reach (``harmonic.plan_lmax``) is refused: the pyramid quadrature that bakes such mips from a lat-long has
  no cube form here.
- **Mip 0** (r = 0, the footprint): the exact area average of the source over each output texel's footprint, which
  the cube's own grid gives in closed form when one size divides the other (``box_average``): an output texel of a
  source k times finer is the solid-angle-weighted mean of its k x k source texels (the grids nest: the texel edges
  u = -1 + 2 i / n are a subset); one k times coarser lies inside one source texel and holds its value. Any other
  ratio is refused (a footprint would cut source texels: no closed form kept here).
- **Orientation**: the source's lookup vector d stands for the world direction d * source_flip, the output's for
  d * flip (lutbake.environment.cube.ORIENTATIONS); both are sign flips, which map texel grids onto texel grids
  (``remap``), so nothing is resampled.
- **L2 SH** of the source (``project_cube``): Σ L_texel ∫_texel Y_k dω by a Gauss–Legendre product rule per texel in
  (u, v) with the area element (1 + u^2 + v^2)^(-3/2).

**Error estimate, per mip**: a harmonic mip's truncation, max |P(lmax) - P(3 lmax / 4)| / P over up to
prefilter.PROBES strided texels (the a_lm and g_l are exact to ~1e-12, so the truncation is what is left); a box
average is exact (0).
"""

from __future__ import annotations

import os

import numpy as np

from . import cube, harmonic, sh
from .prefilter import PROBES, Baked, cube_texels

SH_ORDER = 6  # Gauss–Legendre points per axis and texel for the L2 SH (degree-2 polynomials over the face plane)
TRUNCATION_FRACTION = 0.75  # the error estimate's second synthesis: lmax x this


def remap(faces: np.ndarray, flip) -> np.ndarray:
    """The cube whose lookup vector d holds ``faces``' value at d * flip (flip: +-1 per axis): exact, texel for
    texel (a sign flip maps every texel centre onto a texel centre)."""
    n = faces.shape[1]
    f, s, t = cube.face_st(cube.texel_centres(n) * np.asarray(flip, np.float64))
    i = np.minimum((s * n).astype(int), n - 1)
    j = np.minimum((t * n).astype(int), n - 1)
    return faces[f, j, i]


def box_average(faces: np.ndarray, size: int) -> np.ndarray:
    """(6, size, size, 3): each texel the exact area average of the texel-constant ``faces`` (6, n, n, 3) over its
    footprint, where size divides n or n divides size (module docstring); ValueError otherwise."""
    n = faces.shape[1]
    if n == size:
        return faces.copy()
    if n % size == 0:
        k = n // size
        w = cube.texel_solid_angles(n)[None, :, :, None]
        blocks = (faces * w).reshape(6, size, k, size, k, 3).sum(axis=(2, 4))
        return blocks / w.reshape(1, size, k, size, k, 1).sum(axis=(2, 4))
    if size % n == 0:
        k = size // n
        return np.repeat(np.repeat(faces, k, axis=1), k, axis=2)
    raise ValueError(
        f"mip 0 of a {size}^2 cube from a {n}^2 cube source: its footprint average is exact here only when one size "
        "divides the other (choose a size such as "
        f"{', '.join(str(x) for x in sorted({max(1, n >> 2), max(1, n >> 1), n, 2 * n}))})"
    )


def project_cube(faces: np.ndarray, order: int = SH_ORDER) -> np.ndarray:
    """(9, 3) radiance coefficients L_k = Σ L_texel ∫_texel Y_k dω (lutbake.environment.sh's basis, on the lookup
    vectors) of the texel-constant cube ``faces``."""
    n = faces.shape[1]
    x, wx = np.polynomial.legendre.leggauss(order)
    sub = (cube.texel_edges(n)[:-1, None] + (x[None, :] + 1.0) / n).ravel()
    wsub = np.tile(wx / n, n)
    v, u = np.meshgrid(sub, sub, indexing="ij")
    area = np.outer(wsub, wsub) * (1.0 + u * u + v * v) ** -1.5
    out = np.zeros((9, 3))
    for f in range(6):
        d = cube.face_directions(np.full(u.shape, f), u, v)
        y = sh.basis(d / np.linalg.norm(d, axis=-1, keepdims=True)) * area[..., None]  # (n G, n G, 9)
        per_texel = y.reshape(n, order, n, order, 9).sum(axis=(1, 3))
        out += np.einsum("jik,jic->kc", per_texel, faces[f])
    return out


def bake_from_cube(
    faces: np.ndarray,
    size: int,
    roughness: list[float],
    lobe: str = "ggx_nl",
    source_flip=(1.0, 1.0, 1.0),
    flip=(1.0, 1.0, 1.0),
    workers: int | None = None,
    estimate: bool = True,
) -> Baked:
    """The prefiltered cube of ``size``^2 faces, one mip per entry of ``roughness`` (as prefilter.bake_cube: r = 0 the
    footprint average, r > 0 lobe ``lobe`` at alpha = r^2, ``lobe = "cosine"`` the irradiance cube) of the
    texel-constant cube source ``faces`` (6, n, n, 3) (module docstring). ValueError for a mip it cannot bake."""
    faces = np.asarray(faces, np.float64)
    lobes = ["cosine" if lobe == "cosine" else "footprint" if r == 0 else lobe for r in roughness]
    alphas = [float(r) ** 2 for r in roughness]
    texels = cube_texels(size, lobes, alphas)
    lmax, by_harmonics = harmonic.plan_lmax(lobes, alphas)
    narrow = [m for m, (lb, ok) in enumerate(zip(lobes, by_harmonics)) if lb != "footprint" and not ok]
    if narrow:
        raise ValueError(
            f"mips {narrow} (alpha {[alphas[m] for m in narrow]}) are narrower than the spherical harmonics reach "
            f"(lmax <= {harmonic.LMAX_CAP}); from a cube source only those are baked: use fewer mips or another curve"
        )
    threads = workers or os.cpu_count() or 1
    world = np.asarray(flip, np.float64)
    mips, errors, methods = [], [], []
    h = harmonic.analyse_cube(faces, lmax, flip=source_flip, threads=threads) if any(by_harmonics) else None
    for m, n in enumerate(texels.sizes):
        dirs = texels.dirs[texels.offsets[m] : texels.offsets[m + 1]] * world
        if lobes[m] == "footprint":
            mips.append(box_average(remap(faces, world * np.asarray(source_flip, np.float64)), n))
            errors.append(0.0)
            methods.append("box average")
            continue
        g = harmonic.kernel_coefficients(lobes[m], alphas[m], lmax)
        values = harmonic.synthesise(h, g, dirs, threads)
        mips.append(values.reshape(6, n, n, 3))
        methods.append("harmonic")
        if estimate:
            probes = np.arange(0, len(dirs), max(1, len(dirs) // PROBES))
            coarse = harmonic.synthesise(h, g[: int(lmax * TRUNCATION_FRACTION) + 1], dirs[probes], threads)
            floor = max(float(np.abs(values[probes]).max()) * 1e-6, 1e-300)
            errors.append(float(np.max(np.abs(values[probes] - coarse) / np.maximum(np.abs(values[probes]), floor))))
    return Baked(
        mips,
        list(roughness),
        alphas,
        lobes,
        errors if estimate else [],
        [0.0] * len(mips),
        methods,
        lmax if any(by_harmonics) else 0,
    )


ERROR_METHOD = (
    "harmonic mips: max relative |P(lmax) - P(3 lmax / 4)| over <= 96 strided probe texels (the truncation; a_lm and "
    "g_l exact to ~1e-12); box-averaged mips: exact (0) (lutbake.environment.cube_source)"
)
