"""The dielectric kinds' estimators (lutbake.kinds.dielectric declares which): the panelled Gauss-Legendre of
lutbake.sampling.dielectric or a QMC estimator of lutbake.sampling.hemisphere, seen through a layout's channels
(lutbake.layouts.base.Layout.stored: the integrals (E_R, E_T, third channel) -> the stored values, their error bounds
by the triangle inequality), to the tolerance that format / dtype set (lutbake.tolerance).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

import numpy as np

from ..tolerance import tolerance_of

# the glass kinds' budgets per estimator (lutbake.sampling.hemisphere.estimator_for takes them)
GLASS_SAMPLES = {"gauss_legendre": 3 * 12**2, "sobol_vndf": 1 << 14, "sobol_ndf": 1 << 16, "hammersley_ndf": 1 << 16}


def estimator_of(name: str, samples: int | None = None, seed: int = 0, merged: bool = False, members: bool = True):
    """The dielectric kinds' estimator ``name`` (lutbake.sampling.hemisphere.estimator_for at GLASS_SAMPLES): the
    panelled Gauss-Legendre of lutbake.sampling.dielectric (``merged``: its NDF-peak breakpoints merged; ``members``:
    texels that differ only in eta >= 1 in groups), or a QMC estimator of lutbake.sampling.hemisphere (the same
    half-vector measure)."""
    from .dielectric import DielectricGaussLegendre
    from .hemisphere import estimator_for

    glass = functools.partial(DielectricGaussLegendre, merged=merged, members=members)
    return estimator_for(name, samples, seed, defaults=GLASS_SAMPLES, gauss_legendre=glass)


def kernel_tolerance(layout, tol) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(absolute, relative) per kernel channel such that every channel of ``layout`` (a Layout record) meets ``tol``
    (lutbake.tolerance.Tolerance) through its ``stored`` map: the layout's own rule, else the tolerance on each."""
    if layout.kernel_tolerance is not None:
        return layout.kernel_tolerance(tol)
    a, r = tol.absolute, tol.relative
    return (a, a, a), (r, r, r)


@dataclass(frozen=True)
class LayoutChannels:
    """An estimator whose values pass through ``layout.stored`` (its refinement too)."""

    inner: object
    layout: object

    @property
    def name(self) -> str:
        return self.inner.name

    def samples(self, inputs: dict) -> np.ndarray:
        return self.inner.samples(inputs)

    def prepare(self, integrand, device: str) -> None:
        self.inner.prepare(integrand, device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        return self.layout.stored(self.inner.evaluate(integrand, inputs, device))

    def refined(self):
        inner, how = self.inner.refined()
        return LayoutChannels(inner, self.layout), how


@dataclass(frozen=True)
class LayoutChannelsAdaptive(LayoutChannels):
    """LayoutChannels of lutbake.sampling.dielectric.DielectricAdaptive: ``absolute`` / ``relative``, the table's
    tolerance (its channels); the inner estimator holds kernel_tolerance's per kernel channel."""

    absolute: float = 0.0
    relative: float = 0.0

    def evaluate_with_error(self, integrand, inputs: dict, device: str) -> tuple[np.ndarray, np.ndarray]:
        values, err = self.inner.evaluate_with_error(integrand, inputs, device)
        return self.layout.stored(values), self.layout.stored_error(err)

    def refined(self):
        inner, how = self.inner.refined()
        return replace(self, inner=inner, absolute=self.absolute / 100, relative=self.relative / 100), how


def layout_estimator(o: dict, layout, members: bool = True):
    """The estimator of a ``dielectric`` spec's options ``o`` in ``layout``: to its tolerance (lutbake.tolerance) when
    ``samples`` is unset and the estimator is gauss_legendre, else estimator_of at ``samples``, through the layout's
    channels (``members``: the grid has texels that differ only in eta >= 1, which the gauss_legendre kernels take in
    groups)."""
    if o["estimator"] == "gauss_legendre" and o["samples"] is None:
        from .dielectric import DielectricAdaptive

        tol = tolerance_of(o)
        inner = DielectricAdaptive(*kernel_tolerance(layout, tol), members=members)
        return LayoutChannelsAdaptive(inner, layout, tol.absolute, tol.relative)
    return LayoutChannels(estimator_of(o["estimator"], o["samples"], o["seed"], members=members), layout)
