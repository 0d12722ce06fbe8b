"""The energy-preserving Oren-Nayar terms (lutbake.terms.diffuse: E_fon, E_fon_avg, Fd_fon, Fd_eon) against an
independent float64 numpy implementation written from the EON paper's GLSL listing (Portsmouth, Kutz & Hill 2024,
"EON: A practical energy-preserving rough diffuse BRDF", JCGT 14(1) 2025, arXiv 2410.18026: E_FON_exact, f_EON,
E_EON; the same formulas as adobe/openpbr-bsdf impl/openpbr_diffuse_lobe.h @ 8528294, Apache-2.0), and the
paper's claims checked by quadrature: E_FON is the FON lobe's albedo, avgEF its cosine-weighted mean, EON's albedo
E_EON (= 1 for rho = 1), reciprocity, r = 0 is Lambert."""

import numpy as np
import warp as wp

from lutbake.integrands import diffuse as tdiff
from lutbake.terms import diffuse

TERM_RTOL = 1e-5  # float32 terms vs float64 numpy: measured 4.1e-7
CLOSED_ALBEDO_ATOL = 1e-9  # the paper's closed-form albedos vs GL quadrature of the lobes: measured 5e-11
EON_ALBEDO_ATOL = 1e-6  # GL albedo of f_EON (rho = 1) vs 1: measured 1.0e-7
RECIP_RTOL = 1e-6
LAMBERT_RTOL = 2e-7  # r = 0: 1/pi (1 + 1e-7) (the paper's 1e-7 floors)

C1 = 0.5 - 2.0 / (3.0 * np.pi)
C2 = 2.0 / 3.0 - 28.0 / (15.0 * np.pi)


# ---- numpy reference (the listing's formulas, float64, the direct form of G) ----


def ref_E_fon(mu, r):
    AF = 1.0 / (1.0 + C1 * r)
    BF = r * AF
    Si = np.sqrt(1.0 - mu * mu)
    G = Si * (np.arccos(np.clip(mu, -1, 1)) - Si * mu) + (2.0 / 3.0) * ((Si / mu) * (1.0 - Si**3) - Si)
    return AF + BF / np.pi * G


def ref_f_eon(rho, r, wi, wo):
    mu_i, mu_o = wi[..., 2], wo[..., 2]
    s = np.sum(wi * wo, axis=-1) - mu_i * mu_o
    sovert = np.where(s > 0.0, s / np.maximum(mu_i, mu_o), s)
    AF = 1.0 / (1.0 + C1 * r)
    f_ss = rho / np.pi * AF * (1.0 + r * sovert)
    avg = AF * (1.0 + C2 * r)
    rho_ms = rho * rho * avg / (1.0 - rho * (1.0 - avg))
    eps = 1e-7
    f_ms = (
        rho_ms
        / np.pi
        * np.maximum(eps, 1 - ref_E_fon(mu_o, r))
        * np.maximum(eps, 1 - ref_E_fon(mu_i, r))
        / np.maximum(eps, 1 - avg)
    )
    return f_ss + f_ms


def ref_E_eon(rho, mu, r):
    AF = 1.0 / (1.0 + C1 * r)
    avg = AF * (1.0 + C2 * r)
    rho_ms = rho * rho * avg / (1.0 - rho * (1.0 - avg))
    ef = ref_E_fon(mu, r)
    return rho * ef + rho_ms * (1.0 - ef)


@wp.kernel(enable_backward=False)
def eon_terms(
    l: wp.array(dtype=wp.vec3),
    v: wp.array(dtype=wp.vec3),
    r: wp.array(dtype=float),
    rho: wp.array(dtype=float),
    out: wp.array2d(dtype=float),
):
    i = wp.tid()
    a, b, c = l[i][2], v[i][2], wp.dot(l[i], v[i])
    out[i, 0] = diffuse.Fd_eon(rho[i], a, b, c, r[i])
    out[i, 1] = diffuse.Fd_fon(rho[i], a, b, c, r[i])
    out[i, 2] = diffuse.E_fon(b, r[i])
    out[i, 3] = diffuse.E_fon_avg(r[i])


def run_terms(l, v, r, rho):
    n = len(l)
    out = wp.zeros((n, 4), dtype=float, device="cpu")
    arrays = [wp.array(np.asarray(x, np.float32), dtype=wp.vec3) for x in (l, v)]
    arrays += [wp.array(np.broadcast_to(np.asarray(x, np.float32), (n,)).copy(), dtype=float) for x in (r, rho)]
    wp.launch(eon_terms, dim=n, inputs=[*arrays, out], device="cpu")
    return out.numpy().astype(np.float64)


def random_dirs(rng, n, lo=0.02):
    mu = rng.uniform(lo, 1.0, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    s = np.sqrt(1 - mu * mu)
    return np.stack([s * np.cos(phi), s * np.sin(phi), mu], 1)


def test_Fd_eon_matches_the_papers_listing_in_float64():
    rng = np.random.default_rng(5)
    n = 2000
    l, v = random_dirs(rng, n), random_dirs(rng, n)
    l32, v32 = l.astype(np.float32).astype(np.float64), v.astype(np.float32).astype(np.float64)
    r, rho = rng.uniform(0, 1, n), rng.uniform(0.05, 1, n)
    r32, rho32 = r.astype(np.float32).astype(np.float64), rho.astype(np.float32).astype(np.float64)
    got = run_terms(l, v, r, rho)
    # the listing calls wi the light (incident) and wo the view direction; f_EON is symmetric in them
    np.testing.assert_allclose(got[:, 0], ref_f_eon(rho32, r32, l32, v32), rtol=TERM_RTOL)
    AF = 1.0 / (1.0 + C1 * r32)
    s = np.sum(l32 * v32, 1) - l32[:, 2] * v32[:, 2]
    ss = rho32 / np.pi * AF * (1 + r32 * np.where(s > 0, s / np.maximum(l32[:, 2], v32[:, 2]), s))
    np.testing.assert_allclose(got[:, 1], ss, rtol=TERM_RTOL)
    np.testing.assert_allclose(got[:, 2], ref_E_fon(v32[:, 2], r32), rtol=TERM_RTOL)
    np.testing.assert_allclose(got[:, 3], AF * (1 + C2 * r32), rtol=TERM_RTOL)


def test_eon_is_reciprocal_and_lambert_at_r0():
    rng = np.random.default_rng(6)
    l, v = random_dirs(rng, 500), random_dirs(rng, 500)
    r = rng.uniform(0, 1, 500)
    np.testing.assert_allclose(run_terms(l, v, r, 0.7)[:, 0], run_terms(v, l, r, 0.7)[:, 0], rtol=RECIP_RTOL)
    np.testing.assert_allclose(run_terms(l, v, 0.0, 1.0)[:, 0], 1 / np.pi, rtol=LAMBERT_RTOL)


def gl_hemisphere(n=48):
    """Directions and weights of a product GL rule over the hemisphere (mu on [0, 1] cut at 0.5, phi on [0, 2 pi]
    cut at the kinks of s / t: every pi/2), for lobes f(l) with l = (sin th cos phi, sin th sin phi, mu)."""
    x, w = np.polynomial.legendre.leggauss(n)
    x, w = (x + 1) / 2, w / 2
    mus = np.concatenate([0.5 * x, 0.5 + 0.5 * x])
    wm = np.concatenate([0.5 * w, 0.5 * w])
    phis = np.concatenate([k * np.pi / 2 + np.pi / 2 * x for k in range(4)])
    wp_ = np.tile(np.pi / 2 * w, 4)
    M, P = np.meshgrid(mus, phis, indexing="ij")
    W = np.outer(wm, wp_)
    s = np.sqrt(1 - M * M)
    return np.stack([s * np.cos(P), s * np.sin(P), M], -1).reshape(-1, 3), W.ravel()


def test_papers_closed_form_albedos_by_quadrature():
    """E_FON_exact is the FON lobe's albedo, avgEF its cosine-weighted mean, E_EON the EON lobe's albedo: all
    from the numpy reference by GL quadrature (the l-integral split where mu_l = mu_v, the kink of max(mu_l, mu_v))."""
    dirs, w = gl_hemisphere()
    for r in (0.3, 1.0):
        for mu_v in (0.05, 0.4, 0.9):
            v = np.array([np.sqrt(1 - mu_v**2), 0.0, mu_v])
            acc = {"fon": 0.0, "eon_half": 0.0}
            for lo, hi in ((0.0, mu_v), (mu_v, 1.0)):  # integrate again on panels split at the kink
                x, wx = np.polynomial.legendre.leggauss(64)
                mus = lo + (hi - lo) * (x + 1) / 2
                phis = np.concatenate([k * np.pi / 2 + np.pi / 4 * (x + 1) for k in range(4)])
                M, P = np.meshgrid(mus, phis, indexing="ij")
                W = np.outer((hi - lo) / 2 * wx, np.tile(np.pi / 4 * wx, 4))
                s = np.sqrt(1 - M * M)
                L = np.stack([s * np.cos(P), s * np.sin(P), M], -1)
                mu = L[..., 2]
                sv = np.sum(L * v, -1) - mu * mu_v
                AF = 1 / (1 + C1 * r)
                fon = AF / np.pi * (1 + r * np.where(sv > 0, sv / np.maximum(mu, mu_v), sv))
                acc["fon"] += np.sum(W * fon * mu)
                acc["eon_half"] += np.sum(W * ref_f_eon(0.5, r, L, np.broadcast_to(v, L.shape)) * mu)
            np.testing.assert_allclose(acc["fon"], ref_E_fon(mu_v, r), atol=CLOSED_ALBEDO_ATOL)
            np.testing.assert_allclose(acc["eon_half"], ref_E_eon(0.5, mu_v, r), atol=CLOSED_ALBEDO_ATOL)
        mus = gl_hemisphere()[0][:, 2]
        avg = np.sum(w * ref_E_fon(np.maximum(mus, 1e-12), r) * mus) / np.pi
        np.testing.assert_allclose(avg, (1 + C2 * r) / (1 + C1 * r), atol=CLOSED_ALBEDO_ATOL)


def test_eon_albedo_table_is_one_for_rho_one():
    """The ``diffuse`` kind's integrator (GL over l, order 24) on f_EON: E = 1 for rho = 1 at every view."""
    nov = np.array([0.01, 0.1, 0.3, 0.6, 0.9, 1.0])
    for r in (0.0, 0.25, 0.5, 1.0):
        e = tdiff.albedo_gl("eon", nov, r, order=24)
        np.testing.assert_allclose(e, 1.0, atol=EON_ALBEDO_ATOL, err_msg=f"r = {r}")
