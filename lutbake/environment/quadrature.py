"""The exact-integral quadrature of one output texel: ∫ L w dω and ∫ w dω over the sphere, L the texel-constant
source, w a lobe of lutbake.environment.lobes, by a deterministic descent of the source's pyramid.

**The tree.** The cells of the lat-long pyramid (lutbake.environment.latlong.Pyramid) nest: each cell of level k
is four cells of level k - 1, down to the source texels (level 0) and, below them, sub-cells that split a texel for
the weight alone (levels -1 .. -V: the radiance is the texel's, the cell is smaller). A texel's integral is a sum
over the leaves of one cut of that tree, so every direction is counted once, whatever the cut:

    ∫ L w dω = Σ_leaves L(leaf) ∫_leaf w dω,      ∫ w dω = Σ_leaves ∫_leaf w dω

Descending from the roots (the coarsest level, every cell), a cell whose directions all lie behind a clip plane
(the horizon r.l = 0, or a footprint's four planes) is dropped (its weight is exactly 0). A cell of level k >= 0
**fixes its radiance** (L(leaf) = the cell's linear model, lutbake.environment.latlong.Pyramid: exact integral and
first moments over the cell, for every leaf below it) when

    contrast x variation^2 <= tau,   contrast = max_c (max L_c - min L_c) / P_c   (over its source texels)
    variation = S rho / (d + lambda);   contrast <= tau^2 where a clip plane crosses the cell (the model knows the
    cell, not its cut: the error of a cut cell is first order in its contrast); a footprint's cut cells descend to
    the source texels (contrast 0: only uniform cells fix), so the area average is exact

rho the cell's angular radius, d its least angle to r, lambda the lobe's width, S the lobe's slope
(lutbake.environment.lobes.LOBES), P_c the texel's value from a first, coarse pass (tau = 1; in that pass, the
cell's own mean).
The model integrates the weight's constant and linear parts exactly, so a fixed
cell's error is the weight's curvature against the source's departure from its model, about (max L - min L) x
variation^2 x ∫_cell w: with the criterion, about tau x P x ∫_cell w, and over all cells tau x P x ∫ w (a
relative error tau per channel, the budget spent where the weight and the source's detail are, not on dark cells;
an estimate, not a bound: the recorded error is measured against a finer bake). Level 0 always
fixes (the source is texel-constant: no error). Below a fixed cell the descent continues for the weight alone
until rho K <= d + lambda (the weight is smooth across the cell; where a clip plane crosses the cell,
rho K <= min(d + lambda, c): the clipped length has kinks where the planes take turns), or the floor -V, and the
leaf's ∫ w dω is a
G x G Gauss-Legendre rule in (phi, theta) with dω = sin theta dtheta dphi, **clipped exactly in theta**: on the
meridian phi, p.l = A cos theta + B sin theta (A = p_y, B = p_x cos phi + p_z sin phi) changes sign at most once
in [0, pi], at theta = atan2(-A, B) mod pi, so each node's theta interval is cut where the horizon (or a footprint
edge) crosses it and the rule is applied on the part in front. No random numbers, no clamping: the sums are in
float64 in a fixed order, so a texel's value does not depend on the tile or the thread.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import warp as wp

from ..runtime.warp_runtime import kernel_factory, unique_kernel
from .latlong import Pyramid
from .lobes import LOBES

Nodes = wp.array(dtype=wp.float64)  # Gauss-Legendre nodes or weights on [0, 1]
# the pyramid on the device: ``cells`` (6, N) vec3d rows and ``dims`` (3, levels) int32 rows
CELL_ROWS = ("mean", "offset", "slope_theta", "slope_phi", "low", "high")
DIM_ROWS = ("heights", "widths", "offsets")
MEAN, OFFSET, SLOPE_THETA, SLOPE_PHI, LOW, HIGH = range(6)
HEIGHT, WIDTH, START = range(3)
STACK = 128  # the descent's stack: 3 entries a level below the root cells, at most 40 levels (checked by the host)
MAX_DEPTH = 40
NONE = 127  # a cell whose radiance is not fixed yet
OUT_WIDTH = 5  # ∫ L w (r, g, b), ∫ w, leaves


@wp.struct
class Leaf:
    """One leaf of the descent: the texel's direction r and alpha, the cell (theta0, theta1, phi0, phi1), the fixed
    cell's linear model (rows c0, c_theta, c_phi) and frame (theta_c, dtheta, phi_c, dphi)."""

    r: wp.vec3d
    alpha: wp.float64
    cell: wp.vec4d
    model: wp.mat33d
    frame: wp.vec4d


@wp.struct
class Texels:
    """The texels of one launch: direction, clip planes (n, P), alpha, lobe width, reference value (< 0: none)."""

    dirs: wp.array(dtype=wp.vec3d)
    plane: wp.array2d(dtype=wp.vec3d)
    alphas: wp.array(dtype=wp.float64)
    lams: wp.array(dtype=wp.float64)
    reference: wp.array(dtype=wp.vec3d)


@kernel_factory
def texel_kernel(lobe: str, planes: int, order: int):
    """The kernel integrating each texel's lobe ``lobe`` (LOBES) clipped by ``planes`` planes per texel with an
    ``order`` x ``order`` Gauss-Legendre rule per leaf: out[t] = (∫ L w (rgb), ∫ w, leaves)."""
    weight, slope = LOBES[lobe]
    stack_t = wp.types.vector(length=STACK, dtype=wp.int32)
    breaks_t = wp.types.vector(length=2 + 4 * planes + planes * (planes - 1), dtype=wp.float64)
    pi = wp.float64(math.pi)
    two_pi = wp.float64(2.0 * math.pi)
    half_pi = wp.float64(math.pi / 2)

    @wp.func
    def angle(a: wp.vec3d, b: wp.vec3d):
        return wp.atan2(wp.length(wp.cross(a, b)), wp.dot(a, b))

    @wp.func
    def direction(theta: wp.float64, phi: wp.float64):
        st = wp.sin(theta)
        return wp.vec3d(st * wp.cos(phi), wp.cos(theta), st * wp.sin(phi))

    @wp.func
    def weighted(leaf: Leaf, theta: wp.float64, phi: wp.float64, wt: wp.float64):
        """(L wt, wt) at (theta, phi): L = c0 + c_theta u + c_phi v, the fixed cell's linear model."""
        model = leaf.model
        u = (theta - leaf.frame[0]) / leaf.frame[1]
        v = (phi - leaf.frame[2]) / leaf.frame[3]
        L = wp.vec3d(model[0, 0], model[0, 1], model[0, 2])
        L += wp.vec3d(model[1, 0], model[1, 1], model[1, 2]) * u + wp.vec3d(model[2, 0], model[2, 1], model[2, 2]) * v
        return wp.vec4d(L[0] * wt, L[1] * wt, L[2] * wt, wt)

    @wp.func
    def leaf_span(
        leaf: Leaf, plane: wp.array2d(dtype=wp.vec3d), t: int, ph0: wp.float64, ph1: wp.float64, gx: Nodes, gw: Nodes
    ):
        """(∫ L w dω, ∫ w dω) over phi in [ph0, ph1] (no breakpoint inside), each meridian's theta interval
        clipped."""
        th0 = leaf.cell[0]
        th1 = leaf.cell[1]
        total = wp.vec4d(0.0, 0.0, 0.0, 0.0)
        for a in range(wp.static(order)):
            phi = ph0 + (ph1 - ph0) * gx[a]
            cp = wp.cos(phi)
            sp = wp.sin(phi)
            lo = th0
            hi = th1
            for k in range(wp.static(planes)):
                p = plane[t, k]
                A = p[1]
                B = p[0] * cp + p[2] * sp
                s0 = A * wp.cos(th0) + B * wp.sin(th0)
                s1 = A * wp.cos(th1) + B * wp.sin(th1)
                if s0 < wp.float64(0.0) and s1 < wp.float64(0.0):
                    hi = lo
                elif s0 < wp.float64(0.0) or s1 < wp.float64(0.0):
                    root = wp.atan2(-A, B)
                    if root < wp.float64(0.0):
                        root = root + pi
                    if root >= pi:  # atan2(0, B < 0) = pi: the root in [0, pi) is 0 (a plane through the pole)
                        root = root - pi
                    root = wp.clamp(root, th0, th1)
                    if s0 >= wp.float64(0.0):
                        hi = wp.min(hi, root)
                    else:
                        lo = wp.max(lo, root)
            if hi > lo:
                inner = wp.vec4d(0.0, 0.0, 0.0, 0.0)
                for b in range(wp.static(order)):
                    theta = lo + (hi - lo) * gx[b]
                    wt = gw[b] * wp.sin(theta) * weight(leaf.r, direction(theta, phi), leaf.alpha)
                    inner += weighted(leaf, theta, phi, wt)
                total += gw[a] * (hi - lo) * inner
        return total * (ph1 - ph0)

    @wp.func
    def leaf_plain(leaf: Leaf, gx: Nodes, gw: Nodes):
        """(∫ L w dω, ∫ w dω) over a cell no clip plane crosses: the order x order product rule, its sines and
        cosines once per node row and column."""
        c = leaf.cell  # theta0, theta1, phi0, phi1
        total = wp.vec4d(0.0, 0.0, 0.0, 0.0)
        for b in range(wp.static(order)):
            theta = c[0] + (c[1] - c[0]) * gx[b]
            st = wp.sin(theta)
            ct = wp.cos(theta)
            inner = wp.vec4d(0.0, 0.0, 0.0, 0.0)
            for a in range(wp.static(order)):
                phi = c[2] + (c[3] - c[2]) * gx[a]
                wt = gw[a] * weight(leaf.r, wp.vec3d(st * wp.cos(phi), ct, st * wp.sin(phi)), leaf.alpha)
                inner += weighted(leaf, theta, phi, wt)
            total += gw[b] * st * inner
        return total * (c[1] - c[0]) * (c[3] - c[2])

    @wp.func
    def leaf_weight(leaf: Leaf, plane: wp.array2d(dtype=wp.vec3d), t: int, gx: Nodes, gw: Nodes):
        """(∫ L w dω, ∫ w dω) over the cell: its phi interval split where a plane's great circle crosses the cell's edge
        theta = th0 or th1 (p.l = 0 there: sin(theta) (p_x cos phi + p_z sin phi) = -p_y cos(theta)), where the
        clipped theta interval has a kink or a jump (a plane through the pole cuts along a meridian), and at the
        azimuth of each corner where two planes meet (±p1 x p2); leaf_span on each piece."""
        th0 = leaf.cell[0]
        th1 = leaf.cell[1]
        ph0 = leaf.cell[2]
        ph1 = leaf.cell[3]
        bp = breaks_t()
        nb = wp.int32(1)  # dynamic (a literal is a constant to Warp)
        bp[0] = ph0
        for k in range(wp.static(planes)):
            p = plane[t, k]
            rad = wp.sqrt(p[0] * p[0] + p[2] * p[2])
            base = wp.atan2(p[2], p[0])
            for e in range(2):
                edge = th0
                if e == 1:
                    edge = th1
                st = wp.sin(edge)
                if st > wp.float64(1e-12) and rad > wp.float64(1e-15):
                    c = -p[1] * wp.cos(edge) / (st * rad)
                    if wp.abs(c) < wp.float64(1.0):
                        dphi = wp.acos(c)
                        for sgn in range(2):
                            phi = base + dphi
                            if sgn == 1:
                                phi = base - dphi
                            phi = phi - two_pi * wp.floor((phi - ph0) / two_pi)
                            if phi > ph0 and phi < ph1:
                                bp[nb] = phi
                                nb += 1
        for k1 in range(wp.static(planes)):  # the corners where two planes meet: the clipped length has a kink
            for k2 in range(k1 + 1, wp.static(planes)):
                corner = wp.cross(plane[t, k1], plane[t, k2])
                if wp.length(corner) > wp.float64(1e-15):
                    for sgn in range(2):
                        phi = wp.atan2(corner[2], corner[0])
                        if sgn == 1:
                            phi = wp.atan2(-corner[2], -corner[0])
                        phi = phi - two_pi * wp.floor((phi - ph0) / two_pi)
                        if phi > ph0 and phi < ph1:
                            bp[nb] = phi
                            nb += 1
        for a in range(1, nb):  # insertion sort of the breakpoints
            b = a
            while b > 0 and bp[b - 1] > bp[b]:
                tmp = bp[b]
                bp[b] = bp[b - 1]
                bp[b - 1] = tmp
                b -= 1
        total = wp.vec4d(0.0, 0.0, 0.0, 0.0)
        for q in range(nb):
            right = ph1
            if q + 1 < nb:
                right = bp[q + 1]
            if right > bp[q]:
                total += leaf_span(leaf, plane, t, bp[q], right, gx, gw)
        return total

    @unique_kernel
    def integrate_texels(
        tex: Texels,
        cells: wp.array2d(dtype=wp.vec3d),
        dims: wp.array2d(dtype=wp.int32),
        levels: wp.vec2i,
        control: wp.vec3d,
        gx: Nodes,
        gw: Nodes,
        out: wp.array2d(dtype=wp.float64),
    ):
        """levels = (top, floor); control = (tau, K, c)."""
        t = wp.tid()
        r = tex.dirs[t]
        alpha = tex.alphas[t]
        lam = tex.lams[t]
        plane = tex.plane
        top = levels[0]
        floor = levels[1]
        tau = control[0]
        k_geo = control[1]
        cross = control[2]
        heights = dims[wp.static(HEIGHT)]
        widths = dims[wp.static(WIDTH)]
        offsets = dims[wp.static(START)]
        acc = wp.vec3d(0.0, 0.0, 0.0)
        wsum = wp.float64(0.0)
        leaves = wp.int32(0)  # dynamic
        sl = stack_t()
        si = stack_t()
        sj = stack_t()
        sf = stack_t()
        for ri in range(heights[top]):
            for rj in range(widths[top]):
                n = wp.int32(1)  # dynamic: the stack's depth
                sl[0] = top
                si[0] = ri
                sj[0] = rj
                sf[0] = wp.static(NONE)
                while n > 0:
                    n -= 1
                    lev = sl[n]
                    i = si[n]
                    j = sj[n]
                    fixed = sf[n]
                    h = heights[0]
                    w = widths[0]
                    if lev >= 0:
                        h = heights[lev]
                        w = widths[lev]
                    else:
                        h = h << (-lev)
                        w = w << (-lev)
                    th0 = pi * wp.float64(i) / wp.float64(h)
                    th1 = pi * wp.float64(i + 1) / wp.float64(h)
                    ph0 = wp.float64(2.0) * pi * wp.float64(j) / wp.float64(w) - pi
                    ph1 = wp.float64(2.0) * pi * wp.float64(j + 1) / wp.float64(w) - pi
                    s_eq = wp.max(wp.sin(th0), wp.sin(th1))
                    if th0 <= half_pi and th1 >= half_pi:
                        s_eq = wp.float64(1.0)
                    rho = wp.min(pi, wp.float64(0.5) * ((th1 - th0) + (ph1 - ph0) * s_eq))
                    c = direction(wp.float64(0.5) * (th0 + th1), wp.float64(0.5) * (ph0 + ph1))
                    dist = wp.max(wp.float64(0.0), angle(r, c) - rho)
                    dropped = wp.bool(False)  # dynamic
                    crossing = wp.bool(False)  # dynamic
                    for k in range(wp.static(planes)):
                        a = angle(plane[t, k], c)
                        if a - rho > half_pi:
                            dropped = True
                        if a + rho > half_pi:
                            crossing = True
                    if dropped:
                        continue
                    if fixed == wp.static(NONE):
                        if lev == 0:
                            fixed = 0
                        else:
                            idx = offsets[lev] + i * w + j
                            spread = cells[wp.static(HIGH), idx] - cells[wp.static(LOW), idx]
                            scale_c = tex.reference[t]
                            if scale_c[0] < wp.float64(0.0):  # no reference: the cell's own mean
                                scale_c = cells[wp.static(MEAN), idx]
                            contrast = wp.float64(0.0)
                            for ch in range(3):
                                if spread[ch] > wp.float64(0.0):
                                    if scale_c[ch] > wp.float64(0.0):
                                        contrast = wp.max(contrast, spread[ch] / scale_c[ch])
                                    else:
                                        contrast = wp.float64(1e300)
                            budget = tau * tau  # a cut cell: its error is first order in its contrast
                            if wp.static(lobe == "footprint"):
                                budget = wp.float64(0.0)  # a footprint's cut cells take the source itself
                            if not crossing:
                                variation = wp.float64(wp.static(slope)) * rho / (dist + lam)
                                budget = tau / (variation * variation)
                            if contrast <= budget:
                                fixed = lev
                    scale = dist + lam
                    if crossing:
                        scale = wp.min(scale, cross)
                    if fixed != wp.static(NONE) and (lev == floor or rho * k_geo <= scale):
                        shift = fixed - lev
                        fi = i >> shift
                        fj = j >> shift
                        fh = heights[fixed]
                        fw = widths[fixed]
                        idx = offsets[fixed] + fi * fw + fj
                        leaf = Leaf()
                        leaf.r = r
                        leaf.alpha = alpha
                        leaf.cell = wp.vec4d(th0, th1, ph0, ph1)
                        leaf.model = wp.matrix_from_rows(
                            cells[wp.static(OFFSET), idx],
                            cells[wp.static(SLOPE_THETA), idx],
                            cells[wp.static(SLOPE_PHI), idx],
                        )
                        dth = pi / wp.float64(fh)
                        dph = wp.float64(2.0) * pi / wp.float64(fw)
                        leaf.frame = wp.vec4d(
                            dth * (wp.float64(fi) + wp.float64(0.5)),
                            dth,
                            dph * (wp.float64(fj) + wp.float64(0.5)) - pi,
                            dph,
                        )
                        part = wp.vec4d(0.0, 0.0, 0.0, 0.0)
                        if crossing:
                            part = leaf_weight(leaf, plane, t, gx, gw)
                        else:
                            part = leaf_plain(leaf, gx, gw)
                        acc += wp.vec3d(part[0], part[1], part[2])
                        wsum += part[3]
                        leaves += 1
                    else:
                        for q in range(4):
                            sl[n] = lev - 1
                            si[n] = 2 * i + q // 2
                            sj[n] = 2 * j + q % 2
                            sf[n] = fixed
                            n += 1
        out[t, 0] = acc[0]
        out[t, 1] = acc[1]
        out[t, 2] = acc[2]
        out[t, 3] = wsum
        out[t, 4] = wp.float64(leaves)

    return integrate_texels


def gl_unit(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(order)
    return (x + 1) / 2, w / 2


@functools.lru_cache(maxsize=8)
def _device_pyramid(pyr: Pyramid, device: str) -> tuple:
    """(cells, dims): the pyramid's arrays on ``device`` (CELL_ROWS, DIM_ROWS; one copy per pyramid and device)."""
    cells = np.ascontiguousarray(np.stack([getattr(pyr, name) for name in CELL_ROWS]))
    dims = np.ascontiguousarray(np.stack([getattr(pyr, name) for name in DIM_ROWS]).astype(np.int32))
    return wp.array(cells, dtype=wp.vec3d, device=device), wp.array(dims, dtype=wp.int32, device=device)


def integrate(
    pyr: Pyramid,
    lobe: str,
    dirs: np.ndarray,
    planes: np.ndarray,
    alpha: np.ndarray,
    lam: np.ndarray,
    reference: np.ndarray | None = None,
    *,
    tau: float,
    k_geo: float,
    cross: float,
    floor: int,
    order: int,
    device: str = "cpu",
) -> np.ndarray:
    """(n, OUT_WIDTH) float64: per texel ∫ L w dω (rgb), ∫ w dω and the leaf count, for directions ``dirs`` (n, 3),
    clip ``planes`` (n, P, 3), ``alpha`` and lobe width ``lam`` (n,). ``floor`` <= 0: the lowest sub-texel level.
    ``reference`` (n, 3): the scale the contrast is measured against per texel (the texel's value from a coarser
    pass); None: each cell's own mean."""
    if reference is None:
        reference = np.full((len(dirs), 3), -1.0)
    n = len(dirs)
    if n == 0:
        return np.zeros((0, OUT_WIDTH))
    depth = pyr.levels - floor
    if depth > MAX_DEPTH:
        raise ValueError(f"{pyr.levels} pyramid levels and {-floor} sub-texel levels exceed {MAX_DEPTH}")
    kernel = texel_kernel(lobe, planes.shape[1], order)
    gx, gw = (wp.array(a, dtype=wp.float64, device=device) for a in gl_unit(order))
    out = wp.zeros((n, OUT_WIDTH), dtype=wp.float64, device=device)
    tex = Texels()
    tex.dirs = wp.array(np.ascontiguousarray(dirs, np.float64), dtype=wp.vec3d, device=device)
    tex.plane = wp.array(np.ascontiguousarray(planes, np.float64), dtype=wp.vec3d, device=device)
    tex.alphas = wp.array(np.ascontiguousarray(alpha, np.float64), dtype=wp.float64, device=device)
    tex.lams = wp.array(np.ascontiguousarray(lam, np.float64), dtype=wp.float64, device=device)
    tex.reference = wp.array(np.ascontiguousarray(reference, np.float64), dtype=wp.vec3d, device=device)
    levels = wp.vec2i(pyr.levels - 1, int(floor))
    control = wp.vec3d(float(tau), float(k_geo), float(cross))
    inputs = [tex, *_device_pyramid(pyr, device), levels, control, gx, gw, out]
    wp.launch(kernel, dim=n, inputs=inputs, device=device)
    return out.numpy()
