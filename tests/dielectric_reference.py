"""An independent numpy reference for the rough dielectric energies: integrals over the OUTGOING direction o on the
whole sphere, in its own spherical coordinates about n, with the BSDF written directly from Walter et al. 2007
(Eqs. 20-21) and the Fresnel term from complex arithmetic (a different method from the package's half-vector
quadrature and its closed-form F):

    E_R = ∫_{n.o > 0} f_r(v, o) n.o dω_o,   f_r = F(v.h_r) D(h_r) G2(v, o) / (4 n.v n.o),  h_r = (v + o) / |v + o|
    E_T = ∫_{n.o < 0} f_t(v, o) |n.o| dω_o,
          f_t = |v.h||o.h| eta^2 (1 - F(v.h)) D(h) G2(v, o) / (n.v |n.o| (v.h + eta o.h)^2),
          h = -(v + eta o) / |v + eta o| (flipped to n.h > 0), valid where v.h > 0 > o.h
    dω_o = sin(theta) dtheta dphi, phi in [0, pi] twice (v lies in the xz-plane).

Composite Gauss-Legendre (GL_NODES per panel) with panels graded geometrically (PANEL_RATIO) from every anchor:
the lobe peaks (mirror and refracted directions, at phi = pi), and the curves where the integrand is not smooth:
the cone v.o = -min(eta, 1/eta) that bounds transmission, the circle n.o = -n.v / eta where the transmission
half vector reaches the horizon (GGX's D(pi/2) = alpha^2 / pi: the integrand jumps to 0 there),
the cone v.o = 2 cos^2(theta_c) - 1 where reflection's
Fresnel has its total-internal-reflection kink (eta < 1), and the horizon. Each is a closed-form breakpoint in phi at
every theta (cos(phi) = (k - n.v cos(theta)) / (sin(theta_v) sin(theta))) and enters [0, pi] at closed-form theta.
"""

from __future__ import annotations

import numpy as np
from test_reference_dfg import NDF

GL_NODES = 12
PANEL_RATIO = 3.0
FIRST = 1.0e-5  # first panel width next to an anchor (rad)
CHUNK = 4096  # phi panels per vectorised evaluation


def fresnel_np(eta, c):
    """Unpolarised Fresnel reflectance from complex arithmetic (TIR gives |r| = 1): relative index eta, cos c."""
    c = np.clip(np.asarray(c, np.float64), 0.0, 1.0)
    ct = np.sqrt((1.0 - (1.0 - c * c) / (eta * eta)).astype(np.complex128))
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


def G2_np(masking, lam_i, lam_o):
    if masking == "smith_height_correlated":
        return 1.0 / (1.0 + lam_i + lam_o)
    return 1.0 / ((1.0 + lam_i) * (1.0 + lam_o))


def schlick_weight(x):
    return np.clip(1.0 - x, 0.0, 1.0) ** 5


def eevee_s(eta, c):
    """Blender EEVEE's Schlick weight s of a facet with v.h = c (eevee_lut_comp.glsl): (1 - v.h)^5 for eta >= 1
    (ggx_btdf_gt_one); (1 - |t.h|)^5 with t the refracted direction for eta < 1 (ggx_bsdf_split_sum; 1 under TIR)."""
    if eta >= 1.0:
        return schlick_weight(c)
    ct2 = 1.0 - (1.0 - c * c) / (eta * eta)
    return schlick_weight(np.sqrt(np.maximum(ct2, 0.0)))


def _norm(x):
    """|x| of rows x (n, 3), as a column."""
    return np.sqrt(x[:, 0] * x[:, 0] + x[:, 1] * x[:, 1] + x[:, 2] * x[:, 2])[:, None]


def _lobes(v, o, alpha, eta, ndf, masking, fresnel, side):
    """The lobes of bsdf on one side at directions o (n, 3) (side "r": f_r, or EEVEE's two reflection lobes; "t":
    f_t, or EEVEE's one, evaluated only where it is not 0: below the surface with v.h > 0 > o.h)."""
    D, Lam = NDF[ndf]
    nov = v[2]
    lam_v = Lam(np.float64(nov), alpha)
    with np.errstate(divide="ignore", invalid="ignore"):
        if side == "t":
            ht = -(v + eta * o)
            ht = ht / _norm(ht)
            ht = np.where(ht[..., 2:3] < 0, -ht, ht)
            vh = ht @ v
            oh = ht[:, 0] * o[:, 0] + ht[:, 1] * o[:, 1] + ht[:, 2] * o[:, 2]
            out, keep = np.zeros(len(o)), np.flatnonzero((o[:, 2] < 0) & (vh > 0) & (oh < 0))
            o, ht, vh, oh = o[keep], ht[keep], vh[keep], oh[keep]
        noo = o[..., 2]
        lam_o = Lam(np.abs(noo), alpha)
        g2 = G2_np(masking, lam_v, lam_o)
        if side == "r":
            hr = v + o
            hr = hr / _norm(hr)
            vhr = hr @ v
            if fresnel == "eevee":
                fr0 = np.where((noo > 0) & (vhr > 0), D(hr[..., 2], alpha) * g2 / (4.0 * nov * noo), 0.0)
                sr = eevee_s(eta, vhr)
                return np.nan_to_num((1 - sr) * fr0), np.nan_to_num(sr * fr0)
            fr = fresnel_np(eta, vhr) * D(hr[..., 2], alpha) * g2 / (4.0 * nov * noo)
            return (np.nan_to_num(np.where((noo > 0) & (vhr > 0), fr, 0.0)),)
        ft = (
            np.abs(vh * oh)
            * eta
            * eta
            * (1.0 - fresnel_np(eta, vh))
            * D(ht[..., 2], alpha)
            * g2
            / (nov * np.abs(noo) * (vh + eta * oh) ** 2)
        )
        if fresnel == "eevee":
            ft = (1 - eevee_s(eta, vh)) * (ft / (1.0 - fresnel_np(eta, vh)))
        out[keep] = np.nan_to_num(ft)
    return (out,)


def bsdf(v, o, alpha, eta, ndf="ggx", masking="smith_separable", fresnel="exact"):
    """(f_r, f_t) at direction arrays o (..., 3); each is 0 on the other side. ``fresnel = "eevee"`` returns the
    Fresnel-free lobes weighted as EEVEE's tables: ((1 - s) f_r/F, s f_r/F, (1 - s) f_t/(1 - F)) (eevee_s)."""
    o = np.asarray(o, np.float64)
    flat = o.reshape(-1, 3)
    lobes = [_lobes(v, flat, alpha, eta, ndf, masking, fresnel, side) for side in ("r", "t")]
    return tuple(f.reshape(o.shape[:-1]) for f in lobes[0] + lobes[1])


def _edges(lo, hi, anchors):
    """Panel edges on [lo, hi] graded geometrically away from each anchor (first width FIRST, ratio PANEL_RATIO; a
    panel is never wider than its distance to the nearest anchor x PANEL_RATIO), one row per row of ``anchors``
    (n, m): sorted, each edge once, NaN-padded (an anchor outside [lo, hi], or NaN, adds nothing)."""
    d = [FIRST]
    while d[-1] * PANEL_RATIO < hi - lo:
        d.append(d[-1] * PANEL_RATIO)
    a = np.asarray(anchors, np.float64)[..., None]
    near = np.concatenate([a + np.array(d), a - np.array(d)], axis=-1)
    near = np.where((lo <= a) & (a <= hi) & (lo < near) & (near < hi), near, np.nan)
    a = np.where((lo <= a) & (a <= hi), a, np.nan)
    rows = [np.full((len(a), 1), lo), np.full((len(a), 1), hi), a[..., 0], near.reshape(len(a), -1)]
    e = np.sort(np.concatenate(rows, axis=1), axis=1)
    return np.sort(np.where(np.diff(e, axis=1, prepend=-np.inf) > 0, e, np.nan), axis=1)  # repeats dropped


def _gl(lo, hi):
    """Gauss-Legendre nodes and weights (GL_NODES per panel) of panels [lo, hi] (arrays), rows = panels."""
    x, w = np.polynomial.legendre.leggauss(GL_NODES)
    lo, hi = lo[:, None], hi[:, None]
    return lo + (hi - lo) * (x + 1) / 2, (hi - lo) * w / 2


def _cone_thetas(cos_v, sin_v, k, lo, hi):
    """theta in (lo, hi) where cos(phi) = (k - cos_v cos t) / (sin_v sin t) reaches +-1 (the cone v.o = k is tangent
    to the circle theta = t): cos(t -+ theta_v) = k."""
    tv = np.arctan2(sin_v, cos_v)
    a = np.arccos(np.clip(k, -1, 1))
    cands = [tv + a, tv - a, a - tv, -tv - a, 2 * np.pi - a - tv]
    return [t for t in cands if lo < t < hi]


def _phi_cut(cos_v, sin_v, k, theta):
    with np.errstate(divide="ignore", invalid="ignore"):
        cp = (k - cos_v * np.cos(theta)) / (sin_v * np.sin(theta))
    return np.arccos(np.clip(cp, -1.0, 1.0))


def energies(nov, alpha, eta, ndf="ggx", masking="smith_separable", fresnel="exact"):
    """(E_R, E_T) of the texel by the graded product rule (module docstring); fresnel = "eevee": EEVEE's (scale, bias,
    transmission_factor). eta = 1 makes f_t a delta: excluded. Vectorised over every (theta, phi) node of a hemisphere,
    a phi panel per row (the phi edges graded per theta node), CHUNK panels at a time."""
    nov = float(nov)
    sin_v = np.sqrt(max(1.0 - nov * nov, 0.0))
    v = np.array([sin_v, 0.0, nov])
    tv = np.arctan2(sin_v, nov)
    k_t = -min(eta, 1.0 / eta)  # transmission lives where v.o < k_t
    cuts = [k_t]
    if eta < 1.0:
        cuts.append(2.0 * (1.0 - eta * eta) - 1.0)  # reflection's Fresnel kink, v.h_r = cos theta_c
    half = np.pi / 2
    out = []
    for lo, hi, peak in ((0.0, half, tv), (half, np.pi, np.pi - np.arcsin(min(sin_v / eta, 1.0)))):
        anchors = [peak, lo, hi]
        for k in cuts:
            anchors += _cone_thetas(nov, sin_v, k, lo, hi)
        if lo == half and nov < eta:  # n.h_t = 0: the half vector flips, D(h) jumps from D(pi/2) to 0
            anchors.append(np.arccos(-nov / eta))
        e = _edges(lo, hi, [anchors])[0]
        e = e[~np.isnan(e)]
        th, wt = (x.ravel() for x in _gl(e[:-1], e[1:]))
        # phi panels per theta node: graded from 0, pi (the lobe peaks) and each cut's breakpoint at that theta
        cut_phi = [_phi_cut(nov, sin_v, k, th) for k in cuts] if sin_v > 0 else []
        pe = _edges(0.0, np.pi, np.column_stack([np.full_like(th, np.pi), np.zeros_like(th), *cut_phi]))
        row, col = np.nonzero(~np.isnan(pe[:, 1:]) & ~np.isnan(pe[:, :-1]))
        ph, wp = _gl(pe[row, col], pe[row, col + 1])
        total = np.zeros(2 if lo == 0.0 and fresnel == "eevee" else 1)
        sin_t, cos_t = np.sin(th), np.cos(th)
        w_t = wt * sin_t * np.abs(cos_t)
        for c in range(0, len(row), CHUNK):
            r = row[c : c + CHUNK]
            st, ct = sin_t[r][:, None], cos_t[r][:, None]
            p = ph[c : c + CHUNK]
            o = np.stack([st * np.cos(p), st * np.sin(p), np.broadcast_to(ct, p.shape)], axis=-1).reshape(-1, 3)
            fs = _lobes(v, o, alpha, eta, ndf, masking, fresnel, "r" if lo == 0.0 else "t")
            wo = (w_t[r][:, None] * wp[c : c + CHUNK]).ravel()
            total = total + np.array([np.sum(wo * f) for f in fs])
        out += list(2.0 * total)
    return tuple(out)
