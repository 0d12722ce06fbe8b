"""Prefiltered cube maps: each texel of each mip is the exact integral of the texel-constant source against a lobe
(lutbake.environment.quadrature), baked through lutbake.runtime's executor (tiles of texels, pure functions of the
inputs and the tile: bit-identical for any worker count).

**Specular** (split sum, n = v = r): mip m > 0 holds P(r) = ∫ L w dω / ∫ w dω with alpha = r_m^2, r_m the
perceptual roughness the engine's curve (lutbake.environment.curves) puts at mip m, w = D_ggx(h) (n.l) / 4
(``ggx_nl``, Karis 2013's weighting, the default) or D_ggx(h) / 4 (``ggx``). Mip 0 (r = 0) holds the exact area
average of the source over each texel's footprint (the integral of the texel-constant source over the spherical
quadrilateral, / its solid angle): what a box-filtered resampling gives, and what a texture's texel should hold. (The
pointwise alpha -> 0 limit of P would be the source's value at the centre direction; the area average is chosen
because a texel stands for its footprint.)
**Irradiance cube**: P(r) = ∫ L (n.l)+ dω / ∫ (n.l)+ dω = E(r) / pi (the Lambertian-prefiltered radiance:
diffuse = albedo x texture(r)).

**Error estimate, per mip**: probe texels (every mip's texels, strided, at most PROBES each) baked again at
``Quality.finer()`` (tau / 8, K x 2, one Gauss-Legendre order more, one sub-texel level more); the record is the
max over probes and channels of |P - P_finer| / max(P_finer, max over the mip's probes of P_finer x 1e-6).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from ..runtime.executor import execute_tiles
from ..runtime.plan import TexelPlan
from . import cube
from .latlong import Pyramid
from .lobes import alpha_of, lobe_width
from .quadrature import OUT_WIDTH, integrate, texel_kernel

PROBES = 96  # probe texels per mip of the error estimate
COARSE_TAU = 3.0  # the first pass, whose value each texel's contrast budget is measured against
TILE_TEXELS = 64  # texels per tile: a texel integrates thousands of leaves, so tiles stay small enough to share
FOOTPRINT_TILE_TEXELS = 4096  # a footprint texel integrates tens of leaves: larger tiles, less Python per texel
MAX_SUB_LEVELS = 12  # sub-texel levels below the source (a cell 1/4096 of a source texel)


@dataclass(frozen=True)
class Quality:
    """The quadrature's controls (lutbake.environment.quadrature): ``tau`` the radiance-fixing tolerance (relative),
    ``k_geo`` the cell size K per distance, ``order`` the Gauss-Legendre order per leaf and axis, ``extra_levels``
    sub-texel levels beyond those the narrowest lobe needs."""

    tau: float = 0.3
    k_geo: float = 4.0
    order: int = 3
    extra_levels: int = 0

    def finer(self) -> Quality:
        return Quality(self.tau / 8, self.k_geo * 2, self.order + 1, self.extra_levels + 1)


@dataclass(frozen=True)
class CubeTexels:
    """Every texel of a cube's mips, flattened mip by mip, face, row (t), column (s): per texel its direction,
    its clip planes (the horizon r, or a footprint's four), alpha and lobe width."""

    sizes: tuple[int, ...]
    lobes: tuple[str, ...]  # per mip
    alphas: tuple[float, ...]
    dirs: np.ndarray
    offsets: tuple[int, ...]

    @property
    def n(self) -> int:
        return len(self.dirs)

    def select(self, mips: list[int]) -> CubeTexels:
        """The texels of mips ``mips`` only (in that order)."""
        parts = [self.dirs[self.offsets[m] : self.offsets[m + 1]] for m in mips]
        counts = [len(p) for p in parts]
        return CubeTexels(
            tuple(self.sizes[m] for m in mips),
            tuple(self.lobes[m] for m in mips),
            tuple(self.alphas[m] for m in mips),
            np.concatenate(parts) if parts else np.zeros((0, 3)),
            tuple(np.concatenate([[0], np.cumsum(counts)]).astype(int).tolist()),
        )

    def mip_of(self, start: int, stop: int) -> list[tuple[int, int, int]]:
        """(mip, first, last + 1) of the mips that texels [start, stop) cross."""
        out = []
        for m, o in enumerate(self.offsets[:-1]):
            s, e = max(start, o), min(stop, self.offsets[m + 1])
            if s < e:
                out.append((m, s, e))
        return out


def cube_texels(size: int, lobes: list[str], alphas: list[float]) -> CubeTexels:
    """The texels of a cube of ``size``^2 faces with len(lobes) mips (mip m: max(1, size >> m) texels a side)."""
    sizes = tuple(max(1, size >> m) for m in range(len(lobes)))
    dirs = np.concatenate([cube.texel_centres(n).reshape(-1, 3) for n in sizes])
    offsets = tuple(np.concatenate([[0], np.cumsum([6 * n * n for n in sizes])]).tolist())
    return CubeTexels(sizes, tuple(lobes), tuple(alphas), dirs, offsets)


def sub_levels(pyr: Pyramid, lam: float, quality: Quality) -> int:
    """Sub-texel levels V so that a leaf at the floor is at most lam / K: 2^V >= K pi / (H lam)."""
    if lam <= 0:
        return quality.extra_levels
    need = math.ceil(math.log2(max(1.0, quality.k_geo * math.pi / (int(pyr.heights[0]) * lam))))
    return min(MAX_SUB_LEVELS, need + quality.extra_levels)


def mip_values(pyr: Pyramid, texels: CubeTexels, m: int, idx: np.ndarray, quality: Quality, device: str) -> np.ndarray:
    """(len(idx), OUT_WIDTH) of texels ``idx`` (flat indices, all in mip ``m``)."""
    lobe, alpha, n = texels.lobes[m], texels.alphas[m], texels.sizes[m]
    dirs = texels.dirs[idx]
    if lobe == "footprint":
        local = idx - texels.offsets[m]
        planes = cube.texel_planes(n).reshape(-1, 4, 3)[local]
        cross = 2.0 / n  # about a texel's angular size at the face centre
    else:
        planes = dirs[:, None, :]
        cross = math.pi / 4
    lam = lobe_width(lobe, alpha)
    common = {
        "k_geo": quality.k_geo,
        "cross": cross,
        "floor": -sub_levels(pyr, cross if lobe == "footprint" else lam, quality),
        "order": quality.order,
        "device": device,
    }
    inputs = (pyr, lobe, dirs, planes, np.full(len(idx), alpha), np.full(len(idx), lam))
    if lobe == "footprint":  # its cells fix by geometry alone (slope 0; a cut cell takes the source): no first pass
        return integrate(*inputs, tau=quality.tau, **common)
    coarse = integrate(*inputs, tau=COARSE_TAU, **common)
    reference = coarse[:, :3] / coarse[:, 3:4]
    return integrate(*inputs, reference, tau=quality.tau, **common)


def cube_plan(pyr: Pyramid, texels: CubeTexels, quality: Quality = Quality()) -> TexelPlan:
    """The TexelPlan of every texel of ``texels``: channels P (r, g, b), aux columns ∫ w dω and the leaf count."""

    def run_tile(start: int, stop: int, device: str) -> np.ndarray:
        parts = [mip_values(pyr, texels, m, np.arange(s, e), quality, device) for m, s, e in texels.mip_of(start, stop)]
        out = np.concatenate(parts)
        return np.concatenate([out[:, :3] / out[:, 3:4], out[:, 3:]], axis=1)

    def prepare(device: str) -> None:
        from ..runtime.warp_runtime import load_module

        for lobe in sorted(set(texels.lobes)):
            kernel = texel_kernel(lobe, 4 if lobe == "footprint" else 1, quality.order)
            load_module(kernel.module, device)

    return TexelPlan(
        axes=[],
        channels={"R": "prefiltered radiance", "G": "prefiltered radiance", "B": "prefiltered radiance"},
        reconstruction="",
        n_texels=texels.n,
        n_channels=3,
        run_tile=run_tile,
        prepare=prepare,
        samples=0,
        estimator="exact quadrature over the source's texels (lutbake.environment.quadrature)",
        terms={"lobes": ",".join(texels.lobes)},
        cost=float(texels.n),
        aux_channels=OUT_WIDTH - 3,
        tile_texels=FOOTPRINT_TILE_TEXELS if set(texels.lobes) == {"footprint"} else TILE_TEXELS,
    )


def probe_indices(texels: CubeTexels, m: int) -> np.ndarray:
    """Up to PROBES strided texels of mip m (flat indices)."""
    s, e = texels.offsets[m], texels.offsets[m + 1]
    return np.arange(s, e, max(1, (e - s) // PROBES))


def error_estimates(pyr: Pyramid, texels: CubeTexels, values: np.ndarray, quality: Quality, device: str = "cpu"):
    """Per mip: the max relative difference of the probe texels to a finer bake (module docstring)."""
    out = []
    finer = quality.finer()
    for m in range(len(texels.sizes)):
        idx = probe_indices(texels, m)
        ref = mip_values(pyr, texels, m, idx, finer, device)
        ref = ref[:, :3] / ref[:, 3:4]
        floor = max(float(np.max(ref)) * 1e-6, 1e-300)
        out.append(float(np.max(np.abs(values[idx, :3] - ref) / np.maximum(ref, floor))))
    return out


@dataclass(frozen=True)
class Baked:
    """A baked cube: ``mips[m]`` (6, n, n, 3) float64 (face, row t, column s, rgb), the roughness and alpha per mip,
    the method of each mip (``quadrature`` or ``harmonic``), the estimated relative error per mip, the leaves the
    quadrature integrated per texel (mean, per mip; 0 for a harmonic mip) and the harmonics' lmax (0: none)."""

    mips: list[np.ndarray]
    roughness: list[float]
    alphas: list[float]
    lobes: list[str]
    errors: list[float]
    leaves: list[float]
    methods: list[str]
    lmax: int


METHODS = ("auto", "quadrature", "harmonic")


def bake_cube(
    pyr: Pyramid,
    size: int,
    roughness: list[float],
    lobe: str = "ggx_nl",
    quality: Quality = Quality(),
    workers: int | None = None,
    device: str = "cpu",
    estimate: bool = True,
    method: str = "auto",
) -> Baked:
    """The prefiltered cube of ``size``^2 faces with one mip per entry of ``roughness`` (perceptual): r = 0 is the
    area average (lobe ``footprint``), r > 0 lobe ``lobe`` at alpha = lobes.alpha_of(lobe, r) (r^2; Charlie r).
    ``lobe = "cosine"``: every mip the irradiance lobe (roughness ignored). ``method``: ``auto`` bakes every mip
    whose lobe's coefficients fall fast enough (harmonic.plan_lmax) by spherical harmonics (lutbake.environment.
    harmonic: exact convolution, seconds) and the others (the footprint, lobes narrower than its cap) by the pyramid
    quadrature; ``quadrature`` every mip by the quadrature; ``harmonic`` refuses a mip the harmonics cannot bake."""
    from . import harmonic

    if method not in METHODS:
        raise ValueError(f"method must be one of {list(METHODS)}, got {method!r}")
    lobes = ["cosine" if lobe == "cosine" else "footprint" if r == 0 else lobe for r in roughness]
    alphas = [alpha_of(lobe, r) for r in roughness]
    texels = cube_texels(size, lobes, alphas)
    lmax, by_harmonics = harmonic.plan_lmax(lobes, alphas) if method != "quadrature" else (0, [False] * len(lobes))
    if method == "harmonic" and not all(by_harmonics):
        bad = [m for m, ok in enumerate(by_harmonics) if not ok]
        raise ValueError(f"mips {bad} (lobes {[lobes[m] for m in bad]}) cannot be baked by harmonics; use 'auto'")
    flat = np.zeros((texels.n, OUT_WIDTH))
    quad = [m for m, h in enumerate(by_harmonics) if not h]
    for group in ([m for m in quad if lobes[m] == "footprint"], [m for m in quad if lobes[m] != "footprint"]):
        if group:  # the footprint mips in large tiles, the lobes' in small ones
            sub = texels.select(group)
            values = execute_tiles(cube_plan(pyr, sub, quality), workers=workers, device=device)
            for j, m in enumerate(group):
                flat[texels.offsets[m] : texels.offsets[m + 1]] = values[sub.offsets[j] : sub.offsets[j + 1]]
    if any(by_harmonics):
        threads = workers or os.cpu_count() or 1
        h = harmonic.analyse(pyr.level(0), lmax, threads=threads)
        for m in (m for m, ok in enumerate(by_harmonics) if ok):
            g = harmonic.kernel_coefficients(lobes[m], alphas[m], lmax)
            s, e = texels.offsets[m], texels.offsets[m + 1]
            flat[s:e, :3] = harmonic.synthesise(h, g, texels.dirs[s:e], threads)
    mips = [flat[s:e, :3].reshape(6, n, n, 3) for n, s, e in zip(texels.sizes, texels.offsets, texels.offsets[1:])]
    leaves = [float(np.mean(flat[s:e, 4])) for s, e in zip(texels.offsets, texels.offsets[1:])]
    errors = error_estimates(pyr, texels, flat, quality, device) if estimate else []
    methods = ["harmonic" if ok else "quadrature" for ok in by_harmonics]
    return Baked(mips, list(roughness), alphas, lobes, errors, leaves, methods, lmax if any(by_harmonics) else 0)
