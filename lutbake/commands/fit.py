"""``lutbake fit``: refit a published closed-form family to lutbake's integrals, emit it as GLSL / HLSL with
its measured error, and report the published constants' error beside it.

Families:
- ``karis-mobile``: Karis' mobile split-sum approximation (Karis 2014, "Physically Based Shading on Mobile",
  EnvBRDFApprox; its constants were fitted to the Call of Duty: Black Ops 2 table of Lazarov 2013):
      r = R c0 + c1;  a004 = min(r.x^2, 2^(k NoV)) r.x + r.y;  (A, B) = (-s, s) a004 + (r.z, r.w)
  R = perceptual roughness, E = f0 A + B. Refit (10 constants) to lutbake's exact GGX + height-correlated
  Smith scale/bias table (texel centres, n x n), minimising the error of E at f0 = 0.04 and f0 = 1 (KARIS_F0).
- ``gotanda-eq8``: Gotanda's fitted microfacet diffuse (Gotanda 2014 course notes, Eq. 8; EQUATIONS.md), whose
  17 constants were fitted to his Eq. 4; refit to lutbake's Gauss-Legendre integral of Eq. 4 (GGX, height-
  correlated Smith, Eq. 6 facets, alpha = sigma) on a grid of (n.l, n.v, cos phi, sigma), minimising the
  relative error (floored at REL_FLOOR x the Lambert value so the vanishing both-grazing back-scatter does not
  dominate). The structure of Eq. 8 is kept; only its constants change.
Both fits are least squares (scipy.optimize.least_squares, trust-region reflective; gotanda-eq8 with a soft-L1
loss) from the published constants; errors are measured on the fitting grid and on a second, offset grid (held out).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FAMILIES = {
    "karis-mobile": "Karis 2014 EnvBRDFApprox (mobile split-sum) refit to the exact height-correlated GGX table",
    "gotanda-eq8": "Gotanda 2014 Eq. 8 fitted diffuse refit to the integrated Eq. 4 (microfacet diffuse)",
}
KARIS_PUBLISHED = np.array([-1.0, -0.0275, -0.572, 0.022, 1.0, 0.0425, 1.04, -0.04, -9.28, 1.04])
GOTANDA_PUBLISHED = np.array(
    [
        0.542026,
        0.303573,
        1.36053,
        5.0,
        4.0,
        -0.733996,
        1.50912,
        -1.16402,
        39.0,
        0.09,
        1.31072,
        0.995584,
        0.3726732,
        0.188566,
        0.388410,
        1.4,
        0.5,
    ]
)
# every denominator and exponent of Eq. 8 stays positive inside these bounds (k, e0 - e1, q, v0, v1, v2, v4, v5)
GOTANDA_BOUNDS = (
    np.array(
        [
            -np.inf,
            -np.inf,
            0.05,
            4.5,
            0.0,
            -np.inf,
            -np.inf,
            -np.inf,
            0.0,
            1e-3,
            0.05,
            0.0,
            -np.inf,
            0.01,
            0.0,
            -np.inf,
            -np.inf,
        ]
    ),
    np.array(
        [
            np.inf,
            np.inf,
            np.inf,
            8.0,
            4.4,
            np.inf,
            np.inf,
            np.inf,
            np.inf,
            np.inf,
            np.inf,
            np.inf,
            0.99,
            np.inf,
            np.inf,
            np.inf,
            np.inf,
        ]
    ),
)
GOTANDA_NFEV = 300  # least-squares evaluations (each with a finite-difference Jacobian): ~1 min here
GOTANDA_F_SCALE = 0.03  # soft_l1: relative errors beyond ~3 % count linearly (the tail does not rule the body)
KARIS_F0 = (0.04, 1.0)  # karis-mobile fits E = f0 A + B at these f0 (dielectric, white metal)
REL_FLOOR = 0.02  # gotanda-eq8: relative error = |fit - integral| / max(integral, REL_FLOOR / pi)
GRAZING = 0.15  # both n.l and n.v below this: Eq. 8's stated limit (reported separately)


def karis_mobile(p: np.ndarray, nov: np.ndarray, r: np.ndarray) -> np.ndarray:
    """(A, B) of EnvBRDFApprox with constants p = (c0[4], c1[4], k, s) (published: KARIS_PUBLISHED)."""
    c0, c1, k, s = p[0:4], p[4:8], p[8], p[9]
    rr = r[..., None] * c0 + c1
    a004 = np.minimum(rr[..., 0] ** 2, np.exp2(k * nov)) * rr[..., 0] + rr[..., 1]
    return np.stack([-s * a004 + rr[..., 2], s * a004 + rr[..., 3]], -1)


def gotanda_eq8(p: np.ndarray, nol, nov, lov, sigma) -> np.ndarray:
    """Eq. 8 as a BRDF (L_r / (n.l), rho = 1, f0 = 0) with its constants p (published: GOTANDA_PUBLISHED):
    p = (a1, a2, k, e0, e1, c3, c2, c1, q, v0, v1, v2, v3, v4, v5, bp, lm)."""
    a1, a2, k, e0, e1, c3, c2, c1, q, v0, v1, v2, v3, v4, v5, bp, lm = p
    s, s2 = sigma, sigma * sigma
    omv, oml = np.clip(1 - nov, 0, 1), np.clip(1 - nol, 0, 1)
    kk = s2 + k
    fr = (
        (1 - (a1 * s2 + a2 * s) / kk)
        * (1 - omv ** (e0 - e1 * s2) / kk)
        * ((c3 * s2 * s + c2 * s2 + c1 * s) * omv ** (1 + 1 / (q * s2 * s2 + 1)) + 1)
    )
    lmv = (np.maximum(1 - 2 * s, 0) * (1 - oml**5) + np.minimum(2 * s, 1)) * ((1 - lm * s) * nol + lm * s * nol**2)
    vd = s2 / ((s2 + v0) * (v1 + v2 * nov)) * (1 - oml ** ((1 - v3 * nov**2) / (v4 + v5 * nov)))
    d = lov - nol * nov
    bpv = np.where(d < 0, bp * nov * nol * d, d)
    return 1.05 / np.pi * (fr * lmv + vd * bpv) / nol


@dataclass
class FitResult:
    family: str
    published: np.ndarray
    refit: np.ndarray
    errors: dict  # "published" / "refit" -> {metric: value}
    code: dict  # "glsl" / "hlsl" -> source

    def text(self) -> str:
        keys = list(self.errors["published"])
        lines = [f"{self.family}: {FAMILIES[self.family]}", f"{'':28}{'published':>12}{'refit':>12}"]
        lines += [f"  {k:26}{self.errors['published'][k]:>12.4g}{self.errors['refit'][k]:>12.4g}" for k in keys]
        lines.append("constants: " + ", ".join(f"{x:.6g}" for x in self.refit))
        return "\n".join(lines)


def _karis_target(n: int, offset: float = 0.5):
    from ..axes import Axis
    from .audit import Conventions, Integrator

    t = (np.arange(n) + offset) / n
    nov, r = np.meshgrid(t, t)
    axes = [Axis("perceptual_roughness", "y", n), Axis("NoV", "x", n)]
    conv = Conventions({"layout": "scale_bias", "ndf": "ggx", "masking": "smith_height_correlated"}, axes, "fit")
    ref = Integrator(conv).converged(nov.ravel(), r.ravel() ** 2).reshape(n, n, 2)
    return nov, r, ref


def _karis_errors(p, nov, r, ref) -> dict:
    err = np.abs(karis_mobile(p, nov, r) - ref)
    d = karis_mobile(p, nov, r) - ref
    return {
        "max |A - scale|": float(err[..., 0].max()),
        "mean |A - scale|": float(err[..., 0].mean()),
        "max |B - bias|": float(err[..., 1].max()),
        "mean |B - bias|": float(err[..., 1].mean()),
        "rms over A, B": float(np.sqrt(np.mean(err**2))),
        "max |E - E_exact| (f0 = 0.04)": float(np.abs(0.04 * d[..., 0] + d[..., 1]).max()),
        "max |E - E_exact| (f0 = 1)": float(np.abs(d[..., 0] + d[..., 1]).max()),
    }


def _karis_residual(p, nov, r, ref) -> np.ndarray:
    """What a shader computes: E = f0 A + B at KARIS_F0 (a dielectric and a white metal), minus the exact E."""
    d = karis_mobile(p, nov, r) - ref
    return np.concatenate([(f0 * d[..., 0] + d[..., 1]).ravel() for f0 in KARIS_F0])


def fit_karis(n: int = 64) -> FitResult:
    from scipy.optimize import least_squares

    nov, r, ref = _karis_target(n)
    res = least_squares(
        lambda p: _karis_residual(p, nov, r, ref), KARIS_PUBLISHED, method="trf", x_scale="jac", max_nfev=4000
    )
    hn, hr, href = _karis_target(n, 0.0 + 0.25)  # held out: a quarter-texel offset grid
    errors = {}
    for name, p in (("published", KARIS_PUBLISHED), ("refit", res.x)):
        e = _karis_errors(p, nov, r, ref)
        e["held-out max |A - scale|"] = float(np.abs(karis_mobile(p, hn, hr) - href)[..., 0].max())
        e["held-out max |B - bias|"] = float(np.abs(karis_mobile(p, hn, hr) - href)[..., 1].max())
        errors[name] = e
    return FitResult("karis-mobile", KARIS_PUBLISHED, res.x, errors, karis_code(res.x, errors))


def _gotanda_grid(n_cos: int = 12, n_phi: int = 7, n_sigma: int = 9, offset: float = 0.5):
    c = (np.arange(n_cos) + offset) / n_cos
    cp = np.cos(np.pi * (np.arange(n_phi) + offset) / n_phi)
    s = (np.arange(n_sigma) + offset) / n_sigma
    L, V, P, S = (a.ravel() for a in np.meshgrid(c, c, cp, s, indexing="ij"))
    sl, sv = np.sqrt(1 - L * L), np.sqrt(1 - V * V)
    lov = sl * sv * P + L * V
    return L, V, lov, S, sl, sv, P


def _gotanda_target(grid, order: int = 16):
    from ..integrands import diffuse

    L, V, lov, S, sl, sv, P = grid
    sp = np.sqrt(np.maximum(1 - P * P, 0))
    l = np.stack([sl * P, sl * sp, L], -1)
    v = np.stack([sv, np.zeros_like(sv), V], -1)
    return diffuse.eval_brdf("microfacet", l, v, S, order=order)


def _gotanda_errors(p, grid, ref) -> dict:
    L, V, lov, S = grid[:4]
    fit = gotanda_eq8(p, L, V, lov, S)
    rel = np.abs(fit - ref) / np.maximum(ref, REL_FLOOR / np.pi)
    raw = np.abs(fit - ref) / np.maximum(ref, 1e-12)
    ok = ~((L < GRAZING) & (V < GRAZING))
    return {
        "median relative": float(np.median(raw)),
        "p95 relative": float(np.percentile(raw, 95)),
        "max relative (not both grazing)": float(raw[ok].max()),
        f"max relative, floored at {REL_FLOOR}/pi": float(rel.max()),
        "max relative (all)": float(raw.max()),
        "max abs (1/sr)": float(np.abs(fit - ref).max()),
    }


def fit_gotanda(n_cos: int = 10, n_phi: int = 6, n_sigma: int = 8, max_nfev: int = GOTANDA_NFEV) -> FitResult:
    from scipy.optimize import least_squares

    grid = _gotanda_grid(n_cos, n_phi, n_sigma)
    ref = _gotanda_target(grid)
    L, V, lov, S = grid[:4]
    w = 1 / np.maximum(ref, REL_FLOOR / np.pi)
    res = least_squares(
        lambda p: (gotanda_eq8(p, L, V, lov, S) - ref) * w,
        GOTANDA_PUBLISHED,
        method="trf",
        bounds=GOTANDA_BOUNDS,
        x_scale="jac",
        loss="soft_l1",
        f_scale=GOTANDA_F_SCALE,
        max_nfev=max_nfev,
    )
    held = _gotanda_grid(n_cos + 1, n_phi + 1, n_sigma + 1, offset=0.37)
    href = _gotanda_target(held)
    errors = {}
    for name, p in (("published", GOTANDA_PUBLISHED), ("refit", res.x)):
        e = _gotanda_errors(p, grid, ref)
        e.update({f"held-out {k}": v for k, v in _gotanda_errors(p, held, href).items() if k.startswith("m")})
        errors[name] = e
    return FitResult("gotanda-eq8", GOTANDA_PUBLISHED, res.x, errors, gotanda_code(res.x, errors))


def _f(x: float) -> str:
    s = f"{x:.7g}"
    return s if ("." in s or "e" in s) else s + ".0"


def _header(family: str, errors: dict, comment: str) -> str:
    lines = [f"{comment} lutbake fit {family}: {FAMILIES[family]}", f"{comment} measured error (published -> refit):"]
    lines += [f"{comment}   {k}: {errors['published'][k]:.4g} -> {errors['refit'][k]:.4g}" for k in errors["refit"]]
    return "\n".join(lines) + "\n"


def karis_code(p: np.ndarray, errors: dict) -> dict:
    c0, c1 = ", ".join(_f(x) for x in p[0:4]), ", ".join(_f(x) for x in p[4:8])
    body = (
        "{t}4 r = roughness * {t}4({c0}) + {t}4({c1});\n"
        "    float a004 = min(r.x * r.x, exp2({k} * NoV)) * r.x + r.y;\n"
        "    return {t}2({ms}, {s}) * a004 + r.zw;\n"
    )
    out = {}
    for lang, t in (("glsl", "vec"), ("hlsl", "float")):
        head = _header("karis-mobile", errors, "//")
        sig = f"{t}2 EnvBRDFApprox_lutbake(float NoV, float roughness)"
        code = body.format(t=t, c0=c0, c1=c1, k=_f(p[8]), ms=_f(-p[9]), s=_f(p[9]))
        out[lang] = (
            head
            + "// E = f0 * AB.x + AB.y; roughness = perceptual roughness (alpha = roughness^2)\n"
            + sig
            + " {\n    "
            + code
            + "}\n"
        )
    return out


def gotanda_code(p: np.ndarray, errors: dict) -> dict:
    a1, a2, k, e0, e1, c3, c2, c1, q, v0, v1, v2, v3, v4, v5, bp, lm = (_f(x) for x in p)
    body = f"""    float s2 = sigma * sigma;
    float omv = 1.0 - NoV, oml = 1.0 - NoL, kk = s2 + {k};
    float Fr = (1.0 - ({a1} * s2 + {a2} * sigma) / kk) * (1.0 - pow(omv, {e0} - {e1} * s2) / kk)
             * (({c3} * s2 * sigma + {c2} * s2 + {c1} * sigma) * pow(omv, 1.0 + 1.0 / ({q} * s2 * s2 + 1.0)) + 1.0);
    float Lm = (max(1.0 - 2.0 * sigma, 0.0) * (1.0 - pow(oml, 5.0)) + min(2.0 * sigma, 1.0))
             * ((1.0 - {lm} * sigma) * NoL + {lm} * sigma * NoL * NoL);
    float Vd = s2 / ((s2 + {v0}) * ({v1} + {v2} * NoV))
             * (1.0 - pow(oml, (1.0 - {v3} * NoV * NoV) / ({v4} + {v5} * NoV)));
    float d = LoV - NoL * NoV;
    float Bp = d < 0.0 ? {bp} * NoV * NoL * d : d;
    return 21.0 / (20.0 * 3.14159265) * (1.0 - f0) * (Fr * Lm + Vd * Bp);   // radiance per unit irradiance
"""
    out = {}
    for lang in ("glsl", "hlsl"):
        head = _header("gotanda-eq8", errors, "//")
        out[lang] = (
            head + "// Gotanda 2014 Eq. 8 with refit constants; diffuse radiance = rho * E0 * this; "
            "BRDF = this / NoL\nfloat Fd_gotanda_refit(float NoL, float NoV, float LoV, float sigma, "
            "float f0) {\n" + body + "}\n"
        )
    return out


def fit(family: str) -> FitResult:
    if family == "karis-mobile":
        return fit_karis()
    if family == "gotanda-eq8":
        return fit_gotanda()
    raise ValueError(f"unknown fit family {family!r}; allowed: {', '.join(FAMILIES)}")
