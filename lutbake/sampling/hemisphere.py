"""The hemisphere estimators: integrate a per-texel hemisphere integral with a chosen estimator.

The integral, for a texel with view cosine n.v and NDF alpha, is written over the microfacet
normal h (dω_l = 4 (v.h) dω_h, Walter et al. 2007, Eq. 14):

    I = ∫ f(l, v) (n.l) dω_l = ∫ g(h) dω_h,        g(h) = f(l(h), v) (n.l) 4 (v.h),   l = reflect(v, h)

``integrand(v, h, alpha, param) -> vec`` returns g(h) for every channel (0 where n.l <= 0); ``param`` is a
per-texel scalar the integrand may use (f0 for specular_3d; ignored by the others). Sampling h with
the NDF's density p(h) = D(h)(n.h) gives I = E[g / p]; for a microfacet BRDF D cancels and the
per-sample weight is G2 F (v.h) / ((n.v)(n.h)).

Estimators (``GaussLegendre``, ``AdaptiveGaussLegendre``, ``QuasiMonteCarlo``: objects of the lutbake.sampling.plan
protocol; their kernels come from lutbake.sampling.hemisphere_kernels, which close over an integrand record of
lutbake.integrands.specular):

``gauss_legendre``  (the default) deterministic product Gauss-Legendre after the NDF's change of
    variables u = CDF(theta_h), phi uniform, over the horizon-split domain (lutbake.sampling.horizon: region A, where
    every phi is visible, region B, phi in [0, acos c*], each cut into panels graded geometrically in theta_h).
    Integrating each region over its exact domain removes the horizon kink. Each panel is integrated in
    u = CDF(theta) (lutbake.sampling.facet_rules). The sqrt-like ends of acos c* at c* = -1 and 1
    are removed by u = u0 + du smoothstep(s).
    By symmetry in phi,
        I = (1/pi) ∫_0^1 du ∫_0^phimax(u) dphi  g(h) / p(h).
    The integrand is then analytic in both variables and GL converges exponentially. An integrand only C1 along
    n.l = kink (SpecularIntegrand.nol_kink: Charlie's Lambda; kink_at_nov: n.l = n.v, Ashikhmin-Shirley's
    max(n.l, n.v), whose level line passes through h = n at phi = pi/2) gets the same treatment for that level line
    (lutbake.sampling.horizon.kink_band, kink_cos_phi); a Charlie lobe's panels also grade towards theta_b
    (next_toward).
``sobol_ndf`` / ``hammersley_ndf``  h from the NDF's inverse CDF (Distribution.sample_ndf) at scrambled Sobol'
    (or Hammersley) points, weight g / p / N with p = D(h)(n.h) (Distribution.pdf_ndf).
``sobol_vndf`` (GGX) h from the visible-normal distribution (Distribution.sample_vndf),
    p_v(h) = G1(v) max(0, v.h) D(h) / (n.v) (Distribution.pdf_vndf).

``estimator_for`` picks one by name; the glass kinds pass their own budgets and Gauss-Legendre
(lutbake.sampling.dielectric_layout).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import warp as wp

from ..records import HEMISPHERE_ESTIMATOR
from . import points
from .hemisphere_kernels import _launch, gl_kernel, gl_launch, load, qmc_kernel
from .rules import ADAPTIVE_ORDERS

DEFAULT_SAMPLES = {"gauss_legendre": 432, "sobol_vndf": 4096, "sobol_ndf": 4096, "hammersley_ndf": 1024}


def gl_order(samples: int) -> int:
    """GL points per dimension n for a nominal budget of ``samples`` evaluations per texel: 3 regions x n x n
    (A and B's two halves; grazing texels get more panels, up to 2 log4(pi / (4 theta_a)) + 1)."""
    return max(2, int(round(np.sqrt(samples / 3.0))))


# the method text's note (lutbake.sampling.plan): what a panel's difference is in the product ladder
PRODUCT_NOTE = (
    ", per panel its outer and its inner rule's, each at the other's order (the outer one at least the difference "
    "to order 8 and its geometric tail: lutbake.sampling.ladder.product_ladder_for)"
)


@dataclass(frozen=True)
class GaussLegendre:
    """The ``gauss_legendre`` estimator at a nominal budget of ``budget`` evaluations per texel (order gl_order)."""

    budget: int = DEFAULT_SAMPLES["gauss_legendre"]
    name: str = "gauss_legendre"

    @property
    def order(self) -> int:
        return gl_order(self.budget)

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["nov"]), 3 * self.order**2)

    def _kernel(self, integrand):
        """The kernel of this quadrature for ``integrand`` (a subclass may supply another panelling)."""
        return gl_kernel(integrand)

    def prepare(self, integrand, device: str) -> None:
        load(self._kernel(integrand), device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        return gl_launch(integrand, inputs, (self.order,), (0.0, 0.0), device)[0]

    def refined(self):
        n = self.order
        return replace(self, budget=3 * (n + 4) ** 2), f"order {n} - order {n + 4}"


@dataclass(frozen=True)
class AdaptiveGaussLegendre:
    """``gauss_legendre`` to a tolerance: every panel at the first two orders of ADAPTIVE_ORDERS, then the worst panel
    rule (outer or inner) one order up until the texel's estimate is within max(absolute, relative |I|)
    (make_gauss_legendre, the greedy ladder of lutbake.sampling.ladder.product_ladder_for). ``evaluate_with_error``
    also returns each texel's error estimate (the sum over panels of its outer and inner rules' estimates plus
    TERMS_ROUNDING |I|), recorded as the table's lutbake:error_estimate."""

    absolute: float
    relative: float
    orders: tuple[int, ...] = ADAPTIVE_ORDERS
    name: str = "gauss_legendre"
    estimate_note: str = PRODUCT_NOTE

    def samples(self, inputs: dict) -> np.ndarray:  # nominal: 3 panels at the middle order (the work adapts)
        return np.full(len(inputs["nov"]), 3 * self.orders[(len(self.orders) + 1) // 2] ** 2)  # 24: 1728, as before

    def prepare(self, integrand, device: str) -> None:
        load(gl_kernel(integrand), device)

    def evaluate_with_error(self, integrand, inputs: dict, device: str) -> tuple[np.ndarray, np.ndarray]:
        return gl_launch(integrand, inputs, self.orders, (self.absolute, self.relative), device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        return self.evaluate_with_error(integrand, inputs, device)[0]

    def refined(self):
        return replace(self, absolute=self.absolute / 100, relative=self.relative / 100), "tolerance / 100"


@dataclass(frozen=True)
class QuasiMonteCarlo:
    """``sobol_vndf`` / ``sobol_ndf`` (scrambled Sobol' points, n rounded up to a power of two) or
    ``hammersley_ndf``: h drawn from the visible-normal or the NDF density, weight g / p / N."""

    name: str
    budget: int
    seed: int = 0

    def _n(self) -> int:
        if self.name.startswith("sobol"):
            return 1 << int(np.ceil(np.log2(max(self.budget, 1))))
        return self.budget

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["nov"]), self._n())

    def _kernel(self, integrand):
        return qmc_kernel(integrand, self.name == "sobol_vndf")

    def prepare(self, integrand, device: str) -> None:
        load(self._kernel(integrand), device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        pts = points.sobol(self.budget, self.seed) if self.name.startswith("sobol") else points.hammersley(self.budget)
        pts = np.clip(pts, 0.0, np.nextafter(np.float32(1.0), np.float32(0.0))).astype(np.float32)
        w = np.full(len(pts), 1.0 / len(pts))
        arr = [wp.array(pts, dtype=float, device=device), wp.array(w, dtype=wp.float64, device=device)]
        return _launch(self._kernel(integrand), inputs, arr, integrand.kernel_channels, device)

    def refined(self):
        return replace(self, seed=self.seed + 1), "seed - (seed + 1) (two scramblings)"


def estimator_for(
    name: str,
    samples: int | None = None,
    seed: int = 0,
    tolerance=None,
    defaults: dict = DEFAULT_SAMPLES,
    gauss_legendre=GaussLegendre,
):
    """The hemisphere estimator ``name`` (lutbake.records.HEMISPHERE_ESTIMATOR) at ``samples`` per texel (None: its
    default in ``defaults``). gauss_legendre without ``samples`` but with a ``tolerance`` (lutbake.tolerance.Tolerance)
    adapts its order to it; else it is ``gauss_legendre(budget)`` (the glass kinds pass their own:
    lutbake.sampling.dielectric_layout.estimator_of)."""
    budget = samples or defaults[name]
    if name == "gauss_legendre" and samples is None and tolerance is not None:
        return AdaptiveGaussLegendre(tolerance.absolute, tolerance.relative)
    if name == "gauss_legendre":
        return gauss_legendre(budget)
    if name in HEMISPHERE_ESTIMATOR:
        return QuasiMonteCarlo(name, budget, seed)
    raise KeyError(name)
