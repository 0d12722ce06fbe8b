"""Named checks: analytic reductions and invariants of the terms, of the specular tables and of the microfacet
diffuse model (sigma = 0 limit, reciprocity, albedo <= 1).

Each check returns a :class:`CheckResult` (measured error, tolerance, pass/fail, a one-line detail).
``TABLE`` lists every check as a :class:`Check` record (name, zero-argument callable), lutbake.validate.dielectric's
among them; ``CHECKS`` maps the names to the callables; ``run_all()`` runs them all.
Parametrised checks carry their parameters in the name: ``weak_white_furnace[ggx]``.

The host-side quadratures are lutbake.validate.quadrature's (not the estimators of :mod:`lutbake.sampling`);
the term values come from the Warp ``@wp.func``s themselves (:mod:`.probe`).
"""

from __future__ import annotations

import functools

import numpy as np

from ..edge import ALPHA_MIN, NOV_MIN
from ..integrands.specular import hemisphere_integral
from ..registry import Record, family
from ..sampling import points
from ..terms.distributions import NDFS
from . import dielectric
from .probe import BRDF_PAIRS, evaluate_brdfs, evaluate_terms
from .quadrature import CUT_FIRST_PANEL, GL_NODES, composite_gl, direction, graded_edges, sphere_quadrature
from .results import Check, CheckResult, check_result

# Tolerances (absolute unless said otherwise). The terms run in float32: ~1e-7 is the floor.
PROJECTED_AREA_TOL = 1.0e-6  # |∫ D(m)(n.m) dω_m - 1|
WEAK_FURNACE_TOL = 1.0e-6  # |∫ G1(v) max(0, v.m) D(m) dω_m - n.v|
# E(F = 1) <= 1 + tol everywhere, and |E - 1| <= tol at alpha = ALPHA_MIN, n.v >= 0.05. At alpha > 0 the limit
# is not exact: GGX's tail puts a fraction ~alpha^2 / theta_a^2 of the normals where l falls below the horizon
# (theta_a = (pi/2 - theta_v)/2), 2e-6 at alpha = 1e-4, n.v = 0.05, shrinking as alpha^2.
ALBEDO_TOL = 1.0e-5
# |scale - (1 - (1 - n.v)^5)|, |bias - (1 - n.v)^5| at alpha = ALPHA_MIN, n.v >= 0.05: the same tail plus the
# spread of v.h about n.v give 7e-6 at n.v = 0.05 (it shrinks as alpha^2: 5e-7 at alpha = 3e-5).
DFG_MIRROR_TOL = 2.0e-5
RECIPROCITY_RTOL = 1.0e-6  # |f(l, v) - f(v, l)| / max(f(l, v), f(v, l)), relative: a few float32 roundings
FRESNEL_EQ2_TOL = 2.0e-6  # |Eq. 2 (f0, c) - F_dielectric((1 + sqrt f0) / (1 - sqrt f0), c)|, f0 <= 0.95
SCHLICK_ENDPOINT_TOL = 2.4e-7  # |F_schlick(f0, 1) - f0|, |F_schlick(f0, 0) - 1|: two float32 ulps at 1
ESTIMATOR_AGREEMENT_TOL = 5.0e-5  # |gauss_legendre - sobol_vndf (2^16 samples)| per channel
# Charlie: D evaluates pow(sin^2, 1/(2 alpha)) in float32, which multiplies the rounding of sin^2 (~6e-8 near 1)
# by 1/(2 alpha) = 500 at alpha = 1e-3: measured 3.2e-6 there, < 1e-7 at alpha >= 0.1.
CHARLIE_AREA_TOL = 1.0e-5
ANISO_AREA_TOL = 1.0e-6  # |∫ D_ggx_aniso(m)(n.m) dω_m - 1|
AS_DENSITY_TOL = 1.0e-6  # |∫ p_h(m) dω_m - 1| of Ashikhmin-Shirley's half-vector density
ANISO_FURNACE_TOL = 1.0e-6  # |∫ G1(v) max(0, v.m) D_ggx_aniso(m) dω_m - n.v|
# Kulla-Conty: |E + E_ms - 1| with E_ms integrated over the albedo table's own midpoint grid in n.l (as a shader
# would). For r >= 0.1 the residual is the midpoint rule's error; on the smoothest row (alpha ~ 2e-3) the whole
# loss 1 - E sits within n.l < alpha, inside the first texel, so the midpoint estimate of ∫(1 - E) mu dmu is off by a
# few percent of a 2e-5 loss: a limit of the 96-column grid, not of the model.
KC_FURNACE_TOL = 2.0e-5  # rows with r >= 0.1
KC_FURNACE_TOL_SMOOTHEST = 5.0e-3  # every row

# Grids.
PROJECTED_AREA_ALPHAS = (1.0e-3, 1.0e-2, 0.1, 0.5, 1.0)
ANISOTROPIES = (
    0.5,
    1.0,
    -1.0,
)  # with PROJECTED_AREA_ALPHAS, through the Burley mapping (integrands.anisotropic.alpha_xy)
ANISO_FURNACE_NOVS = (0.1, 0.5, 1.0)
ANISO_FURNACE_PHIS = (0.0, np.pi / 4, np.pi / 2)
ANISO_FURNACE_ALPHAS = (1.0e-2, 0.3)
ANISO_PHI_PANELS = 24  # equal panels in the azimuth (GL_NODES each)
KC_N_MU, KC_N_ROUGH = 96, 12  # the Kulla-Conty furnace's albedo table: [NoV, roughness] texels
FURNACE_NOVS = (0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0)
FURNACE_ALPHAS = (1.0e-3, 1.0e-2, 0.1, 0.5, 1.0)
ALBEDO_COUNT = 24  # texel-centre grid in n.v and perceptual roughness, plus the clamped edges
MIRROR_NOVS = tuple(np.linspace(0.05, 1.0, 20))  # below ~0.05, Lambda(alpha = 1e-4) is not yet negligible
ALBEDO_MASKINGS = ("smith_height_correlated", "smith_separable")
SMITH_NDFS = tuple(n for n, d in NDFS.items() if d.Lambda is not None)  # lutbake's NDFs with a Smith Lambda
DFG_MIRROR_PAIRS = (
    ("ggx", "smith_height_correlated"),
    ("beckmann", "smith_separable"),
    ("beckmann", "v_cavity"),
    ("blinn_phong", "v_cavity"),
)
RECIPROCITY_SAMPLES = 4096
ESTIMATOR_TEXELS = ((0.1, 0.04), (0.3, 1.0), (0.5, 0.25), (0.9, 0.64), (1.0, 0.01))  # (n.v, alpha)
ESTIMATOR_QMC_SAMPLES = 1 << 16
SEED = 20240607

# --- NDF normalisation -----------------------------------------------------------------------------


def ndf_projected_area_is_one(ndf_name: str) -> CheckResult:
    """∫ D(m)(n.m) dω_m = 2 pi ∫_0^{pi/2} D(theta) cos(theta) sin(theta) dtheta = 1 (Walter et al. 2007, Eq. 4),
    composite GL in theta, panels graded geometrically from the pole at the NDF's scale atan(alpha)."""
    err, detail = _projected_area(f"D_{ndf_name}", lambda alpha: (0.0, np.arctan(alpha) / 16.0))
    return check_result(f"ndf_projected_area_is_one[{ndf_name}]", err, PROJECTED_AREA_TOL, detail)


def _projected_area(term: str, grade_at) -> tuple[float, str]:
    """max over PROJECTED_AREA_ALPHAS of |2 pi ∫ D cos sin dtheta - 1| for the term ``term``, by composite GL with
    panels graded towards grade_at(alpha) = (point, scale); and the check's detail line."""
    errors = []
    for alpha in PROJECTED_AREA_ALPHAS:
        theta, w = composite_gl(graded_edges(0.0, np.pi / 2, [grade_at(alpha)]))
        D = evaluate_terms(h=direction(theta), alpha=alpha, names=[term])[term].astype(np.float64)
        errors.append(abs(2.0 * np.pi * np.sum(w * D * np.cos(theta) * np.sin(theta)) - 1.0))
    k = int(np.argmax(errors))
    where = f"worst at alpha={PROJECTED_AREA_ALPHAS[k]}"
    return errors[k], f"max |∫{term}(m)(n.m)dω - 1| over alpha in {PROJECTED_AREA_ALPHAS}; {where}"


def charlie_projected_area_is_one() -> CheckResult:
    """The Charlie sheen NDF (Estevez & Kulla 2017), D = (2 + 1/alpha) sin(theta)^(1/alpha) / (2 pi), is
    normalised in projected area: 2 pi ∫ D cos sin dtheta = 1. Its mass sits within ~sqrt(alpha) of the
    horizon, so the panels are graded towards theta = pi/2."""
    err, detail = _projected_area("D_charlie", lambda alpha: (np.pi / 2, np.sqrt(alpha) / 16.0))
    return check_result("ndf_projected_area_is_one[charlie]", err, CHARLIE_AREA_TOL, detail)


def weak_white_furnace(ndf_name: str) -> CheckResult:
    """∫ G1(v) max(0, v.m) D(m) dω_m = n.v: the visible microsurface projects onto the view as the
    geometric surface does (Heitz 2014, JCGT 3(2), Sec. 3), with G1 = 1/(1 + Lambda(v)).

    v = (sin theta_v, 0, cos theta_v), m at (theta, phi). v.m > 0 iff cos(phi) > c(theta) = -cot(theta_v) cot(theta):
    for theta < pi/2 - theta_v every phi, beyond it phi in [0, acos c] (by symmetry, twice the integral
    over phi in [0, pi]). Composite GL in theta (panels at the NDF scale from the pole, and graded on
    both sides of the cut start pi/2 - theta_v) times GL in phi over the exact visible interval."""
    errors = []
    where = []
    for nov in FURNACE_NOVS:
        sin_v = np.sqrt(max(1.0 - nov * nov, 0.0))
        theta_c = np.pi / 2 - np.arccos(nov)
        for alpha in FURNACE_ALPHAS:
            edges = graded_edges(0.0, np.pi / 2, [(0.0, np.arctan(alpha) / 16.0), (theta_c, CUT_FIRST_PANEL)])
            theta, wt = composite_gl(edges)
            with np.errstate(divide="ignore"):
                c = np.where(theta < theta_c, -1.0, -nov / max(sin_v, 1e-300) / np.tan(theta))
            phimax = np.arccos(np.clip(c, -1.0, 1.0))
            s, ws = points.gauss_legendre(GL_NODES)
            phi = phimax[:, None] * s
            wphi = phimax[:, None] * ws
            h = direction(theta[:, None], phi)
            terms = evaluate_terms(h=h, alpha=alpha, nov=nov, names=[f"D_{ndf_name}", f"G1_smith_{ndf_name}"])
            D = terms[f"D_{ndf_name}"].astype(np.float64)
            G1 = float(terms[f"G1_smith_{ndf_name}"].ravel()[0])
            vom = sin_v * h[..., 0].astype(np.float64) + nov * h[..., 2].astype(np.float64)
            inner = np.sum(wphi * np.maximum(vom, 0.0) * D, axis=1)
            integral = 2.0 * G1 * np.sum(wt * np.sin(theta) * inner)
            errors.append(abs(integral - nov))
            where.append((nov, alpha))
    k = int(np.argmax(errors))
    grid = f"n.v in {FURNACE_NOVS} x alpha in {FURNACE_ALPHAS}"
    detail = f"max |∫G1(v)max(0,v.m)D(m)dω - n.v| over {grid}; worst at (n.v, alpha)={where[k]}"
    return check_result(f"weak_white_furnace[{ndf_name}]", errors[k], WEAK_FURNACE_TOL, detail)


def _aniso_pairs(alphas=PROJECTED_AREA_ALPHAS) -> list[tuple[float, float, float, float]]:
    """(alpha, a, alpha_x, alpha_y) through the Burley mapping of the specular_aniso kind."""
    from ..integrands.anisotropic import alpha_xy

    out = []
    for alpha in alphas:
        for a in ANISOTROPIES:
            ax, ay = alpha_xy(np.array([alpha]), np.array([a]))
            out.append((alpha, a, float(ax[0]), float(ay[0])))
    return out


def _aniso_measure(term: str, weight, horizon: bool = False) -> tuple[float, tuple]:
    """max over _aniso_pairs of |2D integral of term(m) weight(theta) over the hemisphere - 1|; the azimuth on
    [0, pi/2] (the lobes are symmetric in x and y) graded from both ends, times 4."""
    errors, where = [], []
    phi, wphi = composite_gl(graded_edges(0.0, np.pi / 2, [(0.0, 1.0e-3), (np.pi / 2, 1.0e-3)]))
    for alpha, a, ax, ay in _aniso_pairs():
        theta, wt = sphere_quadrature(min(ax, ay), horizon=horizon)
        h = direction(theta[:, None], phi[None, :])
        D = evaluate_terms(h=h, alpha=ax, alpha_y=ay, names=[term])[term].astype(np.float64)
        val = 4.0 * np.sum((wt * weight(theta))[:, None] * wphi[None, :] * D)
        errors.append(abs(val - 1.0))
        where.append((alpha, a))
    k = int(np.argmax(errors))
    return errors[k], where[k]


def ndf_projected_area_is_one_aniso() -> CheckResult:
    """Anisotropic GGX: ∫ D(m)(n.m) dω_m = ∫∫ D cos(theta) sin(theta) dtheta dphi = 1 for (alpha_x, alpha_y) of
    alpha in PROJECTED_AREA_ALPHAS x anisotropy in ANISOTROPIES (Burley mapping); composite GL in theta graded
    from the pole at atan(min(alpha_x, alpha_y)) and in phi graded towards both axes."""
    err, where = _aniso_measure("D_ggx_aniso", lambda t: np.cos(t) * np.sin(t))
    return check_result(
        "ndf_projected_area_is_one[ggx_aniso]",
        err,
        ANISO_AREA_TOL,
        f"max |∫D(m)(n.m)dω - 1| over alpha in {PROJECTED_AREA_ALPHAS} x anisotropy in {ANISOTROPIES}; "
        f"worst at (alpha, a)={where}",
    )


def ashikhmin_shirley_density_is_one() -> CheckResult:
    """Ashikhmin & Shirley 2000's half-vector density, p_h = sqrt((nu+1)(nv+1))/(2 pi) (n.h)^(...), integrates to
    1 over the hemisphere (a solid-angle density: ∫ p_h dω = 1, not the projected area), for nu, nv of the
    same (alpha_x, alpha_y) pairs (nu = max(2/alpha_x^2 - 2, 0))."""
    err, where = _aniso_measure("D_ashikhmin_shirley", lambda t: np.sin(t), horizon=True)
    return check_result(
        "ashikhmin_shirley_density_is_one",
        err,
        AS_DENSITY_TOL,
        f"max |∫p_h dω - 1| over alpha in {PROJECTED_AREA_ALPHAS} x anisotropy in {ANISOTROPIES}; "
        f"worst at (alpha, a)={where}",
    )


def weak_white_furnace_aniso() -> CheckResult:
    """Anisotropic GGX with its anisotropic Smith Lambda: ∫ G1(v) max(0, v.m) D(m) dω_m = n.v for v at
    n.v in ANISO_FURNACE_NOVS and azimuth phi_v in ANISO_FURNACE_PHIS (from the tangent).
    v.m > 0 iff cos(phi - phi_v) > c(theta) = -cot(theta_v) cot(theta): with psi = phi - phi_v the visible
    azimuths are |psi| < acos(c) (all of them below theta = pi/2 - theta_v); composite GL in theta (graded
    from the pole and about the cut start) times ANISO_PHI_PANELS equal GL panels in psi over the exact interval."""
    errors, where = [], []
    s, ws = composite_gl(np.linspace(-1.0, 1.0, ANISO_PHI_PANELS + 1))
    for alpha, a, ax, ay in _aniso_pairs(ANISO_FURNACE_ALPHAS):
        for nov in ANISO_FURNACE_NOVS:
            sin_v = np.sqrt(max(1.0 - nov * nov, 0.0))
            theta_c = np.pi / 2 - np.arccos(nov)
            theta, wt = sphere_quadrature(min(ax, ay), theta_c)
            with np.errstate(divide="ignore"):
                c = np.where(theta < theta_c, -1.0, -nov / max(sin_v, 1e-300) / np.tan(theta))
            psimax = np.arccos(np.clip(c, -1.0, 1.0))
            for phi_v in ANISO_FURNACE_PHIS:
                v = np.array([sin_v * np.cos(phi_v), sin_v * np.sin(phi_v), nov])
                psi = psimax[:, None] * s[None, :]
                h = direction(theta[:, None], phi_v + psi)
                D = evaluate_terms(h=h, alpha=ax, alpha_y=ay, names=["D_ggx_aniso"])["D_ggx_aniso"].astype(np.float64)
                lam = float(evaluate_terms(v=v, alpha=ax, alpha_y=ay, names=["Lambda_ggx_aniso"])["Lambda_ggx_aniso"])
                vom = np.maximum(h.astype(np.float32).astype(np.float64) @ v, 0.0)
                inner = np.sum(psimax[:, None] * ws[None, :] * vom * D, axis=1)
                integral = np.sum(wt * np.sin(theta) * inner) / (1.0 + lam)
                errors.append(abs(integral - nov))
                where.append((nov, round(phi_v, 4), alpha, a))
    k = int(np.argmax(errors))
    return check_result(
        "weak_white_furnace[ggx_aniso]",
        errors[k],
        ANISO_FURNACE_TOL,
        f"max |∫G1(v)max(0,v.m)D(m)dω - n.v| over n.v in {ANISO_FURNACE_NOVS} x phi_v in {{0, pi/4, pi/2}} "
        f"x alpha in {ANISO_FURNACE_ALPHAS} x anisotropy in {ANISOTROPIES}; worst at (n.v, phi_v, alpha, a)={where[k]}",
    )


def kulla_conty_residual(E: np.ndarray, E_avg: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """E(mu_o) + ∫ f_ms(mu_o, mu_i) mu_i dω_i - 1 for every texel of an albedo table E (rows = roughness,
    columns = mu = n.v), with f_ms = (1 - E(mu_o))(1 - E(mu_i)) / (pi (1 - E_avg)) (Kulla & Conty 2017) and the
    mu_i integral by the midpoint rule on the table's texel centres (as a shader would sum it)."""
    E = E.astype(np.float64)
    dmu = 1.0 / len(mu)
    loss = 2.0 * np.pi * np.sum((1.0 - E) * mu * dmu, axis=1) / np.pi  # ∫(1 - E(mu_i)) mu_i dω_i / pi
    E_ms = (1.0 - E) * (loss / np.maximum(1.0 - E_avg.astype(np.float64), 1e-12))[:, None]
    return E + E_ms - 1.0


def kulla_conty_white_furnace() -> CheckResult:
    """The energy-compensated BRDF (single scattering + Kulla-Conty's f_ms) reflects everything at F = 1:
    E + E_ms = 1 for every n.v and roughness. Bakes the default ``albedo`` (GGX, height-correlated Smith;
    KC_N_MU x KC_N_ROUGH) and ``albedo_avg`` tables and measures max |E + E_ms - 1| per roughness row
    (kulla_conty_residual). Measured: the worst row with r >= 0.1 (tolerance KC_FURNACE_TOL); the smoothest rows
    must stay within KC_FURNACE_TOL_SMOOTHEST (module constants)."""
    from ..config import validate_table
    from ..pipeline import bake_table

    e = bake_table(validate_table({"name": "e", "kind": "albedo", "size": [KC_N_MU, KC_N_ROUGH]}, "<check>", 0))[0]
    avg = bake_table(validate_table({"name": "a", "kind": "albedo_avg", "roughness_size": KC_N_ROUGH}, "<check>", 0))[0]
    mu = e.axes[1].values().astype(np.float64)
    worst = np.max(np.abs(kulla_conty_residual(e.data[..., 0], avg.data[0, :, 0], mu)), axis=1)
    rough = e.axes[0].values()
    measured = float(np.max(worst[rough >= 0.1]))
    if np.max(worst) > KC_FURNACE_TOL_SMOOTHEST:
        measured = float("inf")
    loss = float(np.max(1.0 - e.data[..., 0]))
    smooth = rough < 0.1
    rows = ", ".join(f"r={r:.3f}: {w:.1e}" for r, w in zip(rough[smooth], worst[smooth]))
    return check_result(
        "kulla_conty_white_furnace",
        measured,
        KC_FURNACE_TOL,
        "max |E + E_ms - 1| over the roughness rows with r >= 0.1 (inf if any row exceeds "
        f"{KC_FURNACE_TOL_SMOOTHEST:.0e})",
        (
            f"rows with r < 0.1: max |E + E_ms - 1| {rows}; their own tolerance {KC_FURNACE_TOL_SMOOTHEST:.0e} "
            f"(their loss sits inside the first n.v texel of the {KC_N_MU}-column table)",
            f"uncompensated max loss 1 - E (before Kulla-Conty): {loss:.3f}",
        ),
    )


# --- tables ------------------------------------------------------------------------------------------


# (ndf, masking, channels, nov, alpha, estimator="gauss_legendre", samples=None) -> (N, C), at the checks' seed
_integrate = functools.partial(hemisphere_integral, seed=SEED)


def albedo_le_one_and_mirror_limit(ndf_name: str, masking_name: str) -> CheckResult:
    """Directional albedo with F = 1, E(n.v, alpha) = ∫ f (n.l) dω_l (channels "albedo", gauss_legendre):
    E <= 1 on a texel-centre grid (plus n.v = NOV_MIN and alpha in {ALPHA_MIN, 1}), and E -> 1 at
    alpha = ALPHA_MIN for n.v in [0.05, 1]. Measured: the larger of max(E - 1) and max |E(ALPHA_MIN) - 1|."""
    t = (np.arange(ALBEDO_COUNT) + 0.5) / ALBEDO_COUNT
    novs = np.concatenate([[NOV_MIN], t, [1.0]])
    alphas = np.concatenate([[ALPHA_MIN], t * t, [1.0]])
    N, A = np.meshgrid(novs, alphas, indexing="ij")
    E = _integrate(ndf_name, masking_name, "albedo", N.ravel(), A.ravel())[:, 0].reshape(N.shape)
    excess = float(np.max(E - 1.0))
    i, j = np.unravel_index(np.argmax(E), E.shape)
    mirror = _integrate(ndf_name, masking_name, "albedo", MIRROR_NOVS, np.full(len(MIRROR_NOVS), ALPHA_MIN))[:, 0]
    mirror_err = float(np.max(np.abs(mirror - 1.0)))
    return check_result(
        f"albedo_le_one_and_mirror_limit[{ndf_name},{masking_name}]",
        max(excess, mirror_err),
        ALBEDO_TOL,
        f"the larger of max(E - 1) on a {len(novs)}x{len(alphas)} (n.v, alpha) grid and max "
        f"|E(alpha={ALPHA_MIN}) - 1| for n.v in [0.05, 1]",
        (
            f"max(E - 1) = {excess:.3e} at (n.v, alpha) = ({N[i, j]:.4g}, {A[i, j]:.4g})",
            f"max |E(alpha={ALPHA_MIN}) - 1| = {mirror_err:.3e}",
        ),
    )


def dfg_mirror_limit(ndf_name: str, masking_name: str) -> CheckResult:
    """alpha -> 0 (alpha = ALPHA_MIN): D -> delta at n, h = n, v.h = n.v, G2 -> 1, so the split-sum
    channels reduce to Schlick at the mirror direction: scale -> 1 - (1 - n.v)^5, bias -> (1 - n.v)^5."""
    nov = np.asarray(MIRROR_NOVS)
    sb = _integrate(ndf_name, masking_name, "scale_bias", nov, np.full(len(nov), ALPHA_MIN))
    fc = (1.0 - nov.astype(np.float32).astype(np.float64)) ** 5
    err = np.maximum(np.abs(sb[:, 0] - (1.0 - fc)), np.abs(sb[:, 1] - fc))
    k = int(np.argmax(err))
    what = f"|scale - (1-(1-n.v)^5)|, |bias - (1-n.v)^5| at alpha={ALPHA_MIN}"
    detail = f"max over n.v in [0.05, 1] of {what}; worst at n.v={nov[k]:.4g}"
    return check_result(f"dfg_mirror_limit[{ndf_name},{masking_name}]", err[k], DFG_MIRROR_TOL, detail)


def estimators_agree() -> CheckResult:
    """The default DFG table (GGX, height-correlated Smith, scale/bias) under two unrelated estimators:
    product Gauss-Legendre vs scrambled Sobol' with visible-normal sampling, 2^16 points."""
    nov, alpha = (np.array(a) for a in zip(*ESTIMATOR_TEXELS))
    gl = _integrate("ggx", "smith_height_correlated", "scale_bias", nov, alpha)
    qmc = _integrate("ggx", "smith_height_correlated", "scale_bias", nov, alpha, "sobol_vndf", ESTIMATOR_QMC_SAMPLES)
    err = np.abs(gl - qmc)
    k = int(np.argmax(err.max(axis=1)))
    return check_result(
        "estimators_agree",
        err.max(),
        ESTIMATOR_AGREEMENT_TOL,
        f"max |gauss_legendre - sobol_vndf(2^16)| over (n.v, alpha) in {ESTIMATOR_TEXELS}, "
        f"channels scale, bias; worst at {ESTIMATOR_TEXELS[k]}",
    )


# --- BRDF and Fresnel identities ---------------------------------------------------------------------


@functools.lru_cache(maxsize=1)
def _reciprocity_brdfs() -> tuple[dict, dict]:
    rng = np.random.default_rng(SEED)
    n = RECIPROCITY_SAMPLES

    def directions():
        cos_t = rng.uniform(0.0, 1.0, n) ** 2  # biased towards grazing
        phi = rng.uniform(0.0, 2.0 * np.pi, n)
        s = np.sqrt(1.0 - cos_t * cos_t)
        return np.stack([s * np.cos(phi), s * np.sin(phi), cos_t], axis=-1)

    l, v = directions(), directions()
    alpha = rng.uniform(0.1, 1.0, n) ** 2
    f0 = rng.uniform(0.0, 1.0, n)
    return evaluate_brdfs(l, v, alpha, f0), evaluate_brdfs(v, l, alpha, f0)


def reciprocity(ndf_name: str, masking_name: str) -> CheckResult:
    """Helmholtz reciprocity f(l, v) = f(v, l) of the assembled specular BRDF (probe.specular_brdf_for) at
    random direction pairs (n.l, n.v biased towards grazing), alpha = r^2, r in [0.1, 1], f0 in [0, 1]."""
    fwd, bwd = _reciprocity_brdfs()
    a = fwd[(ndf_name, masking_name)].astype(np.float64)
    b = bwd[(ndf_name, masking_name)].astype(np.float64)
    scale = np.maximum(np.maximum(np.abs(a), np.abs(b)), np.finfo(np.float64).tiny)
    rel = np.where((a == 0.0) & (b == 0.0), 0.0, np.abs(a - b) / scale)
    nonzero = int(np.count_nonzero(a))
    return check_result(
        f"reciprocity[{ndf_name},{masking_name}]",
        rel.max(),
        RECIPROCITY_RTOL,
        f"max relative |f(l,v) - f(v,l)| over {RECIPROCITY_SAMPLES} random pairs ({nonzero} nonzero)",
    )


def fresnel_eq2_is_exact_dielectric() -> CheckResult:
    """Gotanda 2014, Eq. 2 (F_dielectric_f0) equals the exact dielectric Fresnel with eta = (1 + s)/(1 - s),
    s = sqrt(f0), on f0 in [0, 0.95] x cos in [0, 1]."""
    f0 = np.linspace(0.0, 0.95, 96)[:, None]
    c = np.linspace(0.0, 1.0, 101)[None, :]
    s = np.sqrt(f0.astype(np.float32).astype(np.float64))
    eq2 = evaluate_terms(f0=f0, cos_theta=c, names=["F_dielectric_f0"])["F_dielectric_f0"].astype(np.float64)
    exact = evaluate_terms(eta=(1.0 + s) / (1.0 - s), cos_theta=c, names=["F_dielectric"])["F_dielectric"].astype(
        np.float64
    )
    err = np.abs(eq2 - exact)
    i, j = np.unravel_index(np.argmax(err), err.shape)
    return check_result(
        "fresnel_eq2_is_exact_dielectric",
        err.max(),
        FRESNEL_EQ2_TOL,
        f"max |F_dielectric_f0(f0, c) - F_dielectric(eta(f0), c)| on 96 f0 x 101 c; "
        f"worst at (f0, c)=({f0[i, 0]:.3g}, {c[0, j]:.3g})",
    )


def schlick_endpoints() -> CheckResult:
    """F_schlick(f0, 1) = f0 and F_schlick(f0, 0) = 1 for f0 in [0, 1]."""
    f0 = np.linspace(0.0, 1.0, 101)
    at_normal = evaluate_terms(f0=f0, cos_theta=1.0, names=["F_schlick"])["F_schlick"].astype(np.float64)
    at_grazing = evaluate_terms(f0=f0, cos_theta=0.0, names=["F_schlick"])["F_schlick"].astype(np.float64)
    err_n = np.max(np.abs(at_normal - f0.astype(np.float32)))
    err_g = np.max(np.abs(at_grazing - 1.0))
    return check_result(
        "schlick_endpoints",
        max(err_n, err_g),
        SCHLICK_ENDPOINT_TOL,
        "the larger of max |F(f0, 1) - f0| and max |F(f0, 0) - 1| over 101 f0 in [0, 1]",
        (f"max |F(f0, 1) - f0| = {err_n:.3e}", f"max |F(f0, 0) - 1| = {err_g:.3e}"),
    )


# --- microfacet diffuse (Gotanda 2014, Eq. 4) ---------------------------------------------------------

# |f(sigma = 0) - F_diff / pi| / (F_diff / pi), n.l and n.v >= 0.1. The limit is not exact at alpha = ALPHA_MIN:
# GGX's tail gives E[sin^2 theta_m] ~ alpha^2 ln(1 / alpha^2), and (m.l)(m.v) / ((n.l)(n.v)) deviates from 1 by that
# times tan(theta_l) tan(theta_v): 7.8e-5 at n.l, n.v ~ 0.07 (converged in the GL order), ~2e-5 at 0.1.
DIFFUSE_SIGMA0_RTOL = 5.0e-5
DIFFUSE_RECIPROCITY_RTOL = 1.0e-5  # |f(l, v) - f(v, l)| / max: the quadrature's cuts are symmetric in l, v
DIFFUSE_ALBEDO_TOL = 1.0e-6  # max(0, max E - 1) over NoV x sigma x f0 and every facet form
DIFFUSE_PAIRS = 256
DIFFUSE_ORDER = 12


def _random_pairs(n: int, seed: int, min_cos: float = 0.0):
    rng = np.random.default_rng(seed)
    cl = rng.uniform(min_cos, 1.0, n)
    cv = rng.uniform(min_cos, 1.0, n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    sl, sv = np.sqrt(1 - cl * cl), np.sqrt(1 - cv * cv)
    return np.stack([sl * np.cos(phi), sl * np.sin(phi), cl], -1), np.stack([sv, 0 * sv, cv], -1)


def diffuse_sigma0_is_lambert_eq6() -> CheckResult:
    """At sigma = 0 (alpha = ALPHA_MIN) the microfacet diffuse BRDF (Eq. 4, facets with Eq. 6) is Lambert x Eq. 6:
    F_diff(n.l, n.v, f0) / pi, for every pair with n.l, n.v >= 0.1 (the limit needs alpha << n.x)."""
    from ..integrands.diffuse import eval_brdf

    l, v = _random_pairs(DIFFUSE_PAIRS, SEED, 0.1)
    worst = 0.0
    for f0 in (0.0, 0.04, 0.5):
        f = eval_brdf("microfacet", l, v, 0.0, f0, "eq6", "sigma", DIFFUSE_ORDER)
        w = lambda c: 1 - (1 - c) ** 5  # noqa: E731
        ref = 1.05 * (1 - f0) * w(l[:, 2]) * w(v[:, 2]) / np.pi
        worst = max(worst, float(np.max(np.abs(f - ref) / ref)))
    return check_result(
        "diffuse_sigma0_is_lambert_eq6",
        worst,
        DIFFUSE_SIGMA0_RTOL,
        f"max relative over {DIFFUSE_PAIRS} random pairs x f0 in (0, 0.04, 0.5), GL order {DIFFUSE_ORDER}",
    )


def diffuse_reciprocity() -> CheckResult:
    """f(l, v) = f(v, l) for the microfacet diffuse BRDF, random pairs (grazing included), sigma 0.05 .. 1."""
    from ..integrands.diffuse import eval_brdf

    l, v = _random_pairs(DIFFUSE_PAIRS, SEED + 1)
    sigma = np.random.default_rng(SEED + 2).uniform(0.05, 1.0, DIFFUSE_PAIRS)
    a = eval_brdf("microfacet", l, v, sigma, 0.04, "eq6", "sigma", DIFFUSE_ORDER)
    b = eval_brdf("microfacet", v, l, sigma, 0.04, "eq6", "sigma", DIFFUSE_ORDER)
    rel = np.abs(a - b) / np.maximum(np.maximum(a, b), 1e-30)
    return check_result(
        "diffuse_reciprocity",
        float(rel.max()),
        DIFFUSE_RECIPROCITY_RTOL,
        f"max relative over {DIFFUSE_PAIRS} random pairs, sigma in [0.05, 1]",
    )


def diffuse_albedo_le_one() -> CheckResult:
    """The directional albedo E(v) = ∫ f (n.l) dω_l of the microfacet diffuse model is <= 1 for every NoV, sigma, f0
    and per-facet Fresnel form (rho = 1): measured max(0, max E - 1)."""
    from ..integrands.diffuse import albedo_swapped

    nov = np.array([NOV_MIN, 0.01, 0.05, 0.2, 0.5, 0.8, 1.0])
    alpha = np.array([ALPHA_MIN, 0.01, 0.1, 0.3, 0.6, 1.0])
    N, A = (x.ravel() for x in np.meshgrid(nov, alpha))
    worst, top = 0.0, 0.0
    for form in ("eq6", "schlick", "dielectric_f0"):
        for f0 in (0.0, 0.04, 0.5):
            e = albedo_swapped(N, A, f0, form, order=DIFFUSE_ORDER)
            top = max(top, float(e.max()))
            worst = max(worst, float(np.max(e - 1.0)))
    return check_result(
        "diffuse_albedo_le_one",
        max(worst, 0.0),
        DIFFUSE_ALBEDO_TOL,
        f"max(0, E - 1) over {len(N)} (NoV, alpha) x f0 in (0, 0.04, 0.5) x facet forms eq6, schlick, dielectric_f0",
        (f"max E = {top:.7f}",),
    )


LTC_SPHERE_TOL = 1.0e-8  # the integrated sphere table vs Snyder's closed form, relative to the unclipped value


def ltc_sphere_table_is_snyder() -> CheckResult:
    """The LTC sphere/disk table (lutbake.ltc.sphere, baked by integration) against Snyder's closed form of the
    horizon-clipped projected solid angle of a spherical cap (ltc_code fitLTC.cpp ihemi), on a 33 x 33 grid of
    (elevation, half-angle), relative to the unclipped value pi sin^2 sigma."""
    from ..ltc import sphere

    omega, sigma = np.meshgrid(np.linspace(0.0, np.pi, 33), np.linspace(1e-3, np.pi / 2, 33))
    got = sphere.cap_projected_solid_angle(omega, sigma)
    want = np.vectorize(sphere.snyder_cap)(omega, sigma)
    err = np.max(np.abs(got - want) / (np.pi * np.sin(sigma) ** 2))
    return check_result(
        "ltc_sphere_table_is_snyder", err, LTC_SPHERE_TOL, "max |integrated - closed form| / (pi sin^2)"
    )


EON_ALBEDO_TOL = 1.0e-6  # EON (rho = 1) albedo by GL vs 1: measured 1.0e-7
LTC_IDENTITY_TOL = 1.0e-3  # packed M^-1 of a Lambert-like lobe vs (1, 0, 0, 1)


def eon_albedo_is_one() -> CheckResult:
    """The energy-preserving Oren-Nayar (Portsmouth et al. 2024) preserves energy: its directional albedo for rho = 1
    is 1 at every view and roughness (the diffuse kind's GL integrator, order 24, model ``eon``)."""
    from ..integrands.diffuse import albedo_gl

    nov, r = np.meshgrid([0.01, 0.1, 0.3, 0.6, 0.9, 1.0], [0.0, 0.25, 0.5, 0.75, 1.0])
    err = np.max(np.abs(albedo_gl("eon", nov.ravel(), r.ravel(), order=24) - 1.0))
    return check_result("eon_albedo_is_one", err, EON_ALBEDO_TOL, "max |E_EON - 1| over 6 NoV x 5 r, rho = 1")


def ltc_eon_r0_is_identity() -> CheckResult:
    """EON at r = 0 is Lambert: its LTC fit (lutbake.ltc.fit, the kind's seeding) is the identity at every view."""
    from ..kinds.ltc import axes_for
    from ..ltc import fit
    from ..ltc.magnitude import magnitude_alpha, magnitude_fresnel, texel_params

    axes = axes_for({"lobe": "eon", "size": [6, 6]})
    nov, r = texel_params(axes)
    col0 = np.arange(0, 36, 6)
    mag, _ = magnitude_fresnel("eon", nov[col0], magnitude_alpha(axes)[col0], None)
    p = fit.Problem("eon", nov[col0], r[col0], mag)
    texels = np.arange(len(col0))
    m, _ = fit.fit_texels(p, texels, 1, fit.coarse_pass(p, len(col0), 1))
    err = np.max(np.abs(fit.pack_inverse(m) - np.array([1.0, 0.0, 0.0, 1.0])))
    return check_result(
        "ltc_eon_r0_is_identity", err, LTC_IDENTITY_TOL, "max |packed M^-1 - (1, 0, 0, 1)| over 6 views"
    )


LTC_AREA_REL_MEDIAN = 0.05  # GGX shaded fit, area-light benchmark (16 shading points x 8 lights), F = 1: measured 0.036


def ltc_area_benchmark_median() -> CheckResult:
    """The shaded GGX LTC fit (``fit = "shaded"``, lutbake.ltc.shaded) on a small area-light benchmark through the
    shader's bilinear lookup (lutbake.validate.ltc_bench: one shading point per roughness x view band, 8 polygon
    lights each, visible-normal ground truth at 256^2): the median relative error."""
    from . import ltc_bench

    cases = ltc_bench.cases(1, 8)
    truths = [ltc_bench.ground_truth(c, 256) for c in cases]
    t1, t2 = ltc_bench.fitted_texels(ltc_bench.lookup_texels(cases, 64), "shaded")
    med = ltc_bench.stats(ltc_bench.errors(t1, t2, cases, truths))["rel_median"]
    return check_result(
        "ltc_area_benchmark_median", med, LTC_AREA_REL_MEDIAN, "median |LTC - truth| / truth, 128 lights"
    )


# --- the checks, in the order lutbake validate runs them ---------------------------------------------------------


TABLE: tuple[Check, ...] = (
    *(Check(f"ndf_projected_area_is_one[{n}]", functools.partial(ndf_projected_area_is_one, n)) for n in NDFS),
    Check("ndf_projected_area_is_one[ggx_aniso]", ndf_projected_area_is_one_aniso),
    Check("ndf_projected_area_is_one[charlie]", charlie_projected_area_is_one),
    Check("ashikhmin_shirley_density_is_one", ashikhmin_shirley_density_is_one),
    *(Check(f"weak_white_furnace[{n}]", functools.partial(weak_white_furnace, n)) for n in SMITH_NDFS),
    Check("weak_white_furnace[ggx_aniso]", weak_white_furnace_aniso),
    *(
        Check(f"albedo_le_one_and_mirror_limit[{n},{m}]", functools.partial(albedo_le_one_and_mirror_limit, n, m))
        for n in SMITH_NDFS
        for m in ALBEDO_MASKINGS
    ),
    *(Check(f"dfg_mirror_limit[{n},{m}]", functools.partial(dfg_mirror_limit, n, m)) for n, m in DFG_MIRROR_PAIRS),
    *(Check(f"reciprocity[{n},{m}]", functools.partial(reciprocity, n, m)) for n, m in BRDF_PAIRS),
    Check("fresnel_eq2_is_exact_dielectric", fresnel_eq2_is_exact_dielectric),
    Check("schlick_endpoints", schlick_endpoints),
    Check("estimators_agree", estimators_agree),
    Check("kulla_conty_white_furnace", kulla_conty_white_furnace),
    Check("diffuse_sigma0_is_lambert_eq6", diffuse_sigma0_is_lambert_eq6),
    Check("diffuse_reciprocity", diffuse_reciprocity),
    Check("diffuse_albedo_le_one", diffuse_albedo_le_one),
    *dielectric.TABLE,  # the rough dielectric BSDF's checks
    Check("ltc_sphere_table_is_snyder", ltc_sphere_table_is_snyder),
    Check("eon_albedo_is_one", eon_albedo_is_one),
    Check("ltc_eon_r0_is_identity", ltc_eon_r0_is_identity),
    Check("ltc_area_benchmark_median", ltc_area_benchmark_median),
)
CHECK = family("check", "analytic checks and invariants (lutbake validate)")


def _summary(run) -> str:
    """The first line of a check's docstring (of the function a partial binds)."""
    doc = (getattr(run, "func", run).__doc__ or "").strip()
    return doc.splitlines()[0] if doc else ""


for _c in TABLE:
    CHECK.add(Record("check", _c.name, _summary(_c.run) or _c.name, fields={"obj": _c.run}))
CHECKS: dict = {r.name: r.obj for r in CHECK}  # name -> the check's zero-argument callable, in TABLE's order


def run_all(names=None) -> list[CheckResult]:
    """Run the named checks (every record of the ``check`` family by default) in TABLE's order."""
    names = CHECK.names() if names is None else list(names)
    unknown = [n for n in names if n not in CHECK]
    if unknown:
        raise KeyError(f"unknown check(s) {unknown}; valid: {', '.join(CHECK.names())}")
    return [CHECK.lookup(n).obj() for n in names]
