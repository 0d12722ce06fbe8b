"""The host-side rules of the gauss_legendre kernel (lutbake.sampling.hemisphere): region A's tabulated inner rule
(phi_rule_a) is a quadrature over [0, pi] that integrates smooth periodic functions, and gl_levels lays the orders
out as the kernel reads them."""

import numpy as np
import pytest

from lutbake.sampling import points
from lutbake.sampling.hemisphere import ADAPTIVE_ORDERS, gl_levels, phi_rule_a

RULE_TOLERANCE = 1e-12  # order 24 on an entire function: exact to rounding


@pytest.mark.parametrize(
    "f, exact",
    [
        (lambda c, s: np.ones_like(c), np.pi),
        (lambda c, s: (1.0 + c) ** 2, 1.5 * np.pi),  # ∫ (1 + cos)^2 = pi + pi/2
        (lambda c, s: s, 2.0),
        (lambda c, s: np.exp(c), np.pi * np.i0(1.0)),  # ∫_0^pi e^cos = pi I_0(1)
    ],
)
def test_phi_rule_a_integrates_over_zero_to_pi(f, exact):
    x, w = points.gauss_legendre(24)
    rows = phi_rule_a(np.stack([x, w], axis=1))
    np.testing.assert_allclose(np.sum(rows[:, 2] * f(rows[:, 0], rows[:, 1])), exact, rtol=RULE_TOLERANCE)


def test_phi_rule_a_nodes_are_the_kernels_sinh_map():
    """phi_j = pi - pi sinh(asinh(1) (1 - x_j)): x = 1 is phi = pi (the sinh map's end at phimax), x = 0 is phi = 0."""
    rows = phi_rule_a(np.array([[0.0, 1.0], [1.0, 1.0]]))
    np.testing.assert_allclose(rows[:, 0], [1.0, -1.0], atol=RULE_TOLERANCE)
    np.testing.assert_allclose(rows[:, 1], [0.0, 0.0], atol=RULE_TOLERANCE)


def test_gl_levels_offsets_address_each_order():
    rules, levels = gl_levels(ADAPTIVE_ORDERS)
    assert len(rules) == len(phi_rule_a(rules)) == sum(ADAPTIVE_ORDERS)
    for (off, n), order in zip(levels, ADAPTIVE_ORDERS):
        x, w = points.gauss_legendre(order)
        assert n == order
        np.testing.assert_array_equal(rules[off : off + n, 0], x)
        np.testing.assert_array_equal(rules[off : off + n, 1], w)
