"""The ltc_aniso kind's tile engine (lutbake.kinds.ltc_aniso): one bake of the anisotropic GGX LTC table (Kt, Heitz,
Dupuy & Narayanan 2022; lutbake.ltc.aniso), shared by its tiles.

The whole 4D table is one computation (the symmetries fill the texels not fitted from the ones fitted, across tiles):
the magnitudes (lutbake.ltc.aniso.magnitude_fresnel) and the fit (lutbake.ltc.aniso.fit_table, in tiles of
aniso.TILE texels on a thread pool: the bits do not depend on the thread count) run once, under a lock, the first
time a tile is asked for; every tile then reads its rows of lutbake.ltc.aniso.texture_layout, the three RGBA 3D
textures (K lobes: 3 K, lutbake.ltc.aniso_lobes.lobe_textures) flattened (texture, layer, theta, phi)
row-major, which is the table's texel order.
"""

from __future__ import annotations

import os
import threading

import numpy as np

from . import aniso
from .aniso_grid import BETWEEN_CONFIGS, BETWEEN_ITERATIONS

PROBE = 64  # anisotropic texels (strided) whose magnitude a second scrambling re-estimates


def available_threads() -> int:
    """The cores this process may run on (the fit's thread pool; its values do not depend on the count)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


class AnisoBake:
    """The state one ltc_aniso bake shares between its tiles: ``grid`` (aniso.Grid4), the fit's frame and metric grid,
    the magnitude's Sobol' budget and seed, ``shaded``: the L3 fit refined to polygon lights (lutbake.ltc.aniso_shaded);
    ``lobes`` 2 or 3: then two lobes fitted per texel and ``between`` = (training configurations, steps) between the
    texels, three split from two (lutbake.ltc.aniso_lobes). ``texels()``: the (3 lobes n_a n_b n_theta n_phi, 4) float64
    texels, computed once; ``matrices`` (the one-lobe M in the paper's layout, (n_a, n_b, n_theta, n_phi, 3, 3)) after
    it."""

    def __init__(
        self,
        grid: aniso.Grid4,
        frame: str,
        fit_samples: int,
        samples: int,
        seed: int,
        shaded=False,
        estimator: str = "sobol",
        lobes: int = 1,
        between: tuple[int, int] = (BETWEEN_CONFIGS, BETWEEN_ITERATIONS),
    ):
        self.grid, self.frame, self.fit_samples, self.shaded = grid, frame, fit_samples, shaded
        self.estimator, self.lobes, self.between = estimator, lobes, between
        self.samples, self.seed = samples, seed
        self._lock = threading.Lock()
        self._flat = None
        self.matrices = None
        self.spread = None

    def magnitude_spread(self, device: str) -> dict:
        """The magnitude's QMC error estimate: max |difference| of magnitude and fresnel between the seed's and the
        next scrambling at up to PROBE anisotropic texels (strided; the points are shared by every texel, so a texel's
        value does not depend on the others evaluated). A spread, not a bound (docs/estimators.md)."""
        ax, ay = self.grid.alphas()
        i, j = np.indices(self.grid.n).reshape(4, -1)[:2]
        aniso_texels = np.flatnonzero(ax[i, j] != ay[i, j])
        if len(aniso_texels) == 0:
            return {"texels": 0, "max_abs": 0.0}
        probe = aniso_texels[:: max(1, len(aniso_texels) // PROBE)][:PROBE]
        one, two = (
            aniso.magnitude_fresnel(self.grid, self.samples, device, seed, probe, self.estimator)
            for seed in (self.seed, self.seed + 1)
        )
        diff = max(float(np.max(np.abs(a - b))) for a, b in zip(one, two))
        return {"texels": int(len(probe)), "seeds": [self.seed, self.seed + 1], "max_abs": diff}

    def prepare(self, device: str) -> None:
        """Load the kernels the bake launches (the first tile computes the table: lutbake.runtime calls this before
        its threads start, so the magnitude and the fit run here once)."""
        self.texels(device)

    def texels(self, device: str) -> np.ndarray:
        with self._lock:
            if self._flat is None:
                g = self.grid
                mag, fres = aniso.magnitude_fresnel(g, self.samples, device, self.seed, estimator=self.estimator)
                m, err = aniso.fit_table(g, mag, self.fit_samples, device, available_threads(), self.frame)
                if self.shaded:
                    from .aniso_shaded import refine_table

                    m, err = refine_table(g, mag, m, self.fit_samples, device, available_threads())
                if self.lobes > 1:
                    from . import aniso_lobes

                    per_texel = aniso_lobes.per_texel_table(g, mag, m, 2, available_threads())
                    lm, lw = aniso_lobes.between_table(g, mag, per_texel, *self.between, lobes=self.lobes)
                    tex = aniso_lobes.lobe_textures(g, mag, fres, lm, lw).astype(np.float64)
                else:
                    tex = aniso.texture_layout(m, mag, fres, err).astype(np.float64)
                if not np.all(np.isfinite(tex)):
                    raise ValueError("ltc_aniso: a texel of the fit is not finite")
                self.matrices = m
                self.spread = self.magnitude_spread(device)
                self._flat = tex.reshape(-1, 4)
        return self._flat

    def run_tile(self, start: int, stop: int, device: str) -> np.ndarray:
        return self.texels(device)[start:stop].copy()
