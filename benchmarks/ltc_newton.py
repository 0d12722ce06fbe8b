"""LTC search investigation (docs/decisions.md, "LTC fit"): would a damped Newton method
fit the texels with fewer objective evaluations than ltc_code's Nelder-Mead (lutbake.ltc.fit.refine), and as well?
On ``--texels`` random texels of the 64^2 GGX fit, from the same starts (the best seed candidate of each texel, as
lutbake.ltc.fit.fit_from), it runs Nelder-Mead as the table does, the Newton method alone, and Nelder-Mead to a looser
tolerance finished by Newton; it prints the evaluations per texel and how many texels each leaves worse than
Nelder-Mead. Not part of ``make bench`` (about a minute). Run: .venv/bin/python benchmarks/ltc_newton.py

The Newton step: a quadratic model from 2 d + d (d - 1) / 2 + 1 values (f at q, q +- h e_i, q + h (e_i + e_j); 10 for
d = 3), central differences with h following the last step (clamped to [1e-6, 1e-3]: the sharp lobes at low roughness
move by 1e-4 in log m), Levenberg damping (H + lambda diag |H|), a step taken only where it lowers the metric (up to 4
tries, lambda x 10 after each miss, x 0.3 after a hit), the best model point taken if lower; a texel stops on
Nelder-Mead's own test 2 |f_old - f_new| <= tol (|f_old| + |f_new|).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lutbake.kinds.ltc import axes_for  # noqa: E402
from lutbake.ltc import fit  # noqa: E402
from lutbake.ltc.magnitude import magnitude_alpha, magnitude_fresnel, texel_params  # noqa: E402

N = 64


def newton(fun, texel, q, f, tol=fit.NELDER_MEAD_TOL, iters=20, h0=1.0e-3):
    """The damped Newton search of the module docstring from (q, f) per texel; returns (q, f, evaluations)."""
    q, f = q.copy(), f.copy()
    n, d = q.shape
    eye = np.eye(d)
    pairs = [(i, j) for i in range(d) for j in range(i + 1, d)]
    active = np.ones(n, bool)
    lam = np.full(n, 1.0e-3)
    h = np.full(n, h0)
    evals = 0
    for _ in range(iters):
        idx = np.flatnonzero(active)
        if len(idx) == 0:
            break
        qi, fi, hh = q[idx], f[idx], h[idx][:, None]
        pts = [qi + hh * eye[i] for i in range(d)] + [qi - hh * eye[i] for i in range(d)]
        pts += [qi + hh * (eye[i] + eye[j]) for i, j in pairs]
        P = np.stack(pts, 1)
        k, m, _ = P.shape
        fv = fun(np.repeat(texel[idx], m), P.reshape(-1, d)).reshape(k, m)
        evals += k * m
        fp, fm = fv[:, :d], fv[:, d : 2 * d]
        g = (fp - fm) / (2.0 * hh)
        H = np.zeros((k, d, d))
        for i in range(d):
            H[:, i, i] = (fp[:, i] - 2.0 * fi + fm[:, i]) / hh[:, 0] ** 2
        for c, (i, j) in enumerate(pairs):
            H[:, i, j] = H[:, j, i] = (fv[:, 2 * d + c] - fp[:, i] - fp[:, j] + fi) / hh[:, 0] ** 2
        qn, fn = qi.copy(), fi.copy()
        todo = np.arange(k)
        lk = lam[idx]
        for _try in range(4):
            if len(todo) == 0:
                break
            damp = lk[todo][:, None] * np.abs(np.einsum("kii->ki", H[todo])) + 1.0e-300
            s = -np.linalg.solve(H[todo] + damp[:, :, None] * eye, g[todo][:, :, None])[:, :, 0]
            s[~np.isfinite(s).all(1)] = 0.0
            norm = np.linalg.norm(s, axis=1)
            s[norm > 0.5] *= (0.5 / norm[norm > 0.5])[:, None]
            ft = fun(texel[idx[todo]], qi[todo] + s)
            evals += len(todo)
            ok = ft < fi[todo]
            qn[todo[ok]], fn[todo[ok]] = qi[todo[ok]] + s[ok], ft[ok]
            lk[todo[ok]] *= 0.3
            lk[todo[~ok]] *= 10.0
            todo = todo[~ok]
        lam[idx] = lk
        best = np.argmin(fv, 1)
        fb = fv[np.arange(k), best]
        lower = fb < fn
        qn[lower], fn[lower] = P[np.arange(k), best][lower], fb[lower]
        h[idx] = np.clip(0.5 * np.linalg.norm(qn - qi, axis=1), 1.0e-6, h0)
        done = 2.0 * np.abs(fi - fn) <= tol * (np.abs(fi) + np.abs(fn))
        q[idx], f[idx] = qn, fn
        active[idx[done]] = False
    return q, f, evals


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--texels", type=int, default=600)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    axes = axes_for({"lobe": "ggx", "size": [N, N]})
    nov, alpha = texel_params(axes)
    mag, _ = magnitude_fresnel("ggx", nov, magnitude_alpha(axes), None)
    p = fit.Problem("ggx", nov, alpha, mag)
    coarse = fit.coarse_pass(p, N, N)
    tex = np.sort(np.random.default_rng(args.seed).choice(N * N, args.texels, replace=False))
    start, f0 = fit.best_of(p, tex, fit.seed_candidates(p, tex, N, coarse))
    atol = fit.ATOL_RELATIVE**3 * p.f3[tex]

    e0 = p.evaluations
    _, f_nm = fit.refine(p, tex, start, fit.FINE_STEPS, f0)
    n_nm = (p.evaluations - e0) / len(tex)
    r_nm = p.relative(tex, f_nm)
    print(f"Nelder-Mead (the table's): {n_nm:.1f} evaluations a texel, median relative error {np.median(r_nm):.6g}")

    def report(name, f, evals):
        ratio = p.relative(tex, f) / np.maximum(r_nm, 1e-300)
        print(
            f"{name}: {evals / len(tex):.1f} evaluations a texel ({evals / len(tex) / n_nm:.2f}x), median "
            f"{np.median(p.relative(tex, f)):.6g}; texels worse by > 0.1 %: {np.sum(ratio > 1.001)}, > 1 %: "
            f"{np.sum(ratio > 1.01)}, worst {ratio.max():.4g}x; better by > 0.1 %: {np.sum(ratio < 0.999)}"
        )

    _, f_n, ev = newton(p.objective, tex, start, f0)
    report("Newton", f_n, ev)
    for tol in (1.0e-3, 1.0e-4):
        e0 = p.evaluations
        q_h, f_h = fit.nelder_mead(p.objective, tex, start, fit.FINE_STEPS[0], tol=tol, atol=atol, f_start=f0)
        ev_nm = p.evaluations - e0
        _, f_h, ev = newton(p.objective, tex, q_h, f_h)
        report(f"Nelder-Mead to {tol:g}, then Newton", f_h, ev_nm + ev)


if __name__ == "__main__":
    main()
