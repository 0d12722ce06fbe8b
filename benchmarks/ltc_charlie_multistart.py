"""Charlie LTC investigation (docs/ltc.md, "Charlie: why the 3-parameter fit was poor"): is the fit stuck in local
minima, or is the parametrisation the limit? At the 25 area-light texels of 64^2, the seeded fit (lutbake.ltc.fit)
against the best of ``--starts`` random starts, for ltc_code's 3 parameters and for the free frame (4). Prints the
relative L3 errors; not part of ``make bench`` (minutes). Run: .venv/bin/python benchmarks/ltc_charlie_multistart.py
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bench_ltc import AREA_TEXELS, N  # noqa: E402

from lutbake.kinds.ltc import axes_for  # noqa: E402
from lutbake.ltc import fit  # noqa: E402
from lutbake.ltc.magnitude import magnitude_alpha, magnitude_fresnel, texel_params  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--starts", type=int, default=40)
    args = ap.parse_args(argv)
    axes = axes_for({"lobe": "charlie", "size": [N, N]})
    nov, alpha = texel_params(axes)
    mag, _ = magnitude_fresnel("charlie", nov, magnitude_alpha(axes), None)
    tex = np.array([t * N + a for t, a in AREA_TEXELS])
    rng = np.random.default_rng(0)
    np.set_printoptions(precision=3, linewidth=160, suppress=True)
    for dof in (3, 4):
        p = fit.Problem("charlie", nov, alpha, mag)
        p.dof = dof
        _, err = fit.fit_texels(p, tex, N, fit.coarse_pass(p, N, N))
        k, s = len(tex), args.starts
        starts = [rng.uniform(-4, 1.5, (k, s)), rng.uniform(-4, 1.5, (k, s)), rng.uniform(-3, 3, (k, s))]
        starts += [rng.uniform(-1.5, 1.5, (k, s))] * (dof - 3)
        _, f = fit.refine(p, np.repeat(tex, s), np.stack(starts, -1).reshape(-1, dof), fit.COARSE_STEPS)
        best = f.reshape(k, s).min(axis=1)
        print(f"{dof} parameters, seeded fit, relative L3 (rows t = 0, 16, 32, 48, 60; columns a = 6 .. 63):")
        print(p.relative(tex, err).reshape(5, 5))
        print(f"{dof} parameters, best of {s} random starts:")
        print(p.relative(tex, np.minimum(best, err)).reshape(5, 5))
        print("texels where a random start beats the seeded fit by > 1e-3 relative:", int(np.sum(best < err * 0.997)))


if __name__ == "__main__":
    main()
