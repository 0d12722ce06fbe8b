"""The seed's analysis figures (Gotanda 2014 course notes, Figures 5-15; slides 004): the curve
configurations, and the fitted model's error against the integrated microfacet model per figure.

Every figure plots L_r = f_r (n.l) (radiance for unit irradiance, rho = 1, f0 = 0.04) against theta_l
(n.e and cos phi fixed) or against theta_e (n.l and cos phi fixed); phi is the azimuth between l and e.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

F0 = 0.04


@dataclass(frozen=True)
class Figure:
    label: str
    vary: str  # "theta_l" or "theta_v": the abscissa
    fixed_cos: float  # n.e when theta_l varies, n.l when theta_v varies
    cos_phi: float
    sigma: float


# Figures 11-15 of the course notes (the fitted-model analysis), with the settings of the slides; Figures 6-10
# use the same nine settings for Oren-Nayar, Oren-Nayar with Fresnel and the integrated model.
FIGURES = [
    Figure("11a", "theta_l", 1.0, 1.0, 0.0),
    Figure("11b", "theta_l", 1.0, 1.0, 0.5),
    Figure("11c", "theta_l", 1.0, 1.0, 1.0),
    Figure("12a", "theta_l", 0.5, 1.0, 0.8),
    Figure("12b", "theta_l", 0.342, 0.5, 0.6),
    Figure("13", "theta_v", 0.866, 1.0, 0.0),
    Figure("14a", "theta_v", 0.866, 1.0, 0.3),
    Figure("14b", "theta_v", 0.866, 1.0, 0.7),
    Figure("15", "theta_v", 0.259, 0.985, 0.8),
]
FIGURE_MODELS = ("oren_nayar", "oren_nayar_fresnel", "microfacet", "fitted")


def directions(fig: Figure, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(l, v) arrays (N, 3) for the figure's abscissa theta (radians), n = +z, v in the xz-plane."""
    c = np.cos(theta)
    s = np.sin(theta)
    cf = fig.fixed_cos
    sf = np.sqrt(max(1.0 - cf * cf, 0.0))
    sp = np.sqrt(max(1.0 - fig.cos_phi**2, 0.0))
    moving = np.stack([s * fig.cos_phi, s * sp, c], -1)
    fixed = np.broadcast_to(np.array([sf, 0.0, cf]), moving.shape)
    return (moving, fixed) if fig.vary == "theta_l" else (fixed, moving)


def curves(
    fig: Figure,
    theta: np.ndarray,
    models=FIGURE_MODELS,
    sigma_to_alpha: str = "sigma",
    facet_fresnel: str = "eq6",
    order: int = 12,
) -> dict[str, np.ndarray]:
    """L_r = f_r (n.l) per model along the figure's abscissa."""
    from ..integrands.diffuse import eval_brdf

    l, v = directions(fig, theta)
    out = {}
    for m in models:
        f = eval_brdf(m, l, v, fig.sigma, F0, facet_fresnel, sigma_to_alpha, order)
        out[m] = f * l[:, 2]
    return out


def error_table(theta=None, sigma_to_alpha: str = "sigma", fitted: str = "fitted", order: int = 12) -> list[dict]:
    """Per figure: max |fitted - integrated| and its RMS, in units of the integrated curve's maximum."""
    theta = np.linspace(0.0, np.pi / 2, 91)[:-1] if theta is None else theta
    rows = []
    for fig in FIGURES:
        c = curves(fig, theta, ("microfacet", fitted), sigma_to_alpha, order=order)
        ref, fit = c["microfacet"], c[fitted]
        scale = np.max(np.abs(ref))
        d = fit - ref
        rows.append(
            {
                "figure": fig.label,
                "vary": fig.vary,
                "fixed_cos": fig.fixed_cos,
                "cos_phi": fig.cos_phi,
                "sigma": fig.sigma,
                "max_err": float(np.max(np.abs(d)) / scale),
                "rms_err": float(np.sqrt(np.mean(d * d)) / scale),
                "argmax_deg": float(np.degrees(theta[np.argmax(np.abs(d))])),
            }
        )
    return rows


COLOURS = {
    "oren_nayar": "tab:blue",
    "oren_nayar_fresnel": "tab:purple",
    "microfacet": "tab:green",
    "fitted": "tab:orange",
}
LABELS = {
    "oren_nayar": "Oren-Nayar (Eq. 5)",
    "oren_nayar_fresnel": "Oren-Nayar with Fresnel (Eq. 7)",
    "microfacet": "microfacet, integrated (Eq. 4)",
    "fitted": "fitted (Eq. 8)",
}


def plot_all(out_dir, sigma_to_alpha: str = "sigma", order: int = 12) -> list:
    """One PNG per figure (out_dir/figure_<label>.png): the four models' L_r along the figure's abscissa."""
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    theta = np.linspace(0.0, np.pi / 2, 91)[:-1]
    models = ("oren_nayar_improved", "oren_nayar_fresnel", "microfacet", "fitted")
    paths = []
    for fig in FIGURES:
        c = curves(fig, theta, models, sigma_to_alpha, order=order)
        f, ax = plt.subplots(figsize=(5, 3.5))
        for m in models:
            key = "oren_nayar" if m == "oren_nayar_improved" else m
            ax.plot(np.degrees(theta), c[m], color=COLOURS[key], label=LABELS[key], ls="--" if m == "fitted" else "-")
        fixed = "n·e" if fig.vary == "theta_l" else "n·l"
        ax.set_title(
            f"Fig. {fig.label}: {fixed} = {fig.fixed_cos}, cos φ = {fig.cos_phi}, σ = {fig.sigma}, f0 = {F0}",
            fontsize=8,
        )
        ax.set_xlabel("θ_l (deg)" if fig.vary == "theta_l" else "θ_e (deg)")
        ax.set_ylabel("L_r (unit irradiance, ρ = 1)")
        ax.legend(fontsize=6)
        f.tight_layout()
        p = out_dir / f"figure_{fig.label}.png"
        f.savefig(p, dpi=120)
        plt.close(f)
        paths.append(p)
    return paths
