"""The host-side rules of the gauss_legendre kernel (lutbake.sampling.hemisphere): region A's tabulated inner rule
(phi_rule_a) is a quadrature over [0, pi] that integrates smooth periodic functions, and gl_levels lays the orders
out as the kernel reads them."""

import numpy as np
import pytest

from lutbake.sampling import points
from lutbake.sampling.rules import ADAPTIVE_ORDERS, gl_levels, phi_rule_a

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


def test_gl_levels_with_a_kronrod_pair():
    """``kronrod`` (a ladder replayed and checked by benchmarks/check_glass_ladder.py): level 1 is the Kronrod extension
    of level 0: its nodes hold level 0's, its weights are Kronrod's; the other levels stay Gauss-Legendre. A pair that
    is not (n, 2n + 1) is refused."""
    orders = (5, 11, 16, 20, 24, 32, 48, 64)
    rules, levels = gl_levels(orders, True)
    (o0, n0), (o1, n1) = levels[:2]
    x, wk, wg = points.gauss_kronrod(n0)
    assert n1 == 2 * n0 + 1
    np.testing.assert_array_equal(rules[o1 : o1 + n1], np.stack([x, wk], axis=1))
    np.testing.assert_allclose(rules[o0 : o0 + n0, 0], x[wg > 0], atol=1e-15)
    for (off, n), order in zip(levels[2:], orders[2:]):
        np.testing.assert_array_equal(rules[off : off + n, 0], points.gauss_legendre(order)[0])
    with pytest.raises(ValueError, match="Gauss-Kronrod"):
        gl_levels((8, 16), True)


# QUADPACK dqk15 (Piessens, de Doncker-Kapenga, Ueberhuber, Kahaner 1983), on [-1, 1], x >= 0 half: the independent
# reference of points.gauss_kronrod(7)
QK15_XGK = [0.0, 0.207784955007898467600689403773245, 0.405845151377397166906606412076961,
            0.586087235467691130294144845693013, 0.741531185599394439863864773280788,
            0.864864423359769072789712788640926, 0.949107912342758524526189684047851,
            0.991455371120812639206854697526329]  # fmt: skip
QK15_WGK = [0.209482141084727828012999174891714, 0.204432940075298892414161999234649,
            0.190350578064785409913256402421014, 0.169004726639267902826583426598550,
            0.140653259715525918745189590510238, 0.104790010322250183839876322541518,
            0.063092092629978553290700663189204, 0.022935322010529224963732008058970]  # fmt: skip
QK15_WG = [0.417959183673469387755102040816327, 0.381830050505118944950369775488975,
           0.279705391489276667901467771423780, 0.129484966168869693270611432679082]  # fmt: skip


def test_gauss_kronrod_is_quadpacks_qk15():
    x, wk, wg = points.gauss_kronrod(7)
    np.testing.assert_allclose(2 * x[7:] - 1, QK15_XGK, atol=1e-15)
    np.testing.assert_allclose(2 * wk[7:], QK15_WGK, rtol=1e-13)
    np.testing.assert_allclose(2 * wg[7::2], QK15_WG, rtol=1e-13)  # the Gauss nodes: every other one from the middle
    assert np.all(wg[8::2] == 0) and np.all(wk > 0)


@pytest.mark.parametrize("n", [5, 7, 10, 12])
def test_gauss_kronrod_degrees(n):
    """The Kronrod weights integrate x^d exactly on [0, 1] for d <= 3n + 1, the Gauss weights for d <= 2n - 1, and the
    Gauss subset is numpy's leggauss(n)."""
    x, wk, wg = points.gauss_kronrod(n)
    for d in range(3 * n + 2):
        assert abs(wk @ x**d - 1 / (d + 1)) < RULE_TOLERANCE, d
    for d in range(2 * n):
        assert abs(wg @ x**d - 1 / (d + 1)) < RULE_TOLERANCE, d
    xg, w = points.gauss_legendre(n)
    np.testing.assert_allclose(x[wg > 0], xg, atol=1e-15)
    np.testing.assert_allclose(wg[wg > 0], w, rtol=1e-13)
