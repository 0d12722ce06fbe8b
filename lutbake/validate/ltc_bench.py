"""The area-light benchmark of GGX LTC tables: what a shader shows, through its bilinear lookup.

Cases: per band of perceptual roughness r (``ROUGH_BANDS``) and of view angle theta_v (``VIEW_BANDS``, degrees),
``cases_per_band`` shading points at uniformly random (r, theta_v) inside the band (between texels, not at their
centres), each lit by ``lights_per_case`` random polygon lights (lutbake.ltc.lights: quads and triangles from small
to hemisphere-sized, around the mirror direction and anywhere above -20 degrees, partly below the horizon), all
from one seed (``SEED``; the shaded fit trains on other seeds).

Ground truth: ∫_P f(v, l)(n.l) dω_l (GGX, height-correlated Smith, F = 1) and ∫_P f (1 - v.h)^5 (n.l) dω_l (the
Schlick part) per light, by visible-normal sampling (Heitz 2018, "Sampling the GGX Distribution of Visible
Normals": h ~ D_v(h), l = reflect(v, h), weight f (n.l) / p(l) = G2(v, l) / G1(v) <= 1) on a stratified S x S grid,
each direction tested against the light's cone; numpy, written from the papers (not lutbake's Warp terms). Its
convergence is checked against an independent estimator (NDF sampling, lutbake.validate.ltc_area.sample_lobe) at
another sample count (tests/test_ltc.py, ``make bench``).

Shader side: lutbake.ltc.polygon.shade, ltc_code's lookup uv = (r, sqrt(1 - NoV)) (N - 1)/N + 0.5/N, bilinear
fetch of both textures (clamp to edge), M^-1 from ltc_1, horizon clip, exact edge integral, two-sided,
value = (f0 t2.x + (1 - f0) t2.y) I.

Errors, per light: relative |value - truth| / truth where the truth exceeds ``REL_FLOOR`` x the albedo (the whole
lobe's integral ∫ f (n.l) dω, by the same samples); and |value - truth| / albedo (every light). With Schlick Fresnel
of reflectance f0 the truth is f0 lobe + (1 - f0) schlick and the albedo likewise.
"""

from __future__ import annotations

import numpy as np

from ..ltc import lights as ltc_lights
from ..ltc import polygon

SEED = 2024
ROUGH_BANDS = ((0.05, 0.3), (0.3, 0.55), (0.55, 0.8), (0.8, 1.0))  # perceptual roughness r, alpha = r^2
VIEW_BANDS = ((0.0, 30.0), (30.0, 60.0), (60.0, 80.0), (80.0, 89.5))  # theta_v, degrees
REL_FLOOR = 1.0e-3
F0_DIELECTRIC = 0.04


def _lambda_ggx(c, alpha):
    c = np.clip(c, 1e-12, 1.0)
    return 0.5 * (np.sqrt(c * c + alpha * alpha * (1.0 - c * c)) / c - 1.0)


def sample_vndf_ggx(v: np.ndarray, alpha: float, s: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(l (S^2, 3), weight f (n.l) / p(l) = G2 / G1(v), (1 - v.h)^5) on a stratified S x S grid: Heitz 2018's
    visible-normal sampler (Listing 1) for isotropic GGX, height-correlated Smith G2 (Heitz 2014, Eq. 99)."""
    u = (np.arange(s) + 0.5) / s
    u1, u2 = (x.ravel() for x in np.meshgrid(u, u))
    vh = np.array([alpha * v[0], alpha * v[1], v[2]])
    vh /= np.linalg.norm(vh)
    lensq = vh[0] ** 2 + vh[1] ** 2
    t1 = np.array([-vh[1], vh[0], 0.0]) / np.sqrt(lensq) if lensq > 0 else np.array([1.0, 0.0, 0.0])
    t2 = np.cross(vh, t1)
    r = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    sh = 0.5 * (1.0 + vh[2])
    p2 = (1.0 - sh) * np.sqrt(1.0 - p1 * p1) + sh * p2
    nh = p1[:, None] * t1 + p2[:, None] * t2 + np.sqrt(np.maximum(0.0, 1.0 - p1 * p1 - p2 * p2))[:, None] * vh
    h = np.stack([alpha * nh[:, 0], alpha * nh[:, 1], np.maximum(1e-7, nh[:, 2])], 1)
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    voh = h @ v
    l = 2.0 * voh[:, None] * h - v
    nol = l[:, 2]
    lv, ll = _lambda_ggx(v[2], alpha), _lambda_ggx(nol, alpha)
    w = np.where(nol > 0, (1.0 + lv) / (1.0 + lv + ll), 0.0)
    return l, w, (1.0 - np.clip(voh, 0.0, 1.0)) ** 5


def view(theta_deg: float) -> np.ndarray:
    t = np.radians(theta_deg)
    return np.array([np.sin(t), 0.0, np.cos(t)])


def cases(cases_per_band: int, lights_per_case: int, seed: int = SEED) -> list[dict]:
    """The benchmark's shading points and lights: dicts with r, theta (deg), nov, band indices, lights (k, 4, 3)."""
    rng = np.random.default_rng(seed)
    out = []
    for i, (r0, r1) in enumerate(ROUGH_BANDS):
        for j, (t0, t1) in enumerate(VIEW_BANDS):
            for _ in range(cases_per_band):
                r, th = rng.uniform(r0, r1), rng.uniform(t0, t1)
                v = view(th)
                out.append(
                    {
                        "r": float(r),
                        "theta": float(th),
                        "nov": float(v[2]),
                        "rough_band": i,
                        "view_band": j,
                        "lights": ltc_lights.random_lights(rng, v, r * r, lights_per_case),
                    }
                )
    return out


def ground_truth(case: dict, s: int, sampler: str = "vndf") -> dict:
    """Per light: ∫_P f (n.l) dω (``lobe``) and ∫_P f (1 - v.h)^5 (n.l) dω (``schlick``), and the albedo, by the
    stratified S x S estimator of ``sampler`` ("vndf", or "ndf": lutbake.validate.ltc_area.sample_lobe)."""
    v, alpha = view(case["theta"]), case["r"] ** 2
    if sampler == "vndf":
        l, w, f5 = sample_vndf_ggx(v, alpha, s)
    else:
        from .ltc_area import sample_lobe

        l, w = sample_lobe("ggx", v, alpha, s)
        h = l + v
        h /= np.linalg.norm(h, axis=1, keepdims=True)
        f5 = (1.0 - np.clip(h @ v, 0.0, 1.0)) ** 5
    keep = w > 0
    l, w, f5 = l[keep], w[keep], f5[keep]
    hit = ltc_lights.inside(l, case["lights"])
    n = s * s
    return {
        "lobe": (w @ hit) / n,
        "schlick": ((w * f5) @ hit) / n,
        "albedo": float(w.sum() / n),
        "schlick_albedo": float((w * f5).sum() / n),
    }


def shade(ltc_1: np.ndarray, ltc_2: np.ndarray, case: dict, ltc_3: np.ndarray | None = None) -> np.ndarray:
    """(2, k): the shader's value per light for F = 1 (row 0: t2.x I) and the Schlick part (row 1: t2.y I); with
    ``ltc_3`` (a two-lobe shader) the Schlick part's polygon integral goes through ltc_3's matrix."""
    out = np.empty((2, len(case["lights"])))
    for k, p in enumerate(case["lights"]):
        out[0, k] = polygon.shade(ltc_1, ltc_2, case["r"], case["nov"], p, f0=1.0)
        out[1, k] = polygon.shade(ltc_1 if ltc_3 is None else ltc_3, ltc_2, case["r"], case["nov"], p, f0=0.0)
    return out


def errors(
    ltc_1: np.ndarray,
    ltc_2: np.ndarray,
    cs: list[dict],
    truths: list[dict],
    f0: float = 1.0,
    ltc_3: np.ndarray | None = None,
) -> dict:
    """Per light of every case (flat arrays): rel (NaN where the truth is below the floor), abs (/ albedo), bands."""
    rel, ab, rb, vb = [], [], [], []
    for c, g in zip(cs, truths):
        val = shade(ltc_1, ltc_2, c, ltc_3)
        got = f0 * val[0] + (1.0 - f0) * val[1]
        want = f0 * g["lobe"] + (1.0 - f0) * g["schlick"]
        alb = max(f0 * g["albedo"] + (1.0 - f0) * g["schlick_albedo"], 1e-12)
        e = np.abs(got - want)
        rel.append(np.where(want > REL_FLOOR * alb, e / np.where(want > 0, want, 1.0), np.nan))
        ab.append(e / alb)
        rb.append(np.full(len(e), c["rough_band"]))
        vb.append(np.full(len(e), c["view_band"]))
    return {
        "rel": np.concatenate(rel),
        "abs": np.concatenate(ab),
        "rough": np.concatenate(rb),
        "view": np.concatenate(vb),
    }


def stats(err: dict, sel: np.ndarray | None = None) -> dict:
    """median / p90 / max of the relative error and of |error| / albedo over the selected lights."""
    sel = np.ones(len(err["abs"]), bool) if sel is None else sel
    rel = err["rel"][sel]
    rel = rel[np.isfinite(rel)]
    ab = err["abs"][sel]
    q = lambda x, p: float(np.quantile(x, p)) if len(x) else float("nan")  # noqa: E731
    return {
        "lights": int(sel.sum()),
        "rel_lights": int(len(rel)),
        "rel_median": q(rel, 0.5),
        "rel_p90": q(rel, 0.9),
        "rel_max": float(rel.max()) if len(rel) else float("nan"),
        "abs_median": q(ab, 0.5),
        "abs_p90": q(ab, 0.9),
        "abs_max": float(ab.max()) if len(ab) else float("nan"),
    }


def band_name(kind: str, i: int) -> str:
    if kind == "rough":
        a, b = ROUGH_BANDS[i]
        return f"r {a:g}-{b:g}"
    a, b = VIEW_BANDS[i]
    return f"theta {a:g}-{b:g}"


def report(err: dict) -> dict:
    """Overall, per roughness band, per view band and per (roughness, view) band."""
    out = {"all": stats(err)}
    for i in range(len(ROUGH_BANDS)):
        out[band_name("rough", i)] = stats(err, err["rough"] == i)
    for j in range(len(VIEW_BANDS)):
        out[band_name("view", j)] = stats(err, err["view"] == j)
    for i in range(len(ROUGH_BANDS)):
        for j in range(len(VIEW_BANDS)):
            sel = (err["rough"] == i) & (err["view"] == j)
            out[f"{band_name('rough', i)} / {band_name('view', j)}"] = stats(err, sel)
    return out


def lookup_texels(cs: list[dict], n: int) -> list[tuple[int, int]]:
    """The (view row, roughness column) texels the shader's bilinear lookups of the cases read (n x n table)."""
    out = set()
    for c in cs:
        u, v = polygon.lookup_uv(n, c["r"], c["nov"])
        x, y = np.clip(u * n - 0.5, 0.0, n - 1.0), np.clip(v * n - 0.5, 0.0, n - 1.0)
        for a in {int(np.floor(x)), min(int(np.floor(x)) + 1, n - 1)}:
            for t in {int(np.floor(y)), min(int(np.floor(y)) + 1, n - 1)}:
                out.add((t, a))
    return sorted(out)


def l3_texels(texels: list[tuple[int, int]], n: int = 64) -> tuple:
    """The L3 fit of ``texels`` of a GGX n x n table as the ``ltc`` kind fits them (its magnitude, its coarse pass
    and seeding): (problem, flat texel indices, packed ltc_1 (k, 4), magnitude (n^2,), fresnel (n^2,)), what
    fitted_texels refines (pass it as ``l3`` to refine one fit several ways)."""
    from ..kinds.ltc import axes_for
    from ..ltc import fit
    from ..ltc.magnitude import magnitude_alpha, magnitude_fresnel, texel_params

    axes = axes_for({"lobe": "ggx", "size": [n, n]})
    nov, alpha = texel_params(axes)
    mag, fres = magnitude_fresnel("ggx", nov, magnitude_alpha(axes), None)
    prob = fit.Problem("ggx", nov, alpha, mag)
    idx = np.array([t * n + a for t, a in texels])
    m, _ = fit.fit_texels(prob, idx, n, fit.coarse_pass(prob, n, n))
    return prob, idx, fit.pack_inverse(m), mag, fres


def fitted_texels(
    texels: list[tuple[int, int]],
    fit_kind: str = "shaded",
    n: int = 64,
    f0_weight: float | None = None,
    l3: tuple | None = None,
) -> tuple[np.ndarray, ...]:
    """A GGX n x n table (ltc_1, ltc_2) with only ``texels`` filled, fitted as the ``ltc`` kind fits them (its
    magnitude, its coarse pass and seeding, and for ``fit_kind`` "shaded" its refinement; the sphere and fit-error
    channels are left 0): enough for the cases whose lookups read only these texels, at a fraction of a table's cost.
    ``fit_kind`` "two_lobe": (ltc_1, ltc_2, ltc_3) of a two-lobe shader, ltc_1 the shaded fit of F = 1 alone and
    ltc_3 the matrix of the Schlick part's own shaded fit (lutbake.ltc.shaded.refine ``schlick_lobe``), t2.y its
    fresnel channel. ``l3``: l3_texels(texels, n) where the caller has it (the same bits, not fitted again)."""
    from ..ltc import shaded

    prob, idx, packed, mag, fres = l3_texels(texels, n) if l3 is None else l3
    mg, fr = mag[idx], fres[idx]
    t1, t2, t3 = np.zeros((n * n, 4)), np.zeros((n * n, 4)), np.zeros((n * n, 4))
    if fit_kind == "two_lobe":
        t3[idx], _, fr = shaded.refine(prob, idx, packed, fres[idx], schlick_lobe=True)
        packed, mg, _ = shaded.refine(prob, idx, packed, fres[idx], f0_weight=0.0)
    elif fit_kind == "shaded":
        w = shaded.F0_WEIGHT if f0_weight is None else f0_weight
        packed, mg, fr = shaded.refine(prob, idx, packed, fres[idx], f0_weight=w)
    t1[idx], t2[idx, 0], t2[idx, 1] = packed, mg, fr
    tables = (t1.reshape(n, n, 4), t2.reshape(n, n, 4), t3.reshape(n, n, 4))
    return tables if fit_kind == "two_lobe" else tables[:2]
