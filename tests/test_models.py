"""The lecture's models (003) as term sets of dfg / albedo / specular_3d: Cook-Torrance, normalized Blinn-Phong,
isotropic Ashikhmin-Shirley; and the config rules that keep a model's terms fixed."""

import numpy as np
import pytest
from scipy import integrate

from lutbake.errors import ConfigError

SIZE = [12, 8]


def test_cook_torrance_is_beckmann_v_cavity_bit_for_bit(bake):
    ct = bake(kind="dfg", model="cook_torrance", size=SIZE)
    mf = bake(kind="dfg", ndf="beckmann", masking="v_cavity", size=SIZE)
    np.testing.assert_array_equal(ct.data, mf.data)
    assert '"model": "cook_torrance"' in ct.attributes["terms"] and '"ndf": "beckmann"' in ct.attributes["terms"]


def test_blinn_phong_lobe_at_shininess_zero_is_lambertian(bake):
    """s = 0 (alpha = 1): f = F (0 + 8)/(8 pi) = F / pi, so E(F = 1) = ∫ (n.l)/pi dω = 1 for every n.v."""
    e = bake(kind="albedo", model="blinn_phong", size=[16, 1], roughness_range=[1.0, 1.0])
    np.testing.assert_allclose(e.data[..., 0], 1.0, atol=1e-6)


def test_blinn_phong_lobe_energy(bake):
    """(s + 8)/(8 pi) is an approximate normalisation: E(F = 1) exceeds 1 by a few percent (measured max 1.075 at
    n.v = 1, alpha = 0.42 on a 64 x 64 endpoint grid), and the microfacet form with the normalized Blinn-Phong NDF
    and V-cavity stays <= 1."""
    lobe = bake(kind="albedo", model="blinn_phong", size=SIZE, texel="endpoint")
    mf = bake(kind="albedo", ndf="blinn_phong", masking="v_cavity", size=SIZE, texel="endpoint")
    print(f"\nBlinn-Phong lobe: max E(F = 1) = {lobe.data.max():.5f}; microfacet + V-cavity: {mf.data.max():.6f}")
    assert 1.05 < lobe.data.max() < 1.08
    assert mf.data.max() <= 1.0 + 1e-6


def test_blinn_phong_ndf_is_close_to_beckmann(bake):
    """With s = 2/alpha^2 - 2 the two NDFs nearly coincide for small alpha (Walter et al. 2007, Sec. 5.2): the
    V-cavity dfg tables of the smooth rows agree closely."""
    bp = bake(kind="dfg", ndf="blinn_phong", masking="v_cavity", size=SIZE, roughness_range=[0.0, 0.4])
    bk = bake(kind="dfg", ndf="beckmann", masking="v_cavity", size=SIZE, roughness_range=[0.0, 0.4])
    err = np.abs(bp.data - bk.data).max()
    print(f"\nmax |Blinn-Phong - Beckmann| (V-cavity, r <= 0.4) = {err:.2e}")
    assert err < 0.01


def test_ashikhmin_shirley_isotropic_energy_le_one(bake):
    """Ashikhmin-Shirley: E(F = 1) <= 1 (its integrand over its own h density is (n.l)/max(n.l, n.v)), and
    specular_3d with Schlick F is f0 scale + bias of the dfg table, as for every model."""
    e = bake(kind="albedo", model="ashikhmin_shirley", size=SIZE, samples=1728)
    print(f"\nAshikhmin-Shirley max E(F = 1) = {e.data.max():.6f}")
    assert e.data.max() <= 1.0 + 1e-6 and e.data.min() > 0.0
    d = bake(kind="dfg", model="ashikhmin_shirley", size=SIZE, samples=1728)
    s3 = bake(kind="specular_3d", model="ashikhmin_shirley", fresnel="schlick", f0_size=3, size=SIZE, samples=1728)
    f0 = s3.axes[0].values().astype(np.float64)
    want = f0[:, None, None] * d.data[None, ..., 0] + d.data[None, ..., 1]
    np.testing.assert_allclose(s3.data[..., 0], want, atol=1e-6)


@pytest.mark.parametrize(
    "kw, match",
    [
        ({"model": "cook_torrance", "ndf": "ggx", "masking": "smith_separable"}, "fixes the NDF"),
        ({"ndf": "blinn_phong"}, "no Smith Lambda"),
        ({"model": "blinn_phong", "estimator": "sobol_vndf"}, "sobol_vndf"),
        ({"model": "phong"}, "model"),
    ],
)
def test_model_config_rules(kw, match, spec):
    with pytest.raises(ConfigError, match=match):
        spec(kind="dfg", **kw)


def ashikhmin_shirley_albedo(s: float, n_v: float) -> float:
    """E = ∫ f (n.l) dω_l of the isotropic Ashikhmin-Shirley lobe of exponent s at n.v (v = (sqrt(1 - n.v²), 0, n.v)),
    independent of lutbake: scipy's cubature (adaptive Gauss-Kronrod, vectorised) over (theta_l, phi) in
    [0, pi/2] x [0, pi], doubled (f is even in phi), theta_l split at theta_v, the max(n.l, n.v) kink (u in [0, 1]
    and [1, 2]); the tolerances of the dblquad in (n.l, phi) it replaces (hemisphere_reference), which it matches to
    6e-11 on this test's texels at 1/40 of the time."""
    sv, tv = np.sqrt(1.0 - n_v * n_v), np.arccos(n_v)

    def f(x):
        u, phi = x[:, 0], x[:, 1]
        lo = u < 1.0
        th = np.where(lo, u * tv, tv + (u - 1.0) * (np.pi / 2 - tv))
        mu, sl = np.cos(th), np.sin(th)
        jac = np.where(lo, tv, np.pi / 2 - tv) * sl
        hx, hy, hz = sv + sl * np.cos(phi), sl * np.sin(phi), n_v + mu
        norm = np.sqrt(hx * hx + hy * hy + hz * hz)
        nh, vh = hz / norm, (sv * hx + n_v * hz) / norm
        return jac * (s + 1.0) / (8.0 * np.pi) * nh**s / (vh * np.maximum(mu, n_v)) * mu

    res = integrate.cubature(f, [0.0, 0.0], [2.0, np.pi], rtol=1e-8, atol=1e-10)
    assert res.status == "converged"
    return 2.0 * float(res.estimate)


def test_ashikhmin_shirley_reaches_its_tolerance_against_scipy(bake):
    """Its max(n.l, n.v) kink is a panel boundary (the level line n.l = n.v, per texel): the default gauss_legendre
    meets 1e-6 with an estimate that bounds its error against scipy's cubature over l (ashikhmin_shirley_albedo)."""
    t = bake(
        kind="albedo",
        model="ashikhmin_shirley",
        size=[4, 3],
        roughness_range=[0.3, 0.9],
        nov_range=[0.1, 0.9],
        texel="endpoint",
    )
    rough, nov = t.axes[0].values().astype(np.float64), t.axes[1].values().astype(np.float64)
    worst = 0.0
    for i, r in enumerate(rough):
        for j, n_v in enumerate(nov):
            want = ashikhmin_shirley_albedo(2.0 / r**4 - 2.0, n_v)  # alpha = r^2
            worst = max(worst, abs(float(t.data[i, j, 0]) - want))
    print(f"\nAshikhmin-Shirley E vs scipy: max error {worst:.2e}, estimate {t.attributes['error_estimate']}")
    assert worst <= float(t.attributes["error_estimate"]) <= 1e-6
