"""Named checks of the rough dielectric BSDF and its energy tables (lutbake validate; docs/transmission.md).

- ``dielectric_smooth_limit``: alpha -> 0 (ALPHA_MIN): E_R -> F(mu, eta), E_T -> 1 - F(mu, eta) (a smooth interface
  conserves energy), for eta > 1 and eta < 1 including total internal reflection (E_R = 1, E_T = 0 for
  mu < cos theta_c).
  View cosines within SMOOTH_KINK_GAP of cos theta_c are left out: F has a square-root kink there that any alpha > 0
  smooths over a width ~alpha, so the limit is reached only as sqrt(alpha).
- ``dielectric_index_matched``: eta = 1: F = 0 and every facet refracts v into -v, so E_R = 0 and
  E_T = G2(mu, mu) / G1(mu) exactly (the weak white furnace ∫ D max(0, v.h) dω_h = mu / G1(mu)). Single scattering
  does NOT give E_T = 1 at eta = 1 for alpha > 0: the missing 1 - G2/G1 is the Smith model's multiple scattering
  (separable: 1 - G1(mu)); it vanishes as alpha -> 0.
- ``dielectric_reciprocity``: f_r(i, o) = f_r(o, i) and the generalised reciprocity of the BTDF,
  f_t(i -> o) / eta_o^2 = f_t(o -> i) / eta_i^2 (Walter et al. 2007, Sec. 3.2; Veach 1997), at random pairs.
- ``dielectric_energy_le_one``: E_R + E_T <= 1 over a (mu, alpha, eta) grid; reports where the loss is largest.
- ``dielectric_estimators_agree``: panelled Gauss-Legendre vs scrambled-Sobol' VNDF sampling.
- ``openpbr_reflection_ratio_reciprocity``: the OpenPBR layout's reflection ratio x (kind dielectric_avg) keeps
  OpenPBR's multiple-scattering transmission lobe symmetric: (1 - x(eta)) E_c,avg(eta) = (1 - x(1/eta)) E_c,avg(1/eta)
  (lutbake.integrands.dielectric_ratio), on mirrored rows of the baked table, and 0 <= x <= 1.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from ..edge import ALPHA_MIN
from ..runtime.warp_runtime import kernel_factory, unique_kernel
from ..terms import dielectric as td
from ..terms import fresnel
from ..terms.distributions import NDFS
from ..terms.frame import reflect
from .results import Check, check_result

SMOOTH_LIMIT_TOL = 2.0e-5  # |E_R - F|, |E_T - (1 - F)| at alpha = ALPHA_MIN, |mu - cos theta_c| >= SMOOTH_KINK_GAP
SMOOTH_KINK_GAP = 0.02
SMOOTH_NOVS = tuple(np.linspace(0.05, 0.999, 40))
INDEX_MATCHED_TOL = 1.0e-6  # |E_R|, |E_T - G2(mu, mu)/G1(mu)| at eta = 1
RECIPROCITY_RTOL = 2.0e-5  # relative, float32 terms, well-conditioned pairs (_well_conditioned)
RECIPROCITY_MIN_COS = 0.05
RECIPROCITY_KINK_GAP = 0.01
RECIPROCITY_PAIRS = 4096
ENERGY_TOL = 1.0e-6  # E_R + E_T <= 1 + tol
ESTIMATOR_TOL = 5.0e-5  # |GL - sobol_vndf (2^16)|
ETAS = (0.5, 0.67, 0.9, 1.1, 1.5, 2.5)
SEED = 20261127
GL_SAMPLES = 3 * 12**2


def _integrate(nov, alpha, eta, masking="smith_separable", estimator="gauss_legendre", samples=GL_SAMPLES):
    from ..integrands.dielectric import integrate

    f = (np.asarray(x, np.float32) for x in np.broadcast_arrays(nov, alpha, eta))
    return integrate(("ggx", masking, "exact", estimator), *f, samples, SEED)


def fresnel_np(eta, c):
    """Exact unpolarised Fresnel by complex arithmetic (TIR: |r| = 1), for the checks' expected values."""
    c = np.clip(np.asarray(c, np.float64), 0.0, 1.0)
    ct = np.sqrt((1.0 - (1.0 - c * c) / (np.asarray(eta, np.float64) ** 2)).astype(np.complex128))
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


def smooth_limit() -> tuple[float, str]:
    mu = np.array(SMOOTH_NOVS)
    worst, where = 0.0, ""
    for eta in ETAS:
        keep = mu if eta >= 1 else mu[np.abs(mu - np.sqrt(1 - eta * eta)) >= SMOOTH_KINK_GAP]
        e = _integrate(keep, ALPHA_MIN, eta)
        F = fresnel_np(eta, keep.astype(np.float32))
        err = np.maximum(np.abs(e[:, 0] - F), np.abs(e[:, 1] - (1 - F)))
        if err.max() > worst:
            worst, where = float(err.max()), f"eta = {eta}, mu = {keep[np.argmax(err)]:.3f}"
    return worst, where


def dielectric_smooth_limit():
    worst, where = smooth_limit()
    return check_result(
        "dielectric_smooth_limit",
        worst,
        SMOOTH_LIMIT_TOL,
        f"max |E_R - F|, |E_T - (1 - F)| at alpha = {ALPHA_MIN:g}, eta in {ETAS}, {len(SMOOTH_NOVS)} mu "
        f"(TIR branch included; |mu - cos theta_c| >= {SMOOTH_KINK_GAP}); worst at {where}",
    )


def lambda_ggx_np(mu, alpha):
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * (1.0 - mu * mu) / (mu * mu)) - 1.0)


def index_matched_expected(mu, alpha, masking):
    """E_T at eta = 1: G2(mu, mu) / G1(mu), GGX."""
    lam = lambda_ggx_np(np.asarray(mu, np.float64), np.asarray(alpha, np.float64))
    g2 = 1.0 / (1.0 + lam) ** 2 if masking == "smith_separable" else 1.0 / (1.0 + 2.0 * lam)
    return g2 * (1.0 + lam)


def dielectric_index_matched():
    mu, alpha = np.meshgrid(np.linspace(0.05, 1.0, 12), np.array([1e-3, 0.05, 0.3, 0.7, 1.0]))
    mu, alpha = mu.ravel().astype(np.float32), alpha.ravel().astype(np.float32)
    worst, loss = 0.0, 0.0
    for m in ("smith_separable", "smith_height_correlated"):
        e = _integrate(mu, alpha, 1.0, masking=m)
        exp = index_matched_expected(mu, alpha, m)
        worst = max(worst, float(np.max(np.abs(e[:, 0]))), float(np.max(np.abs(e[:, 1] - exp))))
        loss = max(loss, float(np.max(1 - exp)))
    return check_result(
        "dielectric_index_matched",
        worst,
        INDEX_MATCHED_TOL,
        f"max |E_R|, |E_T - G2(mu, mu)/G1(mu)| at eta = 1, both maskings, 60 (mu, alpha); single scattering "
        f"keeps E_T < 1 there: the largest 1 - E_T is {loss:.3f} (alpha = 1)",
    )


@kernel_factory
def _bsdf_kernel(masking: str):
    D = NDFS["ggx"].D
    G2 = NDFS["ggx"].G2(masking)

    @unique_kernel
    def eval_bsdf(
        i: wp.array(dtype=wp.vec3),
        o: wp.array(dtype=wp.vec3),
        alpha: wp.array(dtype=float),
        eta: wp.array(dtype=float),
        out: wp.array2d(dtype=float),
    ):
        k = wp.tid()
        a = alpha[k]
        e = eta[k]
        vi = i[k]
        vo = o[k]
        NoI = wp.abs(vi[2])
        NoO = wp.abs(vo[2])
        if vo[2] > 0.0:  # reflection: h_r = normalize(i + o)
            h = wp.normalize(vi + vo)
            IoH = wp.dot(vi, h)
            out[k, 0] = td.f_dielectric_reflection(
                D(h, a), G2(NoI, NoO, h[2], IoH, a), fresnel.F_dielectric(e, IoH), NoI, NoO
            )
        else:
            h = td.half_vector_transmission(vi, vo, e)
            IoH = wp.dot(vi, h)
            OoH = wp.dot(vo, h)
            out[k, 0] = td.f_dielectric_transmission(
                D(h, a), G2(NoI, NoO, h[2], IoH, a), fresnel.F_dielectric(e, wp.abs(IoH)), NoI, NoO, IoH, OoH, e
            )
        # the reflected / refracted direction terms, for the tests
        out[k, 1] = reflect(vi, wp.vec3(0.0, 0.0, 1.0))[2]
        out[k, 2] = td.refract(vi, wp.vec3(0.0, 0.0, 1.0), e)[2]

    return eval_bsdf


def evaluate_bsdf(i, o, alpha, eta, masking="smith_separable") -> np.ndarray:
    """f(i, o) of the Warp terms (f_r for o above the surface, f_t below); i above (n.i > 0), eta = eta_o / eta_i."""
    i, o = (np.ascontiguousarray(np.asarray(x, np.float32).reshape(-1, 3)) for x in (i, o))
    n = len(i)
    a, e = (np.ascontiguousarray(np.broadcast_to(np.asarray(x, np.float32), (n,))) for x in (alpha, eta))
    out = wp.zeros((n, 3), dtype=float, device="cpu")
    wp.launch(
        _bsdf_kernel(masking),
        dim=n,
        device="cpu",
        inputs=[
            wp.array(i, dtype=wp.vec3),
            wp.array(o, dtype=wp.vec3),
            wp.array(a, dtype=float),
            wp.array(e, dtype=float),
            out,
        ],
    )
    return out.numpy()[:, 0].astype(np.float64)


def random_directions(rng, n, upper=True):
    z = rng.uniform(0.05, 1.0, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    s = np.sqrt(1 - z * z)
    d = np.stack([s * np.cos(phi), s * np.sin(phi), z if upper else -z], axis=1)
    return d


def _facet_cosines(i, o, eta):
    """(i.h, o.h) of each pair's half vector (reflection: o above; transmission: o below)."""
    up = o[:, 2:3] > 0
    h = np.where(up, i + o, -(i + eta[:, None] * o))
    h = h / np.linalg.norm(h, axis=1, keepdims=True)
    h = h * np.sign(h[:, 2:3])
    return np.sum(i * h, axis=1), np.sum(o * h, axis=1)


def _well_conditioned(i, o, eta):
    """Pairs away from the places where float32 terms are ill-conditioned: a facet cosine below RECIPROCITY_MIN_COS
    (1 - F -> 0 by cancellation) or within RECIPROCITY_KINK_GAP of cos theta_c (F' is infinite at the TIR kink, so
    the float32 rounding of i.h against o.h is amplified without bound)."""
    ih, oh = _facet_cosines(i, o, eta)
    ok = (np.abs(ih) >= RECIPROCITY_MIN_COS) & (np.abs(oh) >= RECIPROCITY_MIN_COS)
    for c, e in ((ih, eta), (np.abs(oh), 1.0 / eta)):  # the critical facet cosine on either side
        cc = np.sqrt(np.clip(1.0 - e * e, 0.0, 1.0))
        ok &= (e >= 1.0) | (np.abs(np.abs(c) - cc) >= RECIPROCITY_KINK_GAP)
    return ok


def reciprocity_errors(masking="smith_separable") -> tuple[float, float, float]:
    """(max relative error of f_r(i, o) = f_r(o, i), of f_t(i -> o)/eta^2 = f_t(o -> i), both over well-conditioned
    pairs; and the max over every pair) at random pairs."""
    rng = np.random.default_rng(SEED)
    n = RECIPROCITY_PAIRS
    i, o_up, o_dn = random_directions(rng, n), random_directions(rng, n), random_directions(rng, n, upper=False)
    alpha = rng.uniform(0.05, 1.0, n)
    eta = rng.choice(np.array(ETAS), n)
    fr_io, fr_oi = evaluate_bsdf(i, o_up, alpha, eta, masking), evaluate_bsdf(o_up, i, alpha, eta, masking)
    # i -> o crosses from index 1 into eta; the reverse path o -> i starts in eta: relative index 1/eta, seen from
    # o's side (the frame flipped, z -> -z, so that o is above)
    flip = np.array([1.0, 1.0, -1.0])
    ft_io = evaluate_bsdf(i, o_dn, alpha, eta, masking) / eta**2
    ft_oi = evaluate_bsdf(o_dn * flip, i * flip, alpha, 1.0 / eta, masking)
    rel = []
    for a, b, o in ((fr_io, fr_oi, o_up), (ft_io, ft_oi, o_dn)):
        big = np.maximum(a, b) > 0
        rel.append((np.abs(a - b)[big] / np.maximum(a, b)[big], _well_conditioned(i, o, eta)[big]))
    (rr, okr), (rt, okt) = rel
    return float(rr[okr].max()), float(rt[okt].max()), float(max(rr.max(), rt.max()))


def dielectric_reciprocity():
    worst, every = 0.0, 0.0
    for m in ("smith_separable", "smith_height_correlated"):
        r, t, a = reciprocity_errors(m)
        worst, every = max(worst, r, t), max(every, a)
    return check_result(
        "dielectric_reciprocity",
        worst,
        RECIPROCITY_RTOL,
        f"max relative |f_r(i,o) - f_r(o,i)| and |f_t(i->o)/eta_o^2 - f_t(o->i)/eta_i^2| over "
        f"{RECIPROCITY_PAIRS} random pairs per lobe and masking, alpha in [0.05, 1], eta in {ETAS}, facet "
        f"cosines >= {RECIPROCITY_MIN_COS} and >= {RECIPROCITY_KINK_GAP} from cos theta_c (float32 "
        f"conditioning; over every pair: {every:.1e})",
    )


def energy_grid():
    mu = np.array([0.01, 0.05, 0.2, 0.5, 0.8, 1.0])
    alpha = np.array([1e-3, 0.05, 0.2, 0.5, 1.0])
    M, A, E = (x.ravel() for x in np.meshgrid(mu, alpha, np.array(ETAS), indexing="ij"))
    return M, A, E


def dielectric_energy_le_one():
    M, A, E = energy_grid()
    e = _integrate(M, A, E)
    s = e[:, 0] + e[:, 1]
    k = int(np.argmax(1 - s))
    return check_result(
        "dielectric_energy_le_one",
        max(float(s.max()) - 1.0, 0.0),
        ENERGY_TOL,
        f"max E_R + E_T - 1 over {len(M)} (mu, alpha, eta); largest loss 1 - (E_R + E_T) = {1 - s[k]:.4f} at "
        f"mu = {M[k]}, alpha = {A[k]}, eta = {E[k]} (high roughness, grazing)",
    )


def dielectric_estimators_agree():
    mu = np.array([0.1, 0.5, 0.9, 0.3, 0.7], np.float32)
    alpha = np.array([0.3, 0.05, 0.6, 0.5, 0.15], np.float32)
    eta = np.array([1.5, 0.67, 1.33, 0.75, 0.9], np.float32)
    a = _integrate(mu, alpha, eta)
    b = _integrate(mu, alpha, eta, estimator="sobol_vndf", samples=1 << 16)
    return check_result(
        "dielectric_estimators_agree",
        float(np.max(np.abs(a - b))),
        ESTIMATOR_TOL,
        "max |gauss_legendre - sobol_vndf (2^16)| over 5 texels x (E_R, E_T, E_R + E_T)",
    )


RATIO_RECIPROCITY_TOL = 1.0e-7  # float32-stored channels; the relation holds exactly in float64
RATIO_ROW_PAIRS = ((3, 28), (12, 19))  # OpenPBR IOR indices z and 31 - z: eta = 1/2.3 and 2.3, 1/1.3 and 1.3
RATIO_ALPHAS = (20, 32)  # alpha index range (sqrt(alpha) = i/31) of the probed texels


def openpbr_ratio_rows():
    """{IOR index z: (n, 4) float64 rows of the openpbr dielectric_avg layout at RATIO_ALPHAS} for RATIO_ROW_PAIRS,
    baked by the kind's own plan (each tile computes its mirror row's averages itself)."""
    from ..config import validate_table
    from ..pipeline import plan_of

    raw = {"name": "openpbr_ratio_check", "kind": "dielectric_avg", "layout": "openpbr"}
    plan = plan_of(validate_table(raw, "<openpbr_reflection_ratio_reciprocity>", 0))
    lo, hi = RATIO_ALPHAS
    rows = {}
    for pair in RATIO_ROW_PAIRS:
        for z in pair:
            rows[z] = np.asarray(plan.run_tile(z * 32 + lo, z * 32 + hi, "cpu"), np.float32).astype(np.float64)
    return rows


def openpbr_reflection_ratio_reciprocity():
    from ..integrands.dielectric_ratio import reciprocity_residual

    rows = openpbr_ratio_rows()
    res = [reciprocity_residual(rows[a][:, 3], rows[a][:, 0], rows[b][:, 3], rows[b][:, 0]) for a, b in RATIO_ROW_PAIRS]
    x = np.concatenate([r[:, 3] for r in rows.values()])
    out_of_range = float(max(0.0, -x.min(), x.max() - 1.0))
    return check_result(
        "openpbr_reflection_ratio_reciprocity",
        max(float(np.max(np.abs(res))), out_of_range),
        RATIO_RECIPROCITY_TOL,
        f"max |(1 - x(eta)) E_c,avg(eta) - (1 - x(1/eta)) E_c,avg(1/eta)| (and how far x leaves [0, 1]) over IOR "
        f"index pairs {RATIO_ROW_PAIRS} x alpha indices {RATIO_ALPHAS[0]}..{RATIO_ALPHAS[1] - 1} of the openpbr "
        f"dielectric_avg table; x ranges {x.min():.4f}..{x.max():.4f}",
    )


TABLE = (  # lutbake.validate.checks.TABLE lists them among its own
    Check("dielectric_smooth_limit", dielectric_smooth_limit),
    Check("dielectric_index_matched", dielectric_index_matched),
    Check("dielectric_reciprocity", dielectric_reciprocity),
    Check("dielectric_energy_le_one", dielectric_energy_le_one),
    Check("dielectric_estimators_agree", dielectric_estimators_agree),
    Check("openpbr_reflection_ratio_reciprocity", openpbr_reflection_ratio_reciprocity),
)
