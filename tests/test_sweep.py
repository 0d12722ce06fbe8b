"""NaN/Inf sweep (issue 7): every BRDF term of lutbake/terms over its whole domain, edges included
(cosines in {-1, -1e-8, 0, 1e-8, COS_EPS, ..., 1}, alpha in {0, ALPHA_MIN, ..., 1}, f0 in {0, ..., 1}),
and the dfg kernels at extreme texels. Nothing may be NaN or Inf.

Domain note: alpha = 0 is outside the NDFs' domain (D is a Dirac delta there: 0/0 at the pole); the
edge policy (lutbake.edge.ALPHA_MIN) clamps every table's alpha, which test_tables_clamp_alpha_zero
checks. The raw D values at alpha = 0 are listed in OUT_OF_DOMAIN and checked to be the only exception.
"""

import itertools
import logging

import numpy as np
import pytest
import warp as wp

from lutbake.edge import ALPHA_MIN, COS_EPS, NOV_MIN
from lutbake.integrands import specular
from lutbake.terms.fresnel import F_dielectric, F_dielectric_f0, F_schlick
from lutbake.terms.masking import (
    G1_smith,
    G2_smith_height_correlated,
    G2_smith_separable,
    G2_v_cavity,
    Lambda_beckmann,
    Lambda_ggx,
)
from lutbake.terms.ndf import D_beckmann, D_ggx

wp.config.log_level = logging.WARNING

COSINES = np.array([-1.0, -0.5, -1e-8, 0.0, 1e-8, COS_EPS, 1e-6, 1e-4, 1e-2, 0.5, 0.9, 1 - 1e-7, 1.0], np.float32)
ALPHAS = np.array([0.0, ALPHA_MIN, 1e-3, 0.1, 0.5, 1.0], np.float32)
F0S = np.array([0.0, 1e-6, 0.04, 0.5, 0.999, 1.0], np.float32)
ETAS = np.array([1.0, 1.0 + 1e-6, 1.5, 4.0, 1e3, 1e6], np.float32)
TERMS = [
    "D_ggx",
    "D_beckmann",
    "Lambda_ggx",
    "Lambda_beckmann",
    "G1_smith(ggx)",
    "G1_smith(beckmann)",
    "G2_smith_height_correlated(ggx)",
    "G2_smith_height_correlated(beckmann)",
    "G2_smith_separable(ggx)",
    "G2_smith_separable(beckmann)",
    "G2_v_cavity",
    "F_schlick",
    "F_dielectric",
    "F_dielectric_f0",
]
OUT_OF_DOMAIN = {"D_ggx", "D_beckmann"}  # at alpha = 0 only (see the module docstring)
# a baked extreme texel vs the raw kernel at that texel's (NoV, alpha) as its axes list them: float32 rounding
# (measured 5e-8 over every kernel below)
EDGE_TEXEL_ATOL = 1e-6


@wp.kernel
def sweep(
    cos: wp.array(dtype=float),
    alphas: wp.array(dtype=float),
    f0s: wp.array(dtype=float),
    etas: wp.array(dtype=float),
    out: wp.array(dtype=float, ndim=2),
):
    # one thread per (c1, c2, alpha, f0): the direction cosines n.h = c1 and c2 for the second one
    i, j, k, m = wp.tid()
    row = ((i * cos.shape[0] + j) * alphas.shape[0] + k) * f0s.shape[0] + m
    c = cos[i]
    c2 = cos[j]
    a = alphas[k]
    h = wp.vec3(wp.sqrt(wp.max(1.0 - c * c, 0.0)), 0.0, c)
    lg = Lambda_ggx(c, a)
    lg2 = Lambda_ggx(c2, a)
    lb = Lambda_beckmann(c, a)
    lb2 = Lambda_beckmann(c2, a)
    out[row, 0] = D_ggx(h, a)
    out[row, 1] = D_beckmann(h, a)
    out[row, 2] = lg
    out[row, 3] = lb
    out[row, 4] = G1_smith(lg)
    out[row, 5] = G1_smith(lb)
    out[row, 6] = G2_smith_height_correlated(lg, lg2)
    out[row, 7] = G2_smith_height_correlated(lb, lb2)
    out[row, 8] = G2_smith_separable(lg, lg2)
    out[row, 9] = G2_smith_separable(lb, lb2)
    out[row, 10] = G2_v_cavity(c, c2, c, c2, c)  # (NoH, NoV, NoL, VoH, LoH) from the grid
    out[row, 11] = F_schlick(f0s[m], c)
    out[row, 12] = F_dielectric(etas[m], c)
    out[row, 13] = F_dielectric_f0(f0s[m], c)


@pytest.fixture(scope="module")
def swept():
    shape = (len(COSINES), len(COSINES), len(ALPHAS), len(F0S))
    out = wp.zeros((int(np.prod(shape)), len(TERMS)), dtype=float, device="cpu")
    arrays = [wp.array(a, dtype=float, device="cpu") for a in (COSINES, ALPHAS, F0S, ETAS)]
    wp.launch(sweep, dim=shape, inputs=[*arrays, out], device="cpu")
    return out.numpy().reshape(*shape, len(TERMS))


def _where(values, bad):
    idx = np.argwhere(bad)[:5]
    return [
        dict(
            cos=float(COSINES[i]),
            cos2=float(COSINES[j]),
            alpha=float(ALPHAS[k]),
            f0=float(F0S[m]),
            value=float(values[i, j, k, m]),
        )
        for i, j, k, m in idx
    ]


@pytest.mark.parametrize("t", range(len(TERMS)), ids=TERMS)
def test_every_term_is_finite_over_its_whole_domain(swept, t):
    values = swept[..., t]
    bad = ~np.isfinite(values)
    if TERMS[t] in OUT_OF_DOMAIN:
        bad[:, :, ALPHAS == 0.0, :] = False
    assert not bad.any(), f"{TERMS[t]} is NaN/Inf at {_where(values, bad)}"


def test_terms_have_their_limits_at_the_edges(swept):
    term = {n: swept[..., i] for i, n in enumerate(TERMS)}
    c_one = COSINES == 1.0
    # Fresnel: f0 (or the dielectric's) at normal incidence, 1 at grazing, inside [0, 1] everywhere
    for n in ("F_schlick", "F_dielectric", "F_dielectric_f0"):
        assert np.all((term[n] >= 0) & (term[n] <= 1 + 1e-6)), n
    np.testing.assert_allclose(term["F_schlick"][c_one][0, 0, 0], F0S, atol=1e-6)
    np.testing.assert_allclose(term["F_schlick"][COSINES == 0.0][0, 0, 0], 1.0, atol=1e-6)
    # masking: G in [0, 1]; back-facing or horizon directions are fully masked
    for n in TERMS[4:11]:
        assert np.all((term[n] >= 0) & (term[n] <= 1 + 1e-6)), n
    back = COSINES <= COS_EPS
    assert np.all(term["G1_smith(ggx)"][back] <= 1e-29) and np.all(term["G1_smith(beckmann)"][back] <= 1e-29)
    # D is non-negative and 0 for back-facing microfacet normals
    ok_alpha = ALPHAS > 0
    for n in ("D_ggx", "D_beckmann"):
        d = term[n][:, :, ok_alpha]
        assert np.all(d >= 0), n
        assert np.all(term[n][COSINES <= 0.0][:, :, ok_alpha] == 0), n


def test_raw_d_at_alpha_zero_is_the_only_exception(swept):
    """Documents the domain: D at alpha = 0 (a Dirac delta) may be NaN/Inf; every other term is not."""
    other = [i for i, n in enumerate(TERMS) if n not in OUT_OF_DOMAIN]
    assert np.all(np.isfinite(swept[..., other]))


def test_tables_take_the_mirror_at_alpha_zero_and_clamp_grazing_nov(bake):
    t = bake(name="edge", kind="dfg", size=[3, 3], samples=48, texel="endpoint", roughness="alpha", workers=1)
    rough, nov = t.axes
    assert rough.alpha()[0] == 0.0 and "mirror" in t.attributes["alpha_policy"]
    assert nov.values()[0] == pytest.approx(NOV_MIN)


# (ndf, masking, layout, estimator) of every dfg kernel
KERNELS = [
    k
    for k in itertools.product(
        ("ggx", "beckmann"),
        ("smith_height_correlated", "smith_separable", "v_cavity"),
        ("scale_bias", "multiscatter"),
        ("gauss_legendre", "sobol_vndf", "sobol_ndf", "hammersley_ndf"),
    )
    if not (k[0] == "beckmann" and k[3] == "sobol_vndf")
]


@pytest.mark.parametrize("key", KERNELS, ids=["-".join(k) for k in KERNELS])
def test_dfg_kernels_are_finite_at_extreme_texels(key, bake):
    """The raw kernels (no axis clamps) at NoV in {0, 1e-8, NOV_MIN, 1} and alpha in {ALPHA_MIN, 1}; and
    every such table through the config at its extreme texels (alpha 0: the mirror branch, NoV 0 clamped by
    policy) is that integrand at the values its axes list (bake_table itself raises on a non-finite value)."""
    nov, alpha = (
        a.ravel()
        for a in np.meshgrid(np.float32([0.0, 1e-8, NOV_MIN, 0.5, 1.0]), np.float32([ALPHA_MIN, 1e-3, 0.5, 1.0]))
    )
    r = specular.hemisphere_integral(*key[:3], nov, alpha, key[3], 48)
    bad = ~np.isfinite(r).all(axis=1)
    assert not bad.any(), f"{key}: NaN/Inf at (NoV, alpha) = {list(zip(nov[bad], alpha[bad]))}"
    assert np.all(r >= -1e-6)
    ndf, masking, layout, est = key
    t = bake(
        name="x",
        kind="dfg",
        size=[2, 2],
        samples=48,
        texel="endpoint",
        ndf=ndf,
        masking=masking,
        layout=layout,
        estimator=est,
        workers=1,
    )
    rough_axis, nov_axis = t.axes
    a, c = (x.ravel().astype(np.float32) for x in np.meshgrid(rough_axis.alpha(), nov_axis.values(), indexing="ij"))
    np.testing.assert_allclose(
        t.data.reshape(len(a), -1),
        specular.hemisphere_integral(ndf, masking, layout, c, a, est, 48),
        rtol=0,
        atol=EDGE_TEXEL_ATOL,
    )
