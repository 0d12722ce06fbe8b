"""Kind specular_aniso: anisotropic GGX and Ashikhmin-Shirley, NoV x roughness x anisotropy.

Both lobes with the view azimuth averaged take the panelled Gauss-Legendre rule (to the tolerance, 1e-6 by default:
at anisotropy 0 it is the isotropic table to 2e-6, and every estimate bounds its error against the numpy reference
of tests/aniso_reference.py); the fixed view azimuths take QMC (3D Sobol'), which must agree with the tables to its
error, what ANISO_ATOL states (measured below; printed).
"""

import numpy as np
import pytest

from lutbake.errors import ConfigError
from lutbake.integrands.anisotropic import alpha_xy

SIZE = [12, 6]  # [NoV, roughness]
SAMPLES = 16384
# |QMC (16384 points, the kind's default) - gauss_legendre| per texel on this grid: measured 5.4e-4 (anisotropic GGX,
# view azimuth averaged; worst at the grazing, near-mirror texels) and 3.7e-4 (Ashikhmin-Shirley, against its
# gauss_legendre table, panels split along its max(n.l, n.v) kink: within 6e-8 at 1728 samples). At 4096 points
# the errors were 1.0e-3 and 6.3e-3 (Ashikhmin-Shirley's h sampling ignores v, so many samples fall below the horizon).
ANISO_ATOL = 1e-3


# two tables each within the default tolerance 1e-6 of the truth
GL_ATOL = 2e-6


@pytest.fixture(scope="module")
def ggx_ms(bake):
    """Anisotropic GGX, multiscatter layout (G = E(F = 1)), anisotropy in {0, 0.5, 1} (endpoint texels), by the
    default gauss_legendre."""
    return bake(kind="specular_aniso", size=SIZE, anisotropy_size=3, texel="endpoint", layout="multiscatter")


def report(name, got, want, atol=ANISO_ATOL):
    err = np.abs(got - want)
    print(f"\n{name}: max |aniso(a = 0) - isotropic| = {err.max():.2e} (tolerance {atol:.0e})")
    return err.max()


def test_burley_mapping():
    ax, ay = alpha_xy(np.array([0.25, 0.25, 0.25, 1e-6]), np.array([0.0, 1.0, -1.0, 0.5]))
    np.testing.assert_allclose(ax, [0.25, 0.25 / np.sqrt(0.1), 0.25 * np.sqrt(0.1), 1e-4], rtol=1e-6)
    np.testing.assert_allclose(ay, [0.25, 0.25 * np.sqrt(0.1), 0.25 / np.sqrt(0.1), 1e-4], rtol=1e-6)


def test_layout_and_metadata(ggx_ms):
    t = ggx_ms
    assert t.data.shape == (3, SIZE[1], SIZE[0], 2)
    assert [a.name for a in t.axes] == ["anisotropy", "perceptual_roughness", "NoV"]
    np.testing.assert_allclose(t.axes[0].values(), [0.0, 0.5, 1.0])
    assert t.attributes["view_azimuth"].startswith("average")
    assert "Burley 2012" in t.attributes["anisotropy_mapping"]


def test_ggx_at_anisotropy_zero_is_the_isotropic_table(ggx_ms, bake):
    iso = bake(kind="dfg", size=SIZE, texel="endpoint", layout="multiscatter")
    assert ggx_ms.attributes["estimator"] == "gauss_legendre"
    assert report("GGX multiscatter", ggx_ms.data[0], iso.data, GL_ATOL) < GL_ATOL
    albedo = bake(kind="albedo", size=SIZE, texel="endpoint")
    np.testing.assert_allclose(ggx_ms.data[0, ..., 1], albedo.data[..., 0], atol=GL_ATOL)
    assert float(ggx_ms.attributes["error_estimate"]) <= 1e-6


def test_anisotropy_loses_energy_and_stays_below_one(ggx_ms):
    """E(F = 1) <= 1; for rough rows, stretching the lobe (a > 0) costs energy (more of it is masked)."""
    E = ggx_ms.data[..., 1]
    assert E.max() <= 1.0 + 1e-6
    assert np.all(E[2, -1, 1:] < E[0, -1, 1:])


def test_negative_anisotropy_is_the_rotated_lobe(bake):
    """a < 0 swaps alpha_x and alpha_y: seen from the tangent it is the a > 0 lobe seen from the bitangent."""

    def lobe(a: float, view_azimuth: str):
        return bake(
            kind="specular_aniso",
            size=[6, 3],
            anisotropy_size=1,
            anisotropy_range=[a, a],
            view_azimuth=view_azimuth,
            layout="multiscatter",
            samples=SAMPLES,
        )

    a, b, c = lobe(-0.8, "tangent"), lobe(0.8, "bitangent"), lobe(0.8, "tangent")
    np.testing.assert_allclose(a.data, b.data, atol=ANISO_ATOL)
    assert np.max(np.abs(a.data - c.data)) > 10 * ANISO_ATOL  # the view azimuth matters for a stretched lobe


def test_ashikhmin_shirley(bake):
    """At anisotropy 0 it is the isotropic model = ashikhmin_shirley dfg table (both gauss_legendre to 1e-6); its
    E(F = 1) <= 1 for every anisotropy (the integrand over its own h density is (n.l)/max(n.l, n.v) <= 1); QMC
    (sobol, 16384 points) agrees to its error."""
    keys = {"kind": "specular_aniso", "model": "ashikhmin_shirley", "size": SIZE, "anisotropy_size": 3}
    t = bake(keys, texel="endpoint", layout="multiscatter")
    assert t.attributes["estimator"] == "gauss_legendre" and float(t.attributes["error_estimate"]) <= 1e-6
    iso = bake(kind="dfg", model="ashikhmin_shirley", size=SIZE, texel="endpoint", layout="multiscatter")
    assert report("Ashikhmin-Shirley multiscatter", t.data[0], iso.data, GL_ATOL) < GL_ATOL
    E = t.data[..., 1]
    print(f"Ashikhmin-Shirley max E(F = 1) = {E.max():.6f}")
    assert E.max() <= 1.0 + 1e-6 and E.min() > 0.0
    qmc = bake(keys, texel="endpoint", layout="multiscatter", estimator="sobol", samples=SAMPLES)
    assert report("Ashikhmin-Shirley QMC", qmc.data, t.data) < ANISO_ATOL


def test_config_rules(spec):
    with pytest.raises(ConfigError, match="anisotropy_range"):
        spec(name="x", kind="specular_aniso", anisotropy_range=[-1.5, 0.0])
    with pytest.raises(ConfigError, match="model"):
        spec(name="x", kind="specular_aniso", model="cook_torrance")


@pytest.mark.parametrize("model", ["microfacet", "ashikhmin_shirley"])
def test_gauss_legendre_estimate_bounds_the_error(model):
    """Per texel, the panelled rule's estimate (the ladder's plus the view-azimuth rule's |Q_M - Q_(M/2)|) bounds its
    error against the independent numpy reference (tests/aniso_reference.py), at grazing view, low roughness and the
    largest anisotropy (alpha_x / alpha_y = 10: M = 256 azimuth nodes), and a mild lobe."""
    from aniso_reference import averaged_split_sum

    from lutbake.integrands.anisotropic import averaged_integrand, azimuth_nodes_np
    from lutbake.sampling.anisotropic import AzimuthAveragedGaussLegendre

    texels = np.array([(0.02, 0.3, 0.03), (0.5, 1.0, 0.1), (0.9, 0.05, 0.005), (0.2, 0.3, 0.2), (0.004, 0.1, 0.01)])
    nov, ax, ay = (texels[:, k].astype(np.float32) for k in range(3))
    est = AzimuthAveragedGaussLegendre(1e-6, 0.0, azimuth_nodes=azimuth_nodes_np)
    inputs = {"nov": nov, "alpha": ay, "param": ax}
    got, bound = est.evaluate_with_error(averaged_integrand(model, "scale_bias"), inputs, "cpu")
    ref = np.array([averaged_split_sum(float(n), float(x), float(y), model=model) for n, x, y in zip(nov, ax, ay)])
    err = np.abs(got - ref)
    print(
        f"\n{model}: max error {err.max():.2e}, max estimate {bound.max():.2e}, worst error / estimate "
        f"{np.max(err / bound):.3f}"
    )
    assert np.all(err <= bound) and bound.max() <= 1e-6
