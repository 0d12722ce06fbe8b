"""Quasi-Monte Carlo estimators of the anisotropic split-sum tables (kind specular_aniso), for a lobe record of
lutbake.integrands.anisotropic. Inputs per texel: nov, alpha_x, alpha_y, phi_v (phi_v < 0: averaged).

The view azimuth phi_v (of v about n, from T) is a fourth parameter of an anisotropic lobe; the table averages it
out, E = (1/2 pi) ∫ E(phi_v) dphi_v, with phi_v = 2 pi u3 of scrambled 3D Sobol' points (u1, u2, u3), or fixes it.
- ``sobol`` (``AnisoSobol``, the default): h from the lobe's own sampler, weight = channels(v.h) x the lobe's g / p
  (both bounded by 1, so the QMC error is that of a bounded integrand with a kink at the horizon);
- ``sobol_cosine``: l cosine-weighted (pdf (n.l) / pi), weight = pi channels(v.h) f / F: an independent
  estimator (it does not use the lobe's sampler or its pdf) for cross-checks.
alpha_x = alpha_y = 0 (the lobe's mirror limit, lutbake.edge): E = channels(n.v), no samples.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import warp as wp

from ..edge import COS_EPS
from ..runtime.warp_runtime import kernel_factory, load_module, unique_kernel
from ..terms import ndf
from ..terms.frame import reflect
from . import points
from .arrays import Points2, Rows64, store_row
from .hemisphere import PRODUCT_NOTE, AdaptiveGaussLegendre
from .hemisphere_kernels import gl_launch

DEFAULT_SAMPLES = 16384


@wp.func
def view_at(nov: float, phi_v: float):
    s = wp.sqrt(wp.max(1.0 - nov * nov, 0.0))
    return wp.vec3(s * wp.cos(phi_v), s * wp.sin(phi_v), nov)


@kernel_factory
def aniso_kernel(lobe, cosine: bool):
    """QMC kernel over texels (nov, alpha_x, alpha_y, phi_v; phi_v < 0: averaged) with 3D points (module docstring)."""
    ch, sample, weight, f_cos = lobe.channels, lobe.sample, lobe.weight, lobe.f_cos
    acc_type = wp.vec2d
    nch = 2
    smooth = lobe.mirror

    @unique_kernel
    def aniso_qmc_kernel(texel: wp.array(dtype=wp.vec4), pts: Points2, out: Rows64):
        """texel[i] = (n.v, alpha_x, alpha_y, phi_v)."""
        i = wp.tid()
        nov = texel[i][0]
        ax = texel[i][1]
        ay = texel[i][2]
        nu = ndf.as_exponent(wp.min(ax, 1.0))
        nv = ndf.as_exponent(wp.min(ay, 1.0))
        acc = acc_type()
        n = pts.shape[0]
        m = n
        if wp.static(smooth):
            if ax <= 0.0:  # alpha -> 0: the mirror limit below, no samples
                m = 0
        for k in range(m):
            phi = texel[i][3]
            if phi < 0.0:
                phi = 2.0 * wp.pi * pts[k, 2]
            v = view_at(nov, phi)
            w = 0.0
            h = wp.vec3()
            l = wp.vec3()
            if wp.static(cosine):
                r2 = pts[k, 0]
                pl = 2.0 * wp.pi * pts[k, 1]
                st = wp.sqrt(r2)
                l = wp.vec3(st * wp.cos(pl), st * wp.sin(pl), wp.sqrt(wp.max(1.0 - r2, 0.0)))
                h = wp.normalize(l + v)
            else:
                h = sample(v, ax, ay, nu, nv, pts[k, 0], pts[k, 1])
                l = reflect(v, h)
            VoH = wp.dot(v, h)
            if l[2] > COS_EPS and VoH > COS_EPS and v[2] > COS_EPS:
                if wp.static(cosine):
                    w = wp.pi * f_cos(v, l, h, ax, ay, nu, nv) / l[2]  # f (n.l) / pdf, pdf = (n.l) / pi
                else:
                    w = weight(v, l, ax, ay)
                g = ch(VoH, 0.0) * w
                for c in range(wp.static(nch)):
                    acc[c] = acc[c] + wp.float64(g[c])
        for c in range(wp.static(nch)):
            out[i, c] = acc[c] / wp.float64(n)
        if wp.static(smooth):
            if ax <= 0.0:  # the mirror limit (lutbake.edge)
                store_row(out, i, ch(nov, 0.0))

    return aniso_qmc_kernel


@dataclass(frozen=True)
class AnisoSobol:
    """``sobol`` / ``sobol_cosine`` (module docstring) with ``budget`` points (rounded up to a power of two)."""

    name: str = "sobol"
    budget: int = DEFAULT_SAMPLES
    seed: int = 0

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["nov"]), 1 << int(np.ceil(np.log2(max(self.budget, 1)))))

    def _kernel(self, lobe):
        return aniso_kernel(lobe, self.name == "sobol_cosine")

    def prepare(self, lobe, device: str) -> None:
        load_module(self._kernel(lobe).module, device=device)

    def evaluate(self, lobe, inputs: dict, device: str) -> np.ndarray:
        n = len(inputs["nov"])
        pts = np.clip(points.sobol3(self.budget, self.seed), 0.0, np.nextafter(np.float32(1.0), np.float32(0.0)))
        out = wp.zeros((n, 2), dtype=wp.float64, device=device)
        texel = np.stack([np.asarray(inputs[k], np.float32) for k in ("nov", "alpha_x", "alpha_y", "phi_v")], axis=1)
        wp.launch(
            self._kernel(lobe),
            dim=n,
            inputs=[
                wp.array(np.ascontiguousarray(texel), dtype=wp.vec4, device=device),
                wp.array(pts.astype(np.float32), dtype=float, device=device),
                out,
            ],
            device=device,
        )
        return out.numpy()

    def refined(self):
        return AnisoSobol(self.name, self.budget, self.seed + 1), "seed - (seed + 1) (two scramblings)"


# the share of the tolerance the panel ladder gets; the view-azimuth rule's nested estimate takes the rest (measured:
# <= 5.2e-8 on 64 random texels and the grazing, most anisotropic ones, against a 1e-6 tolerance)
LADDER_SHARE = 0.75


@dataclass(frozen=True)
class AzimuthAveragedGaussLegendre(AdaptiveGaussLegendre):
    """``gauss_legendre`` for the view-azimuth average (lutbake.integrands.anisotropic.averaged_integrand; inputs
    nov, alpha = alpha_min, param = alpha_max) to the tolerance max(absolute, relative |E|): the panel ladder of
    AdaptiveGaussLegendre to LADDER_SHARE of it, and each texel's estimate is the ladder's plus the azimuth rule's
    |Q_M - Q_(M/2)| (the error of the coarser rule: pessimistic for Q_M, exponentially convergent).
    ``azimuth_nodes(alpha_max, alpha_min) -> M`` per texel (the integrand's, in numpy): for the nominal cost only."""

    azimuth_nodes: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None
    estimate_note: str = PRODUCT_NOTE + ", plus the view-azimuth rule's |Q_M - Q_(M/2)|"

    def samples(self, inputs: dict) -> np.ndarray:  # nominal: the lobe evaluations of 3 panels at order 24
        return 3 * 24**2 * self.azimuth_nodes(inputs["param"], inputs["alpha"])

    def evaluate_with_error(self, integrand, inputs: dict, device: str) -> tuple[np.ndarray, np.ndarray]:
        tol = (LADDER_SHARE * self.absolute, LADDER_SHARE * self.relative)
        v, e = gl_launch(integrand, inputs, self.orders, tol, device)
        n = integrand.nch
        return v[:, :n], e[:, :n] + np.abs(v[:, :n] - v[:, n : 2 * n])
