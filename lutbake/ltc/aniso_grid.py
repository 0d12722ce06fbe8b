"""The anisotropic GGX LTC table's grid (Kt, Heitz, Dupuy & Narayanan 2022; lutbake.ltc.aniso), without Warp: the
paper's texels, the parametrisations, the fit's frames and which texels are fitted (the symmetries of
lutbake.ltc.aniso's docstring), for the kind's declaration (lutbake.kinds.ltc_aniso) to read at import."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ALPHA_FLOOR = 1.0e-4  # the paper's texels: alpha = max(i / (n - 1), 1e-4) (fit_alphax_alphay_theta_phi.py)
THETA_SCALE = 0.9999  # the paper's texels: theta = k / (n - 1) * 0.9999 * pi / 2 ("to avoid grazing angle")
PARAMETRISATIONS = {
    "alphax_alphay": "(alpha_x, alpha_y, theta, phi): alpha_x = max(i/(n-1), 1e-4), alpha_y = max(j/(n-1), 1e-4)",
    "alpha_lambda": "(alpha, lambda, theta, phi): alpha_x = max(a, 1e-4), alpha_y = max(a lambda, 1e-4), "
    "a = i/(n-1), lambda = j/(n-1)",
}
FRAMES = {
    "free": "Z tilted from the lobe's average direction too (7 parameters; at alpha_x = alpha_y: the isotropic fit "
    "with ltc_code's frame angle free, lutbake's free_frame)",
    "average": "Z = the lobe's average direction (5 parameters; at alpha_x = alpha_y: ltc_code's M, lutbake's "
    "isotropic ggx fit)",
}
BETWEEN_CONFIGS = 40000  # lobes > 1: training configurations of the fit between the texels (lutbake.ltc.aniso_lobes)
BETWEEN_ITERATIONS = 20  # lobes > 1: its Levenberg-Marquardt steps
SPLIT = (0.85, 1.15)  # three lobes: the narrow lobe's M x diag(s, s, 1) for each s, half its weight each
MAGNITUDE_SAMPLES = 1 << 16  # scrambled Sobol' points per anisotropic texel (bounded weights: spread ~1e-5)


@dataclass(frozen=True)
class Grid4:
    """The paper's texels: axes (a, b, theta, phi) of n_a, n_b, n_theta, n_phi endpoint texels (lutbake.ltc.aniso's
    docstring)."""

    parametrisation: str
    n: tuple[int, int, int, int]
    alpha_min: float = ALPHA_FLOOR  # alpha_x, alpha_y >= alpha_min (the paper: 1e-4)

    def axes(self) -> tuple[np.ndarray, ...]:
        a, b = (np.arange(k) / (k - 1) for k in self.n[:2])
        theta = np.arange(self.n[2]) / (self.n[2] - 1) * THETA_SCALE * np.pi / 2
        phi = np.arange(self.n[3]) / (self.n[3] - 1) * np.pi / 2
        return a, b, theta, phi

    def alphas(self) -> tuple[np.ndarray, np.ndarray]:
        """(alpha_x, alpha_y) float32 (n_a, n_b)."""
        a, b, _, _ = self.axes()
        if self.parametrisation == "alphax_alphay":
            ax, ay = np.meshgrid(a, b, indexing="ij")
        else:
            ax, ay = np.meshgrid(a, b, indexing="ij")
            ay = ax * ay
        return np.maximum(ax, self.alpha_min).astype(np.float32), np.maximum(ay, self.alpha_min).astype(np.float32)


def fitted_texels(grid: Grid4) -> np.ndarray:
    """The texels fitted (flat indices into (n_a, n_b, n_theta, n_phi)): alpha_x >= alpha_y, and phi = 0 alone at
    theta = 0 and at alpha_x = alpha_y (the symmetries of lutbake.ltc.aniso's docstring)."""
    ax, ay = grid.alphas()
    idx = np.indices(grid.n).reshape(4, -1)
    ax, ay = ax[idx[0], idx[1]], ay[idx[0], idx[1]]
    keep = (ax >= ay) & (((idx[2] > 0) & (ax != ay)) | (idx[3] == 0))
    return np.flatnonzero(keep)
