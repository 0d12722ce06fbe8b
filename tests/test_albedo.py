"""Kulla-Conty energy compensation: the albedo tables, and the white furnace of the compensated BRDF."""

import numpy as np
import pytest

from lutbake.validate.checks import KC_FURNACE_TOL as FURNACE_TOL
from lutbake.validate.checks import KC_FURNACE_TOL_SMOOTHEST as FURNACE_TOL_SMOOTHEST
from lutbake.validate.checks import KC_N_MU as N_MU
from lutbake.validate.checks import KC_N_ROUGH as N_ROUGH
from lutbake.validate.checks import kulla_conty_residual as white_furnace

# The tolerances and the residual are the named check's (lutbake validate: kulla_conty_white_furnace), which
# documents them; this test prints the per-row residuals.


@pytest.fixture(scope="module")
def tables(bake):
    e = bake(name="e", kind="albedo", size=[N_MU, N_ROUGH])
    avg = bake(name="a", kind="albedo_avg", roughness_size=N_ROUGH)
    return e, avg


def test_albedo_avg_is_one_row_over_the_same_roughness(tables):
    e, avg = tables
    assert avg.data.shape == (1, N_ROUGH, 1) and e.data.shape == (N_ROUGH, N_MU, 1)
    np.testing.assert_array_equal(avg.axes[0].alpha(), e.axes[0].alpha())
    E_avg = avg.data[0, :, 0]
    assert np.all(np.diff(E_avg) < 0) and 0.4 < E_avg[-1] < E_avg[0] <= 1.0
    assert E_avg[0] == pytest.approx(1.0, abs=1e-4)  # near-mirror GGX loses (almost) nothing


def test_albedo_is_dfg_multiscatter_green(tables, bake):
    e, _ = tables
    ms = bake(name="d", kind="dfg", size=[N_MU, N_ROUGH], layout="multiscatter")
    np.testing.assert_allclose(e.data[..., 0], ms.data[..., 1], atol=1e-6)


def test_white_furnace_of_the_compensated_brdf(tables):
    e, avg = tables
    mu = e.axes[1].values().astype(np.float64)
    res = white_furnace(e.data[..., 0], avg.data[0, :, 0], mu)
    worst = np.max(np.abs(res), axis=1)
    print("\nwhite furnace max |E + E_ms - 1| per roughness:")
    for r, E_avg, wv in zip(e.axes[0].values(), avg.data[0, :, 0], worst):
        print(f"  r = {r:.4f}  E_avg = {E_avg:.6f}  {wv:.2e}")
    rough = e.axes[0].values()
    assert np.max(worst[rough >= 0.1]) < FURNACE_TOL
    assert np.max(worst) < FURNACE_TOL_SMOOTHEST
    uncompensated = 1.0 - e.data[..., 0]
    assert np.max(uncompensated) > 0.3  # without f_ms the rough rows lose a lot


@pytest.mark.parametrize("ndf", ["ggx", "beckmann"])
def test_albedo_avg_estimate_bounds_its_error(spec, graded_rule, ndf):
    """Each E_avg texel's recorded estimate (the mu rule's |Kronrod - Gauss| plus its inner bounds) bounds its error
    against a second mu rule: E(mu) at the nodes of a composite Gauss-Legendre rule graded toward mu = 0 and 1 (432
    nodes), the inner integral converged (tolerance 1e-9: its float32 floor, ~1e-7)."""
    from lutbake.kinds import lookup_kind
    from lutbake.kinds.albedo import integrand_of
    from lutbake.sampling.hemisphere import AdaptiveGaussLegendre

    s = spec(kind="albedo_avg", roughness_size=8, ndf=ndf)
    plan = lookup_kind("albedo_avg").plan(s)
    plan.prepare("cpu")
    out = plan.run_tile(0, plan.n_texels, "cpu")
    got, estimate = out[:, 0], out[:, 1]
    mu, w = graded_rule(0.0, 1.0, [0.0, 1.0])
    alpha = plan.axes[0].alpha()
    integrand = integrand_of(s)
    inputs = {
        "nov": np.tile(mu, len(alpha)).astype(np.float32),
        "alpha": integrand.alpha_input(np.repeat(alpha, len(mu))),
        "param": np.zeros(len(mu) * len(alpha), np.float32),
    }
    e = AdaptiveGaussLegendre(1e-9, 0.0).evaluate(integrand, inputs, "cpu")[:, 0].reshape(len(alpha), len(mu))
    ref = 2.0 * e @ (w * mu)
    err = np.abs(got - ref)
    print(
        f"\n{ndf} E_avg: max error {err.max():.2e}, max estimate {estimate.max():.2e}, worst error / estimate "
        f"{np.max(err / estimate):.3f}"
    )
    assert np.all(err <= estimate) and estimate.max() <= 1e-6
