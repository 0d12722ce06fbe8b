"""Check a candidate ladder for the glass tables on every texel, where benchmarks/replay_ladder.py samples a few
thousand: each glass preset's whole grid is integrated by the candidate (lutbake.sampling.dielectric.DielectricAdaptive
with its orders, and ``kronrod`` for a ladder from a Gauss-Kronrod pair) and by the default ladder at a hundredth of
the table's tolerance (``refined()``), both with their per-texel estimates. Where both estimates are honest,
|v - v_ref| <= e + e_ref; a texel with |v - v_ref| - e_ref > e is past the candidate's estimate (or the reference's).
Also the kernel time of the candidate and of the default (one thread, same run).

2026-12-03: the pair (5, 11) -- replayed honest on 6000 random texels a preset -- has 12 texels of EEVEE's bsdf and 1
of OpenPBR's past their estimates, (n.v, alpha, eta) = (0.5599, 0.2844, 0.4714) of EEVEE's bsdf 1.35e-6 off under an
estimate of 8.0e-7; the default none.
Run: PYTHONPATH=. python benchmarks/check_glass_ladder.py [5,K11,16,20,24,32,48,64]  (~6 min on 2 cores)
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from replay_ladder import captured_inputs  # noqa: E402

from lutbake.config import load_config, preset_path  # noqa: E402
from lutbake.sampling import dielectric as DL  # noqa: E402

PRESETS = ("blender-eevee-bsdf", "blender-eevee-btdf", "turquin", "openpbr")
SHOWN = 20  # failing texels printed per preset


def candidate(ladder: str, est):
    """The estimator of a ladder named as benchmarks/replay_ladder.py's ("5,K11,16,..." from the pair (G5, K11))."""
    names = ladder.split(",")
    return replace(est, orders=tuple(int(n.lstrip("K")) for n in names), kronrod=names[1].startswith("K"))


def timed(est, integrand, inputs):
    t0 = time.perf_counter()
    v, e = est.evaluate_with_error(integrand, inputs, "cpu")
    return v, e, time.perf_counter() - t0


def main() -> None:
    ladder = sys.argv[1] if len(sys.argv) > 1 else "5,K11,16,20,24,32,48,64"
    for preset in PRESETS:
        (spec, *_) = load_config(preset_path(preset), [])
        integrand, inputs, est = captured_inputs(spec, DL.DielectricAdaptive)
        v, e, t_cand = timed(candidate(ladder, est), integrand, inputs)
        _, _, t_default = timed(est, integrand, inputs)
        v_ref, e_ref, _ = timed(est.refined()[0], integrand, inputs)
        live = np.array(est.absolute) < 1e200  # the channels with a target (EEVEE's btdf refines one)
        slack = np.abs(v - v_ref) - e_ref
        past = np.flatnonzero(((slack > e) & live).any(axis=1))
        print(
            f"{preset}: {len(v)} texels, {len(past)} past the estimate of {ladder}; kernel {t_cand:.1f} s against "
            f"{t_default:.1f} s for the default ({t_cand / t_default:.2f}x); reference estimates "
            f"<= {e_ref[:, live].max():.1e}"
        )
        for i in past[:SHOWN]:
            c = int(np.argmax(np.where(live & (slack[i] > e[i]), slack[i], -np.inf)))
            print(
                f"  (n.v, alpha, eta) = ({inputs['nov'][i]:.4g}, {inputs['alpha'][i]:.4g}, {inputs['param'][i]:.4g}) "
                f"channel {c}: error {abs(v[i, c] - v_ref[i, c]):.2e}, estimate {e[i, c]:.2e}"
            )


if __name__ == "__main__":
    main()
