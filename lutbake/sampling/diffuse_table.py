"""The diffuse albedo tables' estimator and per-texel inputs (kinds ``diffuse``, ``diffuse_3d`` and the ltc kind's
diffuse lobes, lutbake.ltc.magnitude): which quadrature of lutbake.sampling integrates a model at which order, and
the grid's inputs (nov, sigma, its GGX alpha under lutbake.edge's policy, f0)."""

from __future__ import annotations

import numpy as np

from ..axes import Axis, sigma_alpha
from ..edge import effective_alpha
from .plan import Grid

DEFAULT_ORDER = {"microfacet": 12}  # base GL order (lutbake.sampling.swapped); closed forms: CLOSED_ORDER
CLOSED_ORDER = 24
DEFAULT_COSINE_SAMPLES = 4096


def order_for(o: dict) -> int:
    """The GL order of the table (the inner m-rule's order for sobol_cosine)."""
    if o["estimator"] == "gauss_legendre" and o["samples"]:
        return o["samples"]
    return DEFAULT_ORDER.get(o["model"], CLOSED_ORDER)


def estimator_of(o: dict, members: int = 1):
    """gauss_legendre: the swapped integral for the microfacet model (``members``: its f0 groups, kind diffuse_3d),
    the 2 x 2-panel rule over l otherwise; sobol_cosine: cosine-weighted Sobol' directions l
    (lutbake.sampling.diffuse)."""
    from .diffuse import CosineSobol, DiffuseGaussLegendre
    from .swapped import SwappedGaussLegendre

    order = order_for(o)
    if o["estimator"] == "sobol_cosine":
        return CosineSobol(o["samples"] or DEFAULT_COSINE_SAMPLES, o["seed"], inner_order=order)
    if o["model"] == "microfacet":
        return SwappedGaussLegendre(order, members=members)
    return DiffuseGaussLegendre(order)


def diffuse_grid(axes: list[Axis], nov, sigma, f0, sigma_to_alpha: str) -> Grid:
    """Per-texel inputs of a diffuse albedo table: nov, sigma, alpha (GGX alpha of sigma, lutbake.edge policy:
    clamped, no mirror limit) and f0."""
    alpha = sigma_alpha(sigma, sigma_to_alpha)
    return Grid(
        axes,
        {"nov": nov, "sigma": sigma, "alpha": effective_alpha(alpha, False), "f0": np.asarray(f0, np.float64)},
        grazing=nov,
        alpha=alpha.astype(np.float64),
    )
