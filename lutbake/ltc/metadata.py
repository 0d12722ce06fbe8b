"""The ltc kind's metadata records (lutbake.kinds.ltc): how the matrices were fitted and the magnitude integrated
(lutbake:ltc_fit), and the fit error's statistics written after the bake (lutbake:fit_error_*)."""

from __future__ import annotations

import json

import numpy as np

from ..edge import ALPHA_MIN
from .table import uses_shaded_fit

NORMAL_FRAME = (
    "M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]] in the normal's frame (Zeltner, Burley & Chiang 2022; tizian/ltc-sheen), "
    "2 parameters (log(1 / a), b)"
)
FREE_FRAME = " turned about y by a fitted angle d (4 parameters: every LTC of a lobe symmetric about the xz-plane)"
ROUGHNESS_AXES = {
    "perceptual": "x = perceptual roughness r, NDF alpha = r^2 (ltc_code)",
    "alpha": "x = alpha (the lobe's own parameter: charlie's sheenRoughness)",
    "sigma": "x = Gotanda's sigma, GGX alpha = sigma (the diffuse kind's default sigma_to_alpha, docs/diffuse.md)",
    "diffuse_roughness": "x = EON's roughness r (OpenPBR base_diffuse_roughness), linear in [0, 1]",
    "none": "x unused (lambert)",
}


def magnitude_record(lb, estimator: str, samples) -> str:
    if lb.magnitude == "lobe_adaptive":
        from .magnitude import LOBE_ORDERS

        return (
            f"lutbake.ltc.magnitude.lobe_magnitude: the diffuse kind's Gauss-Legendre rule over l (2 x 2 panels), "
            f"orders {LOBE_ORDERS} raised until two agree within the table's tolerance at every texel (estimate: "
            "lutbake:ltc_magnitude_error_estimate); fresnel = magnitude"
        )
    if lb.magnitude == "lobe":
        from . import fit

        return (
            f"lutbake.ltc.fit.lobe_albedo: Gauss-Legendre {fit.ALBEDO_ORDER} x {fit.ALBEDO_ORDER // 2} (theta graded "
            "to the horizon, phi)"
        )
    if lb.magnitude.startswith("diffuse:"):
        model = lb.magnitude.split(":")[1]
        return (
            f"the diffuse kind's gauss_legendre estimator, model {model!r}, order {samples or 'default'} (rho = 1, "
            "f0 = 0): equal to that table at the same texels; fresnel channel = magnitude"
        )
    return f"{estimator}, {samples or 'default'} samples (lutbake albedo / dfg integrands)"


def shaded_record(o: dict) -> dict:
    if not uses_shaded_fit(o):
        return {"fit": "l3: the matrices minimise the L3 distance; magnitude and fresnel are the exact integrals"}
    from . import shaded

    mag = (
        "magnitude fitted with the matrix, fresnel the least-squares Schlick scale"
        if o["magnitude"] == "fitted"
        else "magnitude = the exact albedo (fixed), fresnel the least-squares Schlick scale"
    )
    return {
        "fit": f"shaded: the l3 fit refined by Levenberg-Marquardt ({shaded.ITERATIONS} steps) to minimise the soft-L1 "
        f"(scale {shaded.ROBUST_SCALE:g}) of (value_j - G_j) / (G_j + {shaded.ABS_WEIGHT:g} albedo) over "
        f"{shaded.LIGHTS} training lights per texel (lutbake.ltc.lights, seed {shaded.SEED}), G_j from the lobe's "
        f"{shaded.SAMPLES}^2 importance samples, for F = 1 and (weight {o['fit_f0_weight']:g}) f0 = "
        f"{shaded.F0_TRAIN:g}; " + mag
    }


def tabulation_record(lb) -> dict:
    if lb.tabulate is None:
        return {}
    from . import tabulated

    return {
        "tabulated_lobe": f"f (n.l) = G2 J, J tabulated per texel on {tabulated.TAB_THETA} theta_l (cell centres) x "
        f"{tabulated.TAB_PHI} phi_l (endpoints, [0, pi]) by Eq. 4's GL quadrature at order {tabulated.TAB_ORDER}, "
        "Catmull-Rom interpolated (lutbake.ltc.tabulated)"
    }


L3_METRIC = (
    "(E / ∫ f^3 dω)^(1/3), E = ∫ |f (n.l) - magnitude D_ltc|^3 dω by MIS over the lobe's and the LTC's N x N "
    "stratified samples (Heitz et al. 2016, ltc_code computeError)"
)


def fit_error_stats(data: np.ndarray, where: tuple[int, int] = (1, 2), metric: str = L3_METRIC) -> dict[str, str]:
    """The lutbake:fit_error_* attributes: statistics of the error per texel (``metric``: the relative L3 error),
    channel ``where[1]`` of slice ``where[0]`` (the ltc kind: slice 1's z; ltc_aniso: slice 2's w)."""
    e = np.asarray(data)[where[0], ..., where[1]].ravel()
    return {
        "fit_error_max": f"{e.max():.4g}",
        "fit_error_median": f"{np.median(e):.4g}",
        "fit_error_p95": f"{np.quantile(e, 0.95):.4g}",
        "fit_error": json.dumps(
            {
                "metric": metric,
                "max": float(e.max()),
                "median": float(np.median(e)),
                "p95": float(np.quantile(e, 0.95)),
                "mean": float(e.mean()),
            }
        ),
    }


def fit_record(o: dict, lb, m_samples, theta_max: float) -> str:
    """The lutbake:ltc_fit attribute: the fit's parametrisation, metric, optimiser and seeding, the magnitude's
    integrator and the roughness axis of lobe ``lb`` under a spec's options ``o``."""
    from . import fit

    q_text = "log(1 / a), b" if lb.normal_frame else "log m11, log m22, m13/m11" + (", d" if lb.free_frame else "")
    return json.dumps(
        {
            "parametrisation": NORMAL_FRAME
            if lb.normal_frame
            else "M = [X Y Z] [[m11, 0, m13], [0, m22, 0], [0, 0, 1]], Z = lobe's average direction"
            + (FREE_FRAME if lb.free_frame else " (ltc_code's 3 parameters)"),
            "metric": "Heitz et al. 2016 L3 distance, MIS over lobe and LTC samples (ltc_code computeError)",
            "fit_samples": f"{o['fit_samples']} x {o['fit_samples']} per technique",
            "optimiser": f"Nelder-Mead (ltc_code nelder_mead.h), tol {fit.NELDER_MEAD_TOL}, "
            f"<= {fit.NELDER_MEAD_ITERS} iterations per restart, simplex sizes {list(fit.COARSE_STEPS)} "
            f"(coarse pass), {list(fit.FINE_STEPS)} (texels) in ({q_text})",
            "seeding": f"coarse pass on {fit.COARSE_NODES}^2 texels from analytic guesses, at the lobe's alpha "
            f"(>= {ALPHA_MIN:g}, unclamped by alpha_min); each texel starts "
            "from the best of the analytic guesses and the surrounding coarse fits (no chaining)",
            "alpha_min": o["alpha_min"],
            "theta_max": theta_max,
            "magnitude": magnitude_record(lb, o["estimator"], m_samples),
            **shaded_record(o),
            "roughness_axis": ROUGHNESS_AXES[lb.roughness],
            **tabulation_record(lb),
        }
    )
