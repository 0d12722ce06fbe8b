"""The prefiltered cube by spherical harmonics: with n = v = r every lobe of lutbake.environment.lobes is zonal (its
weight depends on t = r.l only), so the prefilter is a convolution on the sphere, diagonal in the SH basis
(Funk–Hecke; Driscoll & Healy 1994, "Computing Fourier Transforms and Convolutions on the 2-Sphere", Thm. 1):

    ∫ L(l) k(r.l) dω = Σ_lm g_l a_lm Y_lm(r),   g_l = 2 pi ∫_{-1}^{1} k(t) P_l(t) dt,   P(r) = that / (g_0 ...)

so P(r) = Σ_l (g_l / g_0) Σ_m a_lm Y_lm(r) (a uniform source gives P = L). Three exact steps, none sampled:

1. **Analysis** (``analyse``): a_lm = ∫ L Y*_lm dω of the texel-constant lat-long source, exact for every l <= lmax:
   in phi each cell's integral of e^{-i m phi} is the DFT at the cell centres times sinc(m dphi / 2) (the box
   factor); in theta each row is integrated by an ``order``-point Gauss–Legendre rule (sub-rings), exact to ~1e-9
   relative for l up to the source's row count (a row spans at most half an oscillation of P_lm there). ducc0's
   ring transform (Reinecke & Seljebotn 2013, "Libsharp", A&A 554 A112) does the sums.
2. **The kernel's coefficients** (``kernel_coefficients``): g_l by composite Gauss–Legendre in theta (panels graded
   geometrically from the lobe's width, and at least one per half-oscillation of P_l, ending at the horizon where
   the weight has its kink), P_l by the three-term recurrence.
3. **Synthesis** (``synthesise``) at the cube texels' centre directions: ducc0's NUFFT-based evaluation at arbitrary
   points (epsilon 1e-11).

**Truncation**: the coefficients of a GGX lobe fall like exp(-2 alpha l); a mip is baked this way when |g_l / g_0|
<= ``KERNEL_TAIL`` for every l past ``lmax`` (``needed_lmax``), and lmax is at most ``LMAX_CAP``; a narrower lobe is
left to the pyramid quadrature (lutbake.environment.quadrature). Every lobe is cut at the horizon (n.l > 0): that
kink's g_l fall only like l^-5/2 (the irradiance lobe (n.l)+ is nothing but the kink), so lmax is at least
``LMAX_FLOOR``, where the truncation measured ~1e-5 of P on a real HDR with a sun. The per-mip error estimate
(lutbake.environment.prefilter) checks probe texels against the quadrature, an independent method.

Deterministic: ducc0 splits the work by m and by ring, each sum in a fixed order, so any thread count gives the same
bits (tested).
"""

from __future__ import annotations

import functools
import hashlib
import math
import threading
from dataclasses import dataclass

import numpy as np

from .lobes import PROFILES, SMOOTH_PROFILES

KERNEL_TAIL = 1e-10  # |g_l / g_0| past lmax: the truncation's share of P, before the source's contrast
LMAX_FLOOR = 1023  # the horizon kink's g_l fall like l^-5/2: at 1023 the truncation is ~1e-5 of P (measured)
LMAX_CAP = 1535  # the largest analysis: about 3 s on two cores for a 2048 x 1024 source
SUB_RINGS = 6  # Gauss–Legendre points per source row of at most lmax rows (3 more per lmax / rows beyond)
EPSILON = 1e-11  # ducc0 synthesis accuracy


@dataclass(frozen=True)
class Harmonics:
    """a_lm of the three channels, (3, nalm) complex, ducc0's (healpy's) order: m = 0..lmax, l = m..lmax."""

    alm: np.ndarray
    lmax: int


def l_of_index(lmax: int) -> np.ndarray:
    """l of every a_lm index in ducc0's order."""
    return np.concatenate([np.arange(m, lmax + 1) for m in range(lmax + 1)])


def m_of_index(lmax: int) -> np.ndarray:
    return np.concatenate([np.full(lmax + 1 - m, m) for m in range(lmax + 1)])


_ANALYSES: dict[tuple, Harmonics] = {}  # the last few analyses, by the image's sha256, lmax and order
_ANALYSES_KEPT = 2
_LOCK = threading.Lock()


def analyse(image: np.ndarray, lmax: int, order: int = SUB_RINGS, threads: int = 1) -> Harmonics:
    """a_lm (l <= lmax) of the texel-constant lat-long ``image`` (H, W, 3), lutbake.environment.latlong's
    convention: colatitude theta from +Y, longitude phi = atan2(z, x) + pi in [0, 2 pi). The last analyses are kept
    (a specular and an irradiance cube of one source share one; the same bits for any ``threads``)."""
    image = np.ascontiguousarray(image, np.float64)
    key = (hashlib.sha256(image.data).hexdigest(), image.shape, lmax, order)
    with _LOCK:
        if key in _ANALYSES:
            return _ANALYSES[key]
    out = _analyse(image, lmax, order, threads)
    out.alm.flags.writeable = False
    with _LOCK:
        _ANALYSES[key] = out
        while len(_ANALYSES) > _ANALYSES_KEPT:
            del _ANALYSES[next(iter(_ANALYSES))]
    return out


def _analyse(image: np.ndarray, lmax: int, order: int, threads: int) -> Harmonics:
    from ducc0.sht.experimental import adjoint_synthesis

    h, w = image.shape[:2]
    order += 3 * math.ceil(lmax / h) - 3  # rows wider than a period of P_lm: more sub-rings
    x, wx = np.polynomial.legendre.leggauss(order)
    dth = math.pi / h
    theta = (np.arange(h)[:, None] + 0.5 + 0.5 * x[None, :]) * dth  # (h, order)
    weights = 0.5 * wx[None, :] * dth * np.sin(theta) * (2 * math.pi / w)
    maps = image.transpose(2, 0, 1)[:, :, None, :] * weights[None, :, :, None]
    rings = h * order
    alm = adjoint_synthesis(
        map=maps.reshape(3, 1, -1),
        theta=theta.ravel(),
        lmax=lmax,
        nphi=np.full(rings, w, np.uintp),
        phi0=np.full(rings, math.pi / w),
        ringstart=(np.arange(rings) * w).astype(np.uintp),
        spin=0,
        nthreads=threads,
    )[:, 0, :]
    half = m_of_index(lmax) * (math.pi / w)  # m dphi / 2: the box factor of a texel-constant row
    box = np.ones_like(half)
    box[half > 0] = np.sin(half[half > 0]) / half[half > 0]
    return Harmonics(alm * box, lmax)


CUBE_ORDER = 4  # Gauss–Legendre points per axis of a cube texel, plus 2 per half-oscillation of Y_lm it spans
CUBE_CHUNK = 1 << 22  # points per ducc0 call (its loc array: 32 MiB)


def cube_order(n: int, lmax: int) -> int:
    """Gauss–Legendre points per axis and cube texel for a_lm up to lmax of an n^2-texel face: a texel spans at most
    2/n radians (at the face centre), and Y_lm oscillates with period 2 pi / l, so ``CUBE_ORDER`` plus 2 per half
    period a texel spans. Measured on an octant-constant cube against order 24 (max |a_lm| relative): 1.6e-14
    (n 32, lmax 20: order 6), 7.8e-14 (32, 40: 6), 1.3e-13 (32, 80: 8), 2.7e-13 (16, 100: 12)."""
    return CUBE_ORDER + 2 * math.ceil(lmax * (2.0 / n) / math.pi)


def analyse_cube(
    faces: np.ndarray, lmax: int, order: int | None = None, flip=(1.0, 1.0, 1.0), threads: int = 1
) -> Harmonics:
    """a_lm (l <= lmax) of the texel-constant cube ``faces`` (6, n, n, 3) in lutbake.environment.cube's face table:
    each texel holds the mean radiance over its footprint, so

        a_lm = Σ_texels L_texel ∫_texel Y*_lm(d(u, v)) (1 + u^2 + v^2)^(-3/2) du dv

    (the solid angle of the face plane at unit distance: dω = (1 + u^2 + v^2)^(-3/2) du dv), each texel's integral by
    an ``order`` x ``order`` Gauss–Legendre product rule in (u, v) (default ``cube_order(n, lmax)``), the sums by
    ducc0's adjoint_synthesis_general (the adjoint of the NUFFT-based synthesis at arbitrary points, epsilon
    EPSILON). ``flip``: the world direction of lookup vector d is d * flip (lutbake.environment.cube.ORIENTATIONS),
    so the a_lm are of the world's radiance (theta from +Y, phi = atan2(z, x) + pi, as ``analyse``)."""
    from ducc0.sht.experimental import adjoint_synthesis_general

    from .cube import face_directions, texel_edges

    faces = np.asarray(faces, np.float64)
    n = faces.shape[1]
    if faces.shape != (6, n, n, 3):
        raise ValueError(f"a cube source is (6, n, n, 3), got {faces.shape}")
    order = order or cube_order(n, lmax)
    x, wx = np.polynomial.legendre.leggauss(order)
    edges = texel_edges(n)[:-1]
    sub = (edges[:, None] + (x[None, :] + 1.0) / n).ravel()  # (n * order,) u (or v) of every texel's nodes
    wsub = np.tile(wx / n, n)
    v, u = np.meshgrid(sub, sub, indexing="ij")  # rows: v (t), columns: u (s)
    area = np.outer(wsub, wsub) * (1.0 + u * u + v * v) ** -1.5
    rows_per_chunk = max(1, CUBE_CHUNK // (n * order))
    locs = []
    for f in range(6):
        d = face_directions(np.full(u.shape, f), u, v) * np.asarray(flip, np.float64)
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        locs.append(
            np.stack([np.arccos(np.clip(d[..., 1], -1.0, 1.0)), np.arctan2(d[..., 2], d[..., 0]) + math.pi], -1)
        )

    def channel(c: int) -> np.ndarray:
        """One channel's a_lm: single-threaded ducc0 calls summed in a fixed order (its multi-threaded adjoint
        NUFFT spreads in an order that changes from run to run), so the bits never depend on ``threads``."""
        out = np.zeros((lmax + 1) * (lmax + 2) // 2, np.complex128)
        for f in range(6):
            radiance = np.repeat(np.repeat(faces[f, ..., c], order, axis=0), order, axis=1)  # each node its texel's
            for r0 in range(0, n * order, rows_per_chunk):
                rows = slice(r0, r0 + rows_per_chunk)
                out += adjoint_synthesis_general(
                    map=(radiance[rows] * area[rows]).reshape(1, -1),
                    spin=0,
                    lmax=lmax,
                    loc=np.ascontiguousarray(locs[f][rows].reshape(-1, 2)),
                    epsilon=EPSILON,
                    nthreads=1,
                )[0]
        return out

    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max(1, min(3, threads))) as pool:
        alm = np.stack(list(pool.map(channel, range(3))))
    return Harmonics(alm, lmax)


@functools.lru_cache(maxsize=64)
def kernel_coefficients(lobe: str, alpha: float, lmax: int, order: int = 8, smooth: bool = False) -> np.ndarray:
    """g_l / g_0 for l = 0..lmax of the zonal weight PROFILES[lobe](t, alpha) (module docstring); ``smooth``: of
    SMOOTH_PROFILES[lobe], the weight without the horizon's cut, over the whole sphere, / max |g_l| (its g_0 may
    vanish)."""
    profile = SMOOTH_PROFILES[lobe] if smooth else PROFILES[lobe]
    end = math.pi if smooth else math.pi / 2
    width = max(alpha, 1e-4)
    edges = np.unique(
        np.concatenate(
            [[0.0], np.geomspace(width * 1e-3, end, 256), np.linspace(0.0, end, int(lmax * end / math.pi) + 2)]
        )
    )
    x, wx = np.polynomial.legendre.leggauss(order)
    a, b = edges[:-1, None], edges[1:, None]
    theta = (0.5 * (a + b) + 0.5 * (b - a) * x).ravel()
    t = np.cos(theta)
    f = profile(t, alpha) * (0.5 * (b - a) * wx).ravel() * np.sin(theta)
    g = np.empty(lmax + 1)
    p_prev, p, tmp = np.ones_like(t), t.copy(), np.empty_like(t)
    g[0] = f.sum()
    # np.sum's pairwise sum, not f @ p: BLAS's dot splits the sum by its thread count (other last bits on another
    # machine) and, threaded beside busy cores, waits for its helper threads
    if lmax > 0:
        g[1] = np.sum(f * p)
    for n in range(1, lmax):  # P_{n+1} = ((2n + 1) t P_n - n P_{n-1}) / (n + 1), in place
        np.multiply(t, p, out=tmp)
        tmp *= (2 * n + 1) / (n + 1)
        p_prev *= n / (n + 1)
        tmp -= p_prev
        p_prev, p, tmp = p, tmp, p_prev
        g[n + 1] = np.sum(f * p)
    g /= np.abs(g).max() if smooth else g[0]
    g.flags.writeable = False  # cached
    return g


def needed_lmax(g: np.ndarray) -> int | None:
    """The smallest lmax past which |g_l| <= KERNEL_TAIL up to len(g) - 1, or None when g has not fallen that far."""
    above = np.nonzero(np.abs(g) > KERNEL_TAIL)[0]
    last = int(above[-1]) if len(above) else 0
    return None if last >= len(g) - 1 else last


def synthesise(h: Harmonics, g: np.ndarray, dirs: np.ndarray, threads: int = 1) -> np.ndarray:
    """(n, C): Σ_l g_l Σ_m a_lm Y_lm at unit directions ``dirs`` (n, 3), l <= min(h.lmax, len(g) - 1), C the
    channels of ``h`` (3, or 1 for a combination of them). One ducc0
    thread per channel (its multi-threaded NUFFT sums in an order that depends on the thread count), the channels
    on ``threads`` Python threads: the same bits for any ``threads``."""
    from concurrent.futures import ThreadPoolExecutor

    from ducc0.sht.experimental import synthesis_general

    lmax = min(h.lmax, len(g) - 1)
    ls = l_of_index(h.lmax)
    keep = ls <= lmax  # in ducc0's order the kept entries are the smaller layout's, in order
    alm = h.alm[:, keep] * g[ls[keep]]
    loc = np.stack([np.arccos(np.clip(dirs[:, 1], -1.0, 1.0)), np.arctan2(dirs[:, 2], dirs[:, 0]) + math.pi], 1)

    def channel(c: int) -> np.ndarray:
        return synthesis_general(alm=alm[c : c + 1], spin=0, lmax=lmax, loc=loc, epsilon=EPSILON, nthreads=1)[0]

    with ThreadPoolExecutor(max(1, min(len(alm), threads))) as pool:
        return np.stack(list(pool.map(channel, range(len(alm)))), axis=1)


def plan_lmax(lobes: list[str], alphas: list[float]) -> tuple[int, list[bool]]:
    """(lmax, per mip: baked by harmonics?) for mips of ``lobes`` at ``alphas``: a mip is when its lobe's smooth
    profile (SMOOTH_PROFILES: the lobe's width, without the horizon's kink) has coefficients below KERNEL_TAIL by
    LMAX_CAP; lmax is the largest such mip needs, at least LMAX_FLOOR (for the kink's tail)."""
    needs = [
        needed_lmax(kernel_coefficients(lobe, a, LMAX_CAP, smooth=True)) if lobe in SMOOTH_PROFILES else None
        for lobe, a in zip(lobes, alphas)
    ]
    use = [n is not None for n in needs]
    return max([LMAX_FLOOR] + [n for n in needs if n is not None]), use
