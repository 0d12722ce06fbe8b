"""The adaptive microfacet btf's group kernel (texels that differ only in the azimuth of l share their u nodes,
lutbake.sampling.diffuse.adaptive_azimuths_kernel) gives the bits of the per-texel kernel (adaptive_point_kernel):
the same float operations per texel, whatever the groups."""

import numpy as np
import pytest
import warp as wp

from lutbake.axes import sigma_alpha
from lutbake.edge import effective_alpha
from lutbake.integrands.diffuse import diffuse_integrand
from lutbake.kinds import btf
from lutbake.sampling.diffuse import adaptive_point_kernel, azimuth_groups, eval_points_adaptive, launch_rows
from lutbake.sampling.facets import FACET_ORDERS
from lutbake.sampling.rules import gl_levels


@pytest.fixture(scope="module")
def grid():
    """(l, v, alpha) of a 5 x 5 x 4 phi x 3 sigma angles grid (grazing texels and sigma = 0 included), shuffled so
    that the groups are not contiguous in the input."""
    o = {"size": [5, 5], "phi_size": 4, "sigma_size": 3, "sigma_range": [0.0, 1.0], "sigma_values": None}
    o.update(texel="center", sigma_to_alpha="sigma", parametrisation="angles")
    l, v, sigma = btf.directions(btf.axes_for(o), "angles")
    alpha = effective_alpha(sigma_alpha(sigma.astype(np.float32), "sigma"), False)
    p = np.random.default_rng(3).permutation(len(l))
    return l[p].astype(np.float32), v[p].astype(np.float32), alpha[p]


def per_texel(l, v, alpha, tol, orders):
    facet = diffuse_integrand("microfacet", "eq6").facet
    rules, levels = gl_levels(tuple(orders))
    arrays = [
        wp.array(np.ascontiguousarray(np.stack([l, v], 1)), dtype=wp.vec3),
        wp.array(alpha, dtype=float),
        0.0,
        wp.vec2d(*tol),
        wp.array(rules, dtype=wp.vec2d),
        wp.array(levels, dtype=wp.vec2i),
    ]
    return launch_rows(adaptive_point_kernel(facet), arrays, len(l), "cpu", (len(l), 2))


@pytest.mark.parametrize("tol, orders", [((0.0, 1.0e-5), FACET_ORDERS), ((1.0e-7, 1.0e-9), FACET_ORDERS[:3])])
def test_group_kernel_gives_the_per_texel_bits(grid, tol, orders):
    l, v, alpha = grid
    order, start = azimuth_groups(l, v, alpha)
    assert len(start) - 1 == 5 * 5 * 3  # one group per (theta_l, theta_v, sigma): the 4 azimuths
    got, est = eval_points_adaptive(diffuse_integrand("microfacet", "eq6"), l, v, alpha, 0.0, tol, orders)
    want = per_texel(l, v, alpha, tol, orders)
    assert np.all(np.isfinite(got)) and np.any(got[:, 0] > 0.0)
    np.testing.assert_array_equal(got[:, 0], want[:, 0])
    np.testing.assert_array_equal(est[:, 0], want[:, 1])
