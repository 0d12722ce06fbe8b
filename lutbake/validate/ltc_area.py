"""Area-light ground truth for LTC tables: magnitude x polygon integral of the transformed cosine against a
brute-force integral of f(v, l)(n.l) over the polygon's solid angle, per lobe and roughness.

The brute force is independent of the fit: numpy lobes written from the papers here (not the Warp terms), the
integral ∫_P f(v, l)(n.l) dω_l estimated with the lobe's own importance sampler on a stratified S x S grid
(GGX / Beckmann: h ~ D(h)(n.h), l = reflect(v, h), weight f (n.l) / p(l) = G2 (v.h) / ((n.v)(n.h)); charlie,
lambert: cosine sampling), each sample tested against the polygon (ray from the shading point); the diffuse lobes
gotanda and eon: cosine sampling with f from lutbake's diffuse integrands at each sample (Eq. 4 by its GL quadrature
at order ``DIFFUSE_ORDER``, not the LTC fit's tabulated and interpolated lobe; EON's closed form, itself tested
against a numpy port of the paper's listing in tests/test_eon.py). The LTC side is
lutbake.ltc.polygon.shade at the texel's own (NoV, roughness) (no interpolation: the error measured is the
fit's, plus the tabulated magnitude's).

The light set (``light_set``): quads and triangles of several sizes, distances and orientations, facing the
mirror direction, the side and the viewer, several crossing the horizon (clipped by the LTC side; the brute
force simply finds no sample below the horizon).
"""

from __future__ import annotations

import numpy as np
from scipy.special import erf

from ..ltc import polygon

# (shape, elevation above the horizon (deg), azimuth (deg; 180 = towards the mirror direction), distance, size,
#  tilt of the light's normal away from the shading point (deg), roll (deg))
LIGHTS = (
    ("quad", 90, 0, 2.0, 1.0, 0, 0),
    ("quad", 60, 180, 2.0, 1.0, 0, 20),
    ("quad", 30, 180, 1.5, 1.0, 20, 0),
    ("quad", 8, 180, 1.0, 2.0, 0, 0),  # crosses the horizon
    ("quad", 45, 90, 1.0, 1.0, 30, 45),
    ("quad", 15, 0, 1.0, 1.0, 0, 10),  # crosses the horizon, behind the viewer's side
    ("quad", 50, 180, 10.0, 0.5, 0, 0),  # small and far
    ("quad", 80, 30, 1.0, 20.0, 0, 0),  # covers most of the hemisphere
    ("triangle", 70, 180, 3.0, 2.0, 10, 0),
    ("triangle", 20, 180, 1.0, 1.5, 0, 30),  # crosses the horizon
    ("triangle", 30, 135, 2.0, 1.0, 40, 0),
    ("triangle", 10, 270, 1.0, 2.0, 0, 0),  # crosses the horizon
)
DIFFUSE_MODELS = {"gotanda": "microfacet", "eon": "eon"}  # LTC lobe -> lutbake.integrands.diffuse model
DIFFUSE_ORDER = 12  # GL order of Eq. 4's m-integral in the brute force (the fit's table uses 8)
GT_FLOOR = 1.0e-3  # relative errors are taken where the ground truth exceeds this fraction of the magnitude


def _basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1)


def light_polygon(shape, elev, azim, dist, size, tilt, roll) -> np.ndarray:
    """Vertices (k, 3) in the shading frame, counter-clockwise seen from the shading point."""
    e, a = np.radians(elev), np.radians(azim)
    c = dist * np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    n = -c / dist
    t1, t2 = _basis(n)
    tl = np.radians(tilt)
    n = np.cos(tl) * n + np.sin(tl) * t1
    t1, t2 = _basis(n)
    r = np.radians(roll)
    t1, t2 = np.cos(r) * t1 + np.sin(r) * t2, -np.sin(r) * t1 + np.cos(r) * t2
    angles = np.radians([45, 135, 225, 315]) if shape == "quad" else np.radians([90, 210, 330])
    rad = size / 2 * (np.sqrt(2.0) if shape == "quad" else 1.0)
    return np.array([c + rad * (np.cos(q) * t1 + np.sin(q) * t2) for q in angles])


def light_set() -> list[tuple[str, np.ndarray]]:
    return [
        (f"{s} el{e} az{a} d{d:g} s{sz:g} tilt{t}", light_polygon(s, e, a, d, sz, t, r))
        for s, e, a, d, sz, t, r in LIGHTS
    ]


# ---- numpy lobes (Walter et al. 2007; Heitz 2014; Estevez & Kulla 2017; Ashikhmin & Premoze 2007) ----


def _lambda_ggx(c, alpha):
    c = np.clip(c, 1e-12, 1.0)
    return 0.5 * (np.sqrt(c * c + alpha * alpha * (1.0 - c * c)) / c - 1.0)


def _lambda_beckmann(c, alpha):
    c = np.clip(c, 1e-12, 1.0)
    s = np.sqrt(np.maximum(1.0 - c * c, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.where(s > 0, c / (alpha * np.where(s > 0, s, 1.0)), np.inf)
        lam = np.where(a < 9.0, 0.5 * (erf(a) - 1.0) + np.exp(-a * a) / (2.0 * a * np.sqrt(np.pi)), 0.0)
    return lam


def sample_lobe(lobe: str, v: np.ndarray, alpha: float, s: int) -> tuple[np.ndarray, np.ndarray]:
    """(l (S^2, 3), weight f (n.l) / p(l)) on a stratified S x S grid; weight 0 below the horizon."""
    u = (np.arange(s) + 0.5) / s
    u1, u2 = (x.ravel() for x in np.meshgrid(u, u))
    phi = 2.0 * np.pi * u1
    if lobe in ("ggx", "beckmann"):
        tan2 = alpha * alpha * (u2 / (1.0 - u2) if lobe == "ggx" else -np.log1p(-u2))
        ch = 1.0 / np.sqrt(1.0 + tan2)
        sh = np.sqrt(tan2) * ch
        h = np.stack([sh * np.cos(phi), sh * np.sin(phi), ch], axis=1)
        voh = h @ v
        l = 2.0 * voh[:, None] * h - v
        nol, nov = l[:, 2], v[2]
        lam = _lambda_ggx if lobe == "ggx" else _lambda_beckmann
        g2 = 1.0 / (1.0 + lam(nov, alpha) + lam(nol, alpha))
        w = np.where((nol > 0) & (voh > 0), g2 * voh / (nov * ch), 0.0)
        return l, w
    ct = np.sqrt(u2)
    st = np.sqrt(1.0 - u2)
    l = np.stack([st * np.cos(phi), st * np.sin(phi), ct], axis=1)
    if lobe == "lambert":
        return l, np.ones(len(l))
    h = l + v
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    sin2 = h[:, 0] ** 2 + h[:, 1] ** 2
    d = (2.0 + 1.0 / alpha) * sin2 ** (0.5 / alpha) / (2.0 * np.pi)
    vis = 1.0 / (4.0 * (l[:, 2] + v[2] - l[:, 2] * v[2]))
    return l, np.pi * d * vis  # f (n.l) / (n.l / pi)


def hits(l: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Rays from the origin along l that cross the convex polygon (either side)."""
    nrm = np.cross(poly[1] - poly[0], poly[2] - poly[0])
    den = l @ nrm
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (poly[0] @ nrm) / den
    x = t[:, None] * l
    inside = t > 0
    sgn = None
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        side = np.cross(b - a, x - a) @ nrm
        sgn = side if sgn is None else sgn
        inside &= side >= 0
    return inside


def brute_force(lobe: str, nov: float, alpha: float, polys: list[np.ndarray], s: int = 512) -> np.ndarray:
    """∫_P f(v, l)(n.l) dω_l per polygon (F = 1), the stratified estimator above (``alpha``: the lobe's parameter,
    sigma for gotanda, r for eon)."""
    v = np.array([np.sqrt(max(1.0 - nov * nov, 0.0)), 0.0, nov])
    l, w = sample_lobe("lambert" if lobe in DIFFUSE_MODELS else lobe, v, alpha, s)
    above = l[:, 2] > 0
    l, w = l[above], w[above]
    inside = [hits(l, p) for p in polys]
    if lobe in DIFFUSE_MODELS:  # weight f (n.l) / (n.l / pi) at the samples some light covers
        from ..integrands.diffuse import eval_brdf

        need = np.flatnonzero(np.any(inside, axis=0))
        w = np.zeros(len(l))
        vv = np.broadcast_to(v, (len(need), 3))
        w[need] = np.pi * eval_brdf(DIFFUSE_MODELS[lobe], l[need], vv, alpha, order=DIFFUSE_ORDER)
    return np.array([np.sum(w[h]) for h in inside]) / (s * s)


def ltc_value(t1: np.ndarray, t2: np.ndarray, nov: float, poly: np.ndarray) -> float:
    """magnitude * I at one texel's own values (two-sided), the edge integral exact."""
    minv = polygon.inverse_matrix(t1)
    return float(t2[0]) * abs(polygon.form_factor(poly @ minv.T))


def compare(
    lobe: str,
    ltc_1: np.ndarray,
    ltc_2: np.ndarray,
    nov_values: np.ndarray,
    alpha_values: np.ndarray,
    texels: list[tuple[int, int]],
    s: int = 512,
    references: dict | None = None,
) -> list[dict]:
    """Per (view row t, roughness column a) texel and light: the LTC value, the brute force, their errors.
    ``references``: a dict the brute-force integrals are kept in per (lobe, NoV, alpha, s), for calls that compare
    several tables at the same texels (they do not depend on the table)."""
    lights = light_set()
    polys = [p for _, p in lights]
    rows = []
    for t, a in texels:
        nov, alpha = float(nov_values[t]), float(alpha_values[a])
        key = (lobe, nov, alpha, s)
        gt = references.get(key) if references is not None else None
        if gt is None:
            gt = brute_force(lobe, nov, alpha, polys, s)
            if references is not None:
                references[key] = gt
        mag = float(ltc_2[t, a, 0])
        for (name, p), g in zip(lights, gt):
            val = ltc_value(ltc_1[t, a], ltc_2[t, a], nov, p)
            rows.append(
                {
                    "t": t,
                    "a": a,
                    "nov": nov,
                    "alpha": alpha,
                    "light": name,
                    "ltc": val,
                    "reference": g,
                    "abs_error": abs(val - g) / max(mag, 1e-12),
                    "rel_error": abs(val - g) / g if g > GT_FLOOR * mag else None,
                }
            )
    return rows


def summarise(rows: list[dict], key: str = "a") -> dict:
    """Per roughness column: median / p90 / max relative error (where defined) and max error / magnitude."""
    out = {}
    for k in sorted({r[key] for r in rows}):
        sel = [r for r in rows if r[key] == k]
        rel = np.array([r["rel_error"] for r in sel if r["rel_error"] is not None])
        ab = np.array([r["abs_error"] for r in sel])
        out[k] = {
            "cases": len(sel),
            "rel_cases": int(len(rel)),
            "rel_median": float(np.median(rel)) if len(rel) else None,
            "rel_p90": float(np.quantile(rel, 0.9)) if len(rel) else None,
            "rel_max": float(rel.max()) if len(rel) else None,
            "abs_max": float(ab.max()),
        }
    return out
