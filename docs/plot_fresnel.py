"""Reproduce the seed's Fresnel figures (Gotanda 2014 course notes, Figs. 1-3) from lutbake's @wp.func terms.

    make figures                                  (writes outputs/figures/fig*.png with the venv's Python)
    .venv/bin/python docs/plot_fresnel.py [out_dir]   (default outputs/figures; the PNGs in docs/figures, which
                                                       the docs show, are never rewritten by default)
Fig. 1: Schlick vs exact Fresnel for aluminium at 610 nm (1.3 + 7.48i) and for eta = 1.5.
Fig. 2: Eq. 2 with the real f0 of 1.3 + 7.48i vs the complex-index Fresnel (plus Lazanyi-Schlick).
Fig. 3: improved spherical Gaussian (Eq. 3) vs Schlick vs exact Fresnel at eta = 1.5.
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from lutbake.integrands.fresnel import evaluate  # noqa: E402
from lutbake.metals import fit_lazanyi_a  # noqa: E402

DEFAULT_OUT = Path(__file__).resolve().parents[1] / "outputs" / "figures"  # never docs/figures (tracked)
AL = (1.3, 7.48)
ETA = 1.5


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    theta = np.linspace(0.0, 90.0, 721)
    c = np.cos(np.radians(theta))
    f0_al = ((AL[0] - 1) ** 2 + AL[1] ** 2) / ((AL[0] + 1) ** 2 + AL[1] ** 2)
    f0_15 = ((ETA - 1) / (ETA + 1)) ** 2
    al = evaluate(c, f0=f0_al, n=AL[0], k=AL[1], a=fit_lazanyi_a(*AL))
    g15 = evaluate(c, f0=f0_15, n=ETA, k=0.0)
    figs = {
        "fig1_schlick_vs_fresnel.png": ("Fig. 1: Schlick vs Fresnel", [
            (al["conductor"], "Fresnel, aluminium 610 nm (1.3+7.48i)"), (al["schlick"], "Schlick, aluminium 610 nm"),
            (g15["conductor"], "Fresnel, eta = 1.5"), (g15["schlick"], "Schlick, eta = 1.5")]),
        "fig2_eq2_vs_complex.png": ("Fig. 2: Eq. 2 with a real f0 vs complex index 1.3+7.48i", [
            (al["conductor"], "Fresnel, 1.3+7.48i"), (al["dielectric_f0"], f"Eq. 2, f0 = {f0_al:.3f}"),
            (al["lazanyi"], "Lazanyi-Schlick (fitted a)")]),
        "fig3_improved_sg.png": ("Fig. 3: eta = 1.5", [
            (g15["schlick"], "Schlick"), (g15["conductor"], "Fresnel"), (g15["improved_sg"], "improved SG (Eq. 3)")]),
    }
    for fname, (title, curves) in figs.items():
        fig, ax = plt.subplots(figsize=(6, 4), dpi=110)
        for y, label in curves:
            ax.plot(theta, y, label=label)
        ax.set(xlabel="theta (degrees)", ylabel="F(theta)", title=title, xlim=(0, 90), ylim=(0, 1.02))
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(out / fname)
        plt.close(fig)
        print(out / fname)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_OUT)
