"""Kinds ``diffuse`` / ``diffuse_3d`` to a tolerance: the adaptive swapped integral's per-texel error estimate bounds
the measured error.

The estimate (lutbake.sampling.swapped.swapped_adaptive_kernel) is the sum over u panels of |Q(order k) -
Q(order k-1)| plus TERMS_ROUNDING |E|. It is held against (1) the same integrand at fixed order 32 on every texel of
a 16^2 grid with its grazing column (converged: order 32 and 48 differ by < 3e-11 there) for the Eq. 6 and the exact
dielectric facet forms, and (2) the independent nested rule (l outside, m inside: lutbake.sampling.diffuse at GL
order 24) at a looser tolerance, where that rule's own error (< 1e-7 at these texels) is far below it.
"""

import numpy as np
import pytest

from lutbake.axes import sigma_alpha
from lutbake.edge import effective_alpha
from lutbake.integrands import diffuse as D
from lutbake.sampling.swapped import integrate_swapped, integrate_swapped_adaptive

REFERENCE_NOISE = 1.0e-10  # order 32 against order 48 on the grid below: < 3e-11
NESTED_NOISE = 2.0e-7  # the nested rule at order 24 against the swapped one at order 48 (measured: < 7e-8)
CONVERGED_ORDER = 32
N = 16


def _grid():
    nov = np.tile(np.concatenate([[1.0 / 128], (np.arange(1, N) + 0.5) / N]), N)  # with a grazing column
    sigma = np.repeat((np.arange(N) + 0.5) / N, N)
    return nov, sigma, effective_alpha(sigma_alpha(sigma.astype(np.float32), "sigma"), False).astype(np.float64)


@pytest.mark.parametrize("facet, f0", [("eq6", 0.0), ("dielectric_f0", 0.5)])
@pytest.mark.parametrize("tol", [(1.0e-6, 0.0), (0.25 / 65535, 0.0), (1.5e-8, 2.0**-13)])
def test_error_estimate_bounds_error_on_every_texel_of_a_grid(facet, f0, tol):
    integrand = D.diffuse_integrand("microfacet", facet)
    nov, _, alpha = _grid()
    ref = integrate_swapped(integrand, nov, alpha, f0, orders=np.full((len(nov), 3), CONVERGED_ORDER))
    got, est = integrate_swapped_adaptive(integrand, nov, alpha, f0, tol)
    err = np.abs(got - ref)
    print(f"{facet} tol {tol}: max error {err.max():.3e}, max estimate {est.max():.3e}")
    assert np.all(err <= est + REFERENCE_NOISE)
    assert np.all(est <= np.maximum(tol[0], tol[1] * np.abs(got)))  # every texel met its tolerance


def test_error_estimate_bounds_error_against_the_nested_rule():
    nov = np.array([1.0 / 128, 0.05, 0.2, 0.5, 0.9, 1.0], np.float32)
    sigma = np.array([0.5, 0.05, 0.5, 0.3, 1.0, 0.1], np.float32)
    alpha = effective_alpha(sigma_alpha(sigma, "sigma"), False).astype(np.float64)
    nested = D.albedo_gl("microfacet", nov, sigma, 0.04, "eq6", "sigma", order=24)
    got, est = integrate_swapped_adaptive(D.diffuse_integrand("microfacet", "eq6"), nov, alpha, 0.04, (1e-4, 0.0))
    assert np.all(np.abs(got - nested) <= est + NESTED_NOISE)
    assert np.all(est <= 1e-4)
