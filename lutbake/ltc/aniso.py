"""LTC tables of anisotropic GGX (Kt, Heitz, Dupuy & Narayanan 2022, "Bringing Linearly Transformed Cosines to
Anisotropic GGX", I3D; github AakashKT/LTC-Anisotropic): the lobe, its fit and the 4D table's texels.

The lobe: f(v, l) (n.l) = D(h) G2(v, l) / (4 n.v), D the anisotropic GGX NDF (Heitz 2014, Eq. 85; lutbake.terms.ndf
D_ggx_aniso), G2 height-correlated Smith with the anisotropic Lambda (Heitz 2014, Eqs. 86 and 99;
lutbake.terms.masking), F = 1 (the Fresnel channel below); the paper's fitting/anisotropic_ggx.py evaluates the same
f (its G2 = 1 / (1 + Lambda_v + Lambda_l), its cos theta_l cancelled by the rendering equation's).

Frames. The paper's texel (alpha_x, alpha_y, theta, phi) has v = (sin theta cos phi, sin theta sin phi, cos theta) in
the tangent frame (T = +x, B = +y, n = +z). The fit (lutbake.ltc.fit, a tabulated lobe) works in the view frame,
v = (sin theta, 0, cos theta): a view-frame direction x is R_z(phi) x in the tangent frame, so the lobe reads its
texel's (alpha_y, cos phi, sin phi) from the per-texel table and rotates, and a fitted view-frame M is R_z(phi) M in
the tangent frame (the clamped cosine is invariant under R_z, so any M R_z is the same LTC: ``canonical`` picks one).

The metric's lobe sampler is the anisotropic NDF's (h of slope (alpha_x r cos p, alpha_y r sin p), r = sqrt(u2 /
(1 - u2)), p = 2 pi u1 + phi; density D(h) (n.h) / (4 |v.h|), Walter et al. 2007 Eq. 14 and 38): at alpha_x = alpha_y
it is ltc_code's GGX sampler (lutbake.ltc.lobes), the same directions up to the rotation's rounding, so the isotropic
slice is fitted on lutbake's isotropic metric (test_ltc_aniso: the identity). The parametrisation: Problem's general
form (lutbake.ltc.fit.general_matrices, 5 parameters: m11, m22, m13, m23 and the frame angle psi about the lobe's
average direction) where the lobe has no plane of symmetry, ltc_code's 3 where it has (phi = 0 or pi/2, alpha_x =
alpha_y). The paper instead fits all 9 coefficients by SGD on a sliced-Wasserstein loss between LTC samples and
rejection-sampled GGX samples (fitting/fit_alphax_alphay_theta_phi.py), then aligns each M by a search over
R_z and flips (their "killing rotation").

Symmetries (the domain fitted): a reflection y -> -y maps phi to -phi, x -> -x maps phi to pi - phi, so phi in
[0, pi/2] covers every view (the paper's table and shader); the swap S of x and y maps (alpha_x, alpha_y, phi) to
(alpha_y, alpha_x, pi/2 - phi) with M -> S M S, so only alpha_x >= alpha_y is fitted; at theta = 0 the tangent-frame M
does not depend on phi (fitted once); at alpha_x = alpha_y the view-frame M does not (the lobe is isotropic: fitted at
phi = 0, where the sampler's rotation is exact, and turned by R_z(phi), so the slice is the isotropic fit at every
phi, not up to the rotation's rounding, which matters at alpha = 1e-4). The alpha x lambda table (alpha_y = alpha
lambda <= alpha_x) needs no swap.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import warp as wp

from ..edge import COS_EPS
from ..runtime.warp_runtime import MODULE_OPTIONS
from ..terms import masking, ndf
from ..terms.frame import reflect
from . import fit
from .aniso_grid import (  # noqa: F401 - aniso's names too
    ALPHA_FLOOR,
    FRAMES,
    MAGNITUDE_SAMPLES,
    PARAMETRISATIONS,
    THETA_SCALE,
    Grid4,
    fitted_texels,
)
from .lobes import Lobe, half_vector, pdf_reflected_ndf, smith_f_cos

wp.set_module_options(MODULE_OPTIONS)

TILE = 64  # texels a fit call takes (fixed: the table's bits do not depend on the worker count)


@wp.func
def to_tangent(x: wp.vec3, c: float, s: float):
    """The view-frame direction x in the tangent frame: R_z(phi) x, (c, s) = (cos phi, sin phi)."""
    return wp.vec3(c * x[0] - s * x[1], s * x[0] + c * x[1], x[2])


@wp.func
def aniso_f_pdf(v: wp.vec3, l: wp.vec3, ax: float, tab: wp.array3d(dtype=float), t: int):
    """(f (n.l), the sampler's density) of anisotropic GGX at texel t, v and l in the view frame, tab[t, 0] =
    (alpha_y, cos phi, sin phi). D at the upper-hemisphere mirror of h (lutbake.ltc.lobes.D_ggx_abs: only the
    density sees n.h < 0)."""
    ay = tab[t, 0, 0]
    c = tab[t, 0, 1]
    s = tab[t, 0, 2]
    vt = to_tangent(v, c, s)
    lt = to_tangent(l, c, s)
    h = half_vector(vt, lt)
    d = ndf.D_ggx_aniso(wp.vec3(h[0], h[1], wp.abs(h[2])), ax, ay)
    lam_v = masking.Lambda_ggx_aniso(vt, ax, ay)
    f = 0.0
    if lt[2] > COS_EPS:
        f = smith_f_cos(d, lam_v, masking.Lambda_ggx_aniso(lt, ax, ay), vt[2], lt[2])
    return wp.vec2(f, pdf_reflected_ndf(d, h, vt))


@wp.func
def aniso_f_cos(v: wp.vec3, l: wp.vec3, ax: float, tab: wp.array3d(dtype=float), t: int):
    return aniso_f_pdf(v, l, ax, tab, t)[0]


@wp.func
def aniso_pdf(v: wp.vec3, l: wp.vec3, ax: float, tab: wp.array3d(dtype=float), t: int):
    return aniso_f_pdf(v, l, ax, tab, t)[1]


@wp.func
def aniso_sample(v: wp.vec3, ax: float, u1: float, u2: float):
    """Not used: the fit calls aniso_sample_at (the sampler needs the texel's table)."""
    return v


def needs_texel_table(v, alpha, device, workers):
    raise ValueError("the ggx_aniso lobe reads (alpha_y, cos phi, sin phi) per texel: pass fit.Problem(tab=...)")


LOBES = {
    frame: Lobe(
        "ggx_aniso" if frame == "average" else "ggx_aniso_free",
        aniso_f_cos,
        aniso_sample,
        aniso_pdf,
        aniso_f_pdf,
        "aniso",
        "alpha",
        needs_texel_table,
        free_frame=frame == "free",
        general_frame=True,
    )
    for frame in ("average", "free")
}


@wp.func
def sample_ndf_aniso(v: wp.vec3, ax: float, ay: float, c: float, s: float, u1: float, u2: float):
    """l = reflect(v, h), h of the anisotropic GGX NDF (module docstring) turned into the view frame by R_z(-phi)."""
    p = 2.0 * wp.pi * u1
    r = wp.sqrt(u2 / (1.0 - u2))
    cp = wp.cos(p)
    sp = wp.sin(p)
    pc = cp * c - sp * s  # cos(p + phi)
    ps = sp * c + cp * s  # sin(p + phi)
    ht = wp.normalize(wp.vec3(ax * r * pc, ay * r * ps, 1.0))
    h = wp.vec3(c * ht[0] + s * ht[1], c * ht[1] - s * ht[0], ht[2])
    return reflect(v, h)


@wp.kernel(enable_backward=False)
def aniso_lobe_samples(x: fit.Texels, grid: wp.array(dtype=wp.vec2), out: fit.LobeSamples):
    """fit.kernels' lobe_samples with the texel's anisotropic sampler."""
    i, k = wp.tid()
    vi = x.v[i]
    ax = x.alpha[i]
    u = grid[k]
    l = sample_ndf_aniso(vi, ax, x.tab[i, 0, 0], x.tab[i, 0, 1], x.tab[i, 0, 2], u[0], u[1])
    out.dirs[i, k] = wp.vec3d(wp.float64(l[0]), wp.float64(l[1]), wp.float64(l[2]))
    fp = aniso_f_pdf(vi, l, ax, x.tab, i)
    out.f[i, k] = wp.float64(fp[0])
    out.p[i, k] = wp.float64(fp[1])


class AnisoProblem(fit.Problem):
    """fit.Problem of the ggx_aniso lobe at texels (n.v, alpha_x, alpha_y, phi): the lobe samples drawn by the
    anisotropic NDF sampler (aniso_lobe_samples), then the frames and ∫ f^3 from them as fit.Problem does."""

    def __init__(self, nov, ax, ay, phi, magnitude, n_grid=fit.LTC_FIT_GRID, device="cpu", frame: str = "free"):
        ax32, ay32 = np.asarray(ax, np.float32), np.asarray(ay, np.float32)
        phi = np.asarray(phi, np.float64)
        tab = np.stack([ay32, np.cos(phi).astype(np.float32), np.sin(phi).astype(np.float32)], axis=1)[:, None, :]
        symmetric = (ax32 == ay32) | (np.sin(phi) == 0.0) | (np.cos(phi) < 1e-12)
        self.phi, self.alpha_y = phi, ay32
        super().__init__(
            LOBES[frame], nov, ax32, magnitude, n_grid, device, tab=np.ascontiguousarray(tab), symmetric=symmetric
        )
        s = self.grid_n**2
        grid = wp.array(fit.stratified_grid(self.grid_n), dtype=wp.vec2, device=device)
        wp.launch(aniso_lobe_samples, dim=(self.n, s), inputs=[self._texels, grid, self._lobe], device=device)
        dirs, f, p = self.lobe_sample_arrays(slice(None))
        w = np.where(p > 0.0, f / np.where(p > 0.0, p, 1.0), 0.0)
        self.f3 = np.sum(f * f * w, axis=1) / s
        self.frame_z = self._frames(np.einsum("ts,tsk->tk", w, dirs))


def tangent_angle(problem: AnisoProblem, texel: np.ndarray) -> np.ndarray:
    """psi of the tangent T (view frame: (cos phi, -sin phi, 0)) projected on the plane of the frame (X0, Y0)."""
    z = problem.frame_z[texel]
    x0, y0 = fit.frame_of(z)
    t = np.stack([np.cos(problem.phi[texel]), -np.sin(problem.phi[texel]), np.zeros(len(z))], axis=1)
    return np.arctan2(np.einsum("ij,ij->i", t, y0), np.einsum("ij,ij->i", t, x0))


def guesses(problem: AnisoProblem, texel: np.ndarray) -> np.ndarray:
    """Starting points (k, 5, 5): fit.analytic_guesses at alpha_x (isotropic, no skew), and lobes stretched along the
    tangent (scales 2 alpha_x, 2 alpha_y and alpha_x, alpha_y, psi = the tangent's angle)."""
    iso = fit.analytic_guesses(problem, texel)
    ax = np.maximum(problem.alpha[texel].astype(np.float64), 1e-4)
    ay = np.maximum(problem.alpha_y[texel].astype(np.float64), 1e-4)
    psi, z = tangent_angle(problem, texel), np.zeros(len(texel))
    tilt = [z] * (problem.dof - 5)
    stretched = [np.stack([np.log(s * ax), np.log(s * ay), z, z, psi, *tilt], axis=1) for s in (2.0, 1.0)]
    return np.concatenate([iso, np.stack(stretched, axis=1)], axis=1)


def canonical(m: np.ndarray) -> np.ndarray:
    """The representative M R_z(b) of an LTC closest to the identity in the Frobenius norm (max tr(M R_z(b)): b =
    atan2(m01 - m10, m00 + m11)), scaled so that |M e_z| = 1 (the paper's normalisation, npy_to_cpp.py). The paper
    aligns by a search over b and four flips against cosine samples (its "killing rotation"), to the same end: M that
    interpolate between texels."""
    b = np.arctan2(m[:, 0, 1] - m[:, 1, 0], m[:, 0, 0] + m[:, 1, 1])
    r = np.zeros_like(m)
    r[:, 0, 0] = r[:, 1, 1] = np.cos(b)
    r[:, 0, 1], r[:, 1, 0] = -np.sin(b), np.sin(b)
    r[:, 2, 2] = 1.0
    out = m @ r
    return out / np.linalg.norm(out[:, :, 2], axis=1)[:, None, None]


def rotate_z(m: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """R_z(phi) M (k, 3, 3): a view-frame M in the tangent frame."""
    c, s = np.cos(phi), np.sin(phi)
    r = np.zeros_like(m)
    r[:, 0, 0] = r[:, 1, 1] = c
    r[:, 0, 1], r[:, 1, 0] = -s, s
    r[:, 2, 2] = 1.0
    return r @ m


def fit_tile(nov, ax, ay, phi, magnitude, n_grid: int, device: str, frame: str) -> tuple[np.ndarray, ...]:
    """Fit one tile of texels: Nelder-Mead from the best of guesses() at lutbake.ltc.fit's COARSE_STEPS (0.5, 0.1,
    0.02), in the parameters the texel's lobe has (a symmetric one: ltc_code's (log m11, log m22, m13 / m11) and, frame
    "free", the frame angle d1: the isotropic fit's own space, no idle directions in its simplex). Returns (view-frame
    M (k, 3, 3), Heitz's E, the relative error (E / ∫ f^3)^(1/3))."""
    p = AnisoProblem(nov, ax, ay, phi, magnitude, n_grid, device, frame)
    q, e = np.zeros((p.n, p.dof)), np.zeros(p.n)
    for symmetric in (True, False):
        t = np.flatnonzero(p.symmetric == symmetric)
        if len(t) == 0:
            continue
        dims = ([0, 1, 2] + [5] * (p.dof == 7)) if symmetric else list(range(p.dof))

        def fun(tt, qr, dims=dims):
            full = np.zeros((len(qr), p.dof))
            full[:, dims] = qr
            return p.objective(tt, full)

        cands = guesses(p, t)[:, :, dims]
        f = fun(np.repeat(t, cands.shape[1]), cands.reshape(-1, len(dims))).reshape(len(t), -1)
        best = np.argmin(f, axis=1)
        qr, fr = cands[np.arange(len(t)), best], f[np.arange(len(t)), best]
        for step in fit.COARSE_STEPS:
            qr, fr = fit.nelder_mead(fun, t, qr, step, atol=fit.ATOL_RELATIVE**3 * p.f3[t], f_start=fr)
        q[np.ix_(t, dims)], e[t] = qr, fr
    texel = np.arange(p.n)
    return p.matrices(texel, q), e, p.relative(texel, e)


def fit_table(grid: Grid4, magnitude, n_grid=fit.LTC_FIT_GRID, device="cpu", workers=1, frame: str = "free"):
    """The tangent-frame, canonical M (n_a, n_b, n_theta, n_phi, 3, 3) and the relative fit error of every texel:
    fitted_texels in tiles of TILE (threads: ``workers``; each texel's fit reads only its own inputs, so the bits do
    not depend on the worker count), the others by the symmetries."""
    args = fitted_inputs(grid, magnitude)
    out = in_tiles(lambda t: fit_tile(*(a[t] for a in args), n_grid, device, frame), len(args[0]), workers)
    return completed(grid, np.concatenate([o[0] for o in out]), np.concatenate([o[2] for o in out]))


def fitted_inputs(grid: Grid4, magnitude: np.ndarray) -> tuple[np.ndarray, ...]:
    """(n.v float32, alpha_x, alpha_y, phi, magnitude) of the fitted_texels, in their order."""
    ax2, ay2 = grid.alphas()
    _, _, theta, phi = grid.axes()
    todo = fitted_texels(grid)
    i, j, k, m = np.indices(grid.n).reshape(4, -1)[:, todo]
    return np.cos(theta[k]).astype(np.float32), ax2[i, j], ay2[i, j], phi[m], magnitude.reshape(-1)[todo]


def in_tiles(run, n: int, workers: int) -> list:
    """run(slice) over [0, n) in tiles of TILE on ``workers`` threads, in order (tiles fixed: the same bits for any
    worker count)."""
    tiles = [slice(s, s + TILE) for s in range(0, n, TILE)]
    with ThreadPoolExecutor(max(1, workers)) as pool:
        return list(pool.map(run, tiles))


def completed(grid: Grid4, mats: np.ndarray, rel: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The table (tangent-frame canonical M, relative error) from the view-frame M and errors of the fitted_texels, the
    other texels by the symmetries (module docstring)."""
    ax2, ay2 = grid.alphas()
    _, _, _, phi = grid.axes()
    i, j, k, m = np.indices(grid.n).reshape(4, -1)[:, fitted_texels(grid)]
    full = np.full((*grid.n, 3, 3), np.nan)
    err = np.full(grid.n, np.nan)
    full[i, j, k, m] = canonical(rotate_z(mats, phi[m]))
    err[i, j, k, m] = rel
    a, b = np.nonzero(ax2 == ay2)  # isotropic: one view-frame M for every phi (fitted at phi = 0)
    for p in range(1, grid.n[3]):
        full[a, b, :, p] = canonical(rotate_z(full[a, b, :, 0].reshape(-1, 3, 3), phi[p])).reshape(len(a), -1, 3, 3)
        err[a, b, :, p] = err[a, b, :, 0]
    full[:, :, 0, :] = full[:, :, 0, :1]  # theta = 0: one M for every phi (tangent frame)
    err[:, :, 0, :] = err[:, :, 0, :1]
    if grid.parametrisation == "alphax_alphay":  # alpha_x < alpha_y: S M(alpha_y, alpha_x, pi/2 - phi) S
        s = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
        lower = ax2 < ay2
        a, b = np.nonzero(lower)
        full[a, b] = s @ full[b, a][:, :, ::-1] @ s
        err[a, b] = err[b, a][:, :, ::-1]
    return full, err


def magnitude_fresnel(
    grid: Grid4,
    samples: int = MAGNITUDE_SAMPLES,
    device: str = "cpu",
    seed: int = 0,
    texels: np.ndarray | None = None,
    estimator: str = "sobol",
):
    """(magnitude, fresnel) (n_a, n_b, n_theta, n_phi), or (k,) at flat ``texels``: ∫ f (n.l) dω and
    ∫ f (1 - v.h)^5 (n.l) dω, F = 1. Texels with
    alpha_x = alpha_y: the isotropic ltc kind's integrals (lutbake.ltc.magnitude: Gauss-Legendre, exact; they do not
    depend on phi); the others: the specular_aniso kind's integrand (lutbake.integrands.anisotropic, the
    ``multiscatter`` channels (Fc, 1)) and estimator at the texel's fixed view azimuth
    (lutbake.sampling.anisotropic.AnisoSobol:
    anisotropic VNDF sampling, weight G2 / G1 <= 1); ``estimator = "sobol_cosine"``: its cosine-weighted l instead (a
    second estimator of the anisotropic texels, independent of the lobe's sampler)."""
    from ..integrands.anisotropic import aniso_integrand
    from ..sampling.anisotropic import AnisoSobol
    from .magnitude import magnitude_fresnel as isotropic

    ax2, ay2 = grid.alphas()
    _, _, theta, phi = grid.axes()
    i, j, k, m = np.indices(grid.n).reshape(4, -1)[:, slice(None) if texels is None else texels]
    nov = np.cos(theta[k]).astype(np.float32)
    ax, ay = ax2[i, j], ay2[i, j]
    mag, fres = np.zeros(len(nov)), np.zeros(len(nov))
    iso = ax == ay
    if iso.any():
        mag[iso], fres[iso] = isotropic("ggx", nov[iso], ax[iso], None, device)
    if (~iso).any():
        est, integrand = AnisoSobol(estimator, samples, seed), aniso_integrand("microfacet", "multiscatter")
        inputs = {"nov": nov[~iso], "alpha_x": ax[~iso], "alpha_y": ay[~iso], "phi_v": phi[m][~iso].astype(np.float32)}
        est.prepare(integrand, device)
        out = est.evaluate(integrand, inputs, device)
        fres[~iso], mag[~iso] = out[:, 0], out[:, 1]
    return (mag.reshape(grid.n), fres.reshape(grid.n)) if texels is None else (mag, fres)


def relative_error_of(grid: Grid4, magnitude: np.ndarray, m: np.ndarray, texels: np.ndarray, n_grid=fit.LTC_FIT_GRID):
    """The relative L3 fit error (E / ∫ f^3)^(1/3) (lutbake.ltc.fit) of tangent-frame matrices ``m`` (k, 3, 3) at flat
    texels ``texels`` of ``grid`` (e.g. the published table's, any scale or orientation of M)."""
    ax2, ay2 = grid.alphas()
    _, _, theta, phi = grid.axes()
    i, j, k, l = np.indices(grid.n).reshape(4, -1)[:, texels]
    p = AnisoProblem(np.cos(theta[k]), ax2[i, j], ay2[i, j], phi[l], magnitude.reshape(-1)[texels], n_grid)
    t = np.arange(p.n)
    return p.relative(t, p.error(t, rotate_z(np.asarray(m, np.float64), -phi[l])))


def quadrant(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(phi folded into [0, pi/2], the reflection F (k, 3, 3) with M(phi) = F M(folded)): the paper's shader
    (Sphere.glsl LtcMatrixAndNormalization): [pi/2, pi): pi - phi, F = diag(-1, 1, 1); [pi, 3pi/2): phi - pi,
    diag(-1, -1, 1); [3pi/2, 2pi): 2pi - phi, diag(1, -1, 1). F changes det M's sign where it reflects: the polygon
    integral takes its orientation from sign(det M)."""
    p = np.mod(phi, 2.0 * np.pi)
    q = np.minimum((p // (np.pi / 2)).astype(int), 3)
    folded = np.choose(q, [p, np.pi - p, p - np.pi, 2.0 * np.pi - p])
    signs = np.array([[1.0, 1.0, 1.0], [-1.0, 1.0, 1.0], [-1.0, -1.0, 1.0], [1.0, -1.0, 1.0]])[q]
    return folded, signs[:, :, None] * np.eye(3)


def corner_weights(u: np.ndarray, n) -> tuple[np.ndarray, np.ndarray]:
    """The quadrilinear interpolation of a table of endpoint texels n (4,) at table coordinates u (k, 4) in [0, 1]
    (clamped): the 16 corner texels' indices (k, 16, 4) and weights (k, 16), corners in np.ndindex(2, 2, 2, 2) order
    (the shader's: docs/shaders/ltc_aniso.glsl)."""
    s = np.clip(u, 0.0, 1.0) * (np.array(n) - 1)
    lo = np.minimum(np.floor(s).astype(int), np.array(n) - 2)
    w = s - lo
    corners = np.array(list(np.ndindex(2, 2, 2, 2)))
    weight = np.prod(np.where(corners[None], w[:, None, :], 1.0 - w[:, None, :]), axis=2)
    return lo[:, None, :] + corners[None], weight


def lookup(table: np.ndarray, grid: Grid4, ax, ay, theta, phi, extra: np.ndarray | None = None):
    """The shader's reconstruction (docs/shaders/ltc_aniso.glsl) on the host: the paper's quadrilinear interpolation
    of M (and of ``extra`` (n_a, n_b, n_theta, n_phi, c): magnitude, fresnel) at endpoint texel coordinates
    u = (a, b, theta / (0.9999 pi / 2), phi / (pi / 2)) * (n - 1), phi folded by ``quadrant``, alpha_x < alpha_y of an
    alpha_lambda table by the swap S. Returns (tangent-frame M (k, 3, 3), extra (k, c) or None)."""
    ax, ay, theta, phi = (np.atleast_1d(np.asarray(x, np.float64)) for x in (ax, ay, theta, phi))
    folded, flip = quadrant(phi)
    swap = (ay > ax) if grid.parametrisation == "alpha_lambda" else np.zeros(len(ax), bool)
    a = np.where(swap, ay, ax)
    b = np.where(swap, ax, ay)
    if grid.parametrisation == "alpha_lambda":
        b = b / np.maximum(a, 1e-30)
    folded = np.where(swap, np.pi / 2 - folded, folded)
    u = np.stack([a, b, theta / (THETA_SCALE * np.pi / 2), folded / (np.pi / 2)], axis=1)
    index, weight = corner_weights(u, grid.n)
    flat = np.concatenate([table.reshape(*grid.n, 9), *([] if extra is None else [extra])], axis=-1)
    out = np.zeros((len(a), flat.shape[-1]))
    for c in range(16):
        i = index[:, c]
        out += weight[:, c, None] * flat[i[:, 0], i[:, 1], i[:, 2], i[:, 3]]
    m = out[:, :9].reshape(-1, 3, 3)
    s = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    m = np.where(swap[:, None, None], s @ m @ s, m)
    return flip @ m, (out[:, 9:] if extra is not None else None)


def texture_layout(table: np.ndarray, magnitude: np.ndarray, fresnel: np.ndarray, err: np.ndarray) -> np.ndarray:
    """The shader's textures (docs/shaders/ltc_aniso.glsl): three RGBA 3D textures of width n_phi, height n_theta and
    depth n_a n_b (layer = b + n_b a: the 4th axis packed into the depth, as the paper's Tex3D path), texel (x, y, z) =
    (phi, theta, layer): t0 = (M00, M01, M02, M10), t1 = (M11, M12, M20, M21), t2 = (M22, magnitude, fresnel,
    fit_error); shape (3, n_a n_b, n_theta, n_phi, 4), float32."""
    na, nb, nt, nphi = table.shape[:4]
    m = table.reshape(na, nb, nt, nphi, 9)
    ch = np.concatenate([m, magnitude[..., None], fresnel[..., None], err[..., None]], axis=-1)
    return np.ascontiguousarray(ch.reshape(na * nb, nt, nphi, 3, 4).transpose(3, 0, 1, 2, 4), dtype=np.float32)
