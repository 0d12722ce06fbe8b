"""The shaded fit of anisotropic GGX LTCs (lutbake.ltc.aniso): each texel's general matrix refined to the polygon-light
integrals a shader computes, as lutbake.ltc.shaded refines the isotropic tables' packed M^-1.

At a texel (n.v, alpha_x, alpha_y, phi) the shader shows value(P) = magnitude I_P, I_P the clamped-cosine integral of
the polygon M^-1 P clipped to the horizon (Heitz et al. 2016, Eq. 11; Kt et al. 2022, Sec. 5). With the magnitude
kept at the exact albedo (the kind's channel), the matrix minimises lutbake.ltc.shaded's soft-L1 cost of the
residuals z_j = (magnitude I_j - G_j) / (G_j + c A) over ``shaded.LIGHTS`` training lights per texel
(lutbake.ltc.shaded.texel_lights at the texel's n.v and sqrt(alpha_x alpha_y), in the view frame), G_j the lobe's
integral over light j from the anisotropic sampler's ``shaded.SAMPLES``^2 stratified samples (AnisoProblem's).
Search: Levenberg-Marquardt in the 9 coefficients of the view-frame M^-1 (the integral does not see M^-1's scale: the
damping holds that direction), forward-difference Jacobian, ``ITERATIONS`` steps, float64, from the L3 fit. Each
texel reads its own inputs only: bit-identical for any grouping.
"""

from __future__ import annotations

import numpy as np

from . import aniso, shaded
from .aniso import AnisoProblem

ITERATIONS = 10


def refine_matrices(
    nov, ax, ay, phi, magnitude, m_view: np.ndarray, device: str = "cpu", iterations: int = ITERATIONS
) -> np.ndarray:
    """View-frame M (k, 3, 3) refined from ``m_view`` (the L3 fit's) to the training lights (module docstring)."""
    nov = np.asarray(nov, np.float64)
    k = len(nov)
    a = np.asarray(magnitude, np.float64)
    polys = shaded.texel_lights(nov, np.sqrt(np.asarray(ax, np.float64) * np.asarray(ay, np.float64)))
    sp = AnisoProblem(nov, ax, ay, phi, a, shaded.SAMPLES, device)
    g, _ = shaded.targets(sp, np.arange(k), polys, device)
    sw = 1.0 / np.maximum(g + shaded.ABS_WEIGHT * a[:, None], shaded.TINY)
    local = np.arange(k)

    def residuals(minv: np.ndarray) -> np.ndarray:
        """z (n, L) of n = r k matrices (r blocks of the k texels, in order)."""
        t = np.tile(local, len(minv) // k)
        return (a[t, None] * shaded.integrals(minv.reshape(-1, 3, 3), t, polys, device) - g[t]) * sw[t]

    minv = levenberg_marquardt(np.linalg.inv(m_view).reshape(k, 9), residuals, unit_blocks(1), iterations)
    return np.linalg.inv(minv.reshape(k, 3, 3))


def unit_blocks(lobes: int):
    """x (k, P) -> the same with its first ``lobes`` blocks of 9 coefficients (each lobe's M^-1) scaled to unit
    norm: the polygon integral does not see an M^-1's scale. The coefficients after them are left as they are."""

    def normalise(x: np.ndarray) -> np.ndarray:
        b = x[:, : 9 * lobes].reshape(len(x), lobes, 9)
        out = x.copy()
        out[:, : 9 * lobes] = (b / np.linalg.norm(b, axis=2, keepdims=True)).reshape(len(x), -1)
        return out

    return normalise


def levenberg_marquardt(x: np.ndarray, residuals, normalise, iterations: int) -> np.ndarray:
    """k independent least-squares problems of the soft-L1 cost Σ_j ρ(z_j) (lutbake.ltc.shaded.robust), x (k, P) ->
    z (k, L) = residuals(x); residuals of (r k, P) are r blocks of the k problems, in order. Levenberg-Marquardt with
    the IRLS weights of ρ, forward-difference Jacobian, damping relative to diag(J^T J), each step mapped by
    ``normalise``; a step is kept only where it lowers the problem's cost. Problems are independent: the same bits
    for any grouping."""
    k, n = x.shape
    x = normalise(x)
    z = residuals(x)
    cost = np.sum(shaded.robust(z), axis=1)
    lam = np.full(k, shaded.LAMBDA0)
    eye = np.eye(n)
    for _ in range(iterations):
        so = np.sqrt(shaded.robust_weight(z))
        h = shaded.FD_STEP * np.maximum(np.abs(x), 1.0)
        trials = x[:, None, :] + h[:, :, None] * eye[None]  # (k, n trials, n)
        zt = residuals(trials.transpose(1, 0, 2).reshape(-1, n)).reshape(n, k, -1)
        jac = ((zt - z[None]) / h.T[:, :, None]).transpose(1, 2, 0) * so[:, :, None]  # (k, L, n)
        jtj = np.einsum("kla,klb->kab", jac, jac)
        jtr = np.einsum("kla,kl->ka", jac, z * so)
        d = np.einsum("kaa->ka", jtj).copy()
        d[d <= 0.0] = 1.0
        step = -np.linalg.solve(jtj + lam[:, None, None] * d[:, :, None] * eye[None], jtr[:, :, None])[..., 0]
        cand = normalise(x + step)
        z_new = residuals(cand)
        c_new = np.sum(shaded.robust(z_new), axis=1)
        ok = np.isfinite(c_new) & (c_new < cost)
        x[ok], z[ok], cost[ok] = cand[ok], z_new[ok], c_new[ok]
        lam = np.where(ok, lam / 3.0, lam * 4.0)
    return x


def refine_table(
    grid: aniso.Grid4, magnitude, table: np.ndarray, n_grid: int, device="cpu", workers=1, iterations=ITERATIONS
):
    """lutbake.ltc.aniso.fit_table's (M, relative L3 error) with every fitted texel's M refined from ``table`` (the
    L3 fit) by refine_matrices, in aniso's fixed tiles (the same bits for any worker count); the error channel is the
    refined M's L3 error (metric grid ``n_grid``); the other texels by the symmetries (aniso.completed)."""
    nov, ax, ay, phi, mag = aniso.fitted_inputs(grid, magnitude)
    m_view = aniso.rotate_z(table.reshape(-1, 3, 3)[aniso.fitted_texels(grid)], -phi)

    def run(t):
        m = refine_matrices(nov[t], ax[t], ay[t], phi[t], mag[t], m_view[t], device, iterations)
        p = AnisoProblem(nov[t], ax[t], ay[t], phi[t], mag[t], n_grid, device)
        texel = np.arange(p.n)
        return m, p.relative(texel, p.error(texel, m))

    out = aniso.in_tiles(run, len(nov), workers)
    return aniso.completed(grid, np.concatenate([o[0] for o in out]), np.concatenate([o[1] for o in out]))
