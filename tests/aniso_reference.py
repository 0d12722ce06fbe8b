"""numpy reference of the view-azimuth-averaged anisotropic GGX split sum (independent of lutbake's @wp.funcs and of
its panelled rule): E = (1/pi) ∫_0^pi dbeta ∫ f(l, v) (n.l) dω_l, f = D G2 / (4 (n.l)(n.v)), anisotropic GGX
(Heitz 2014, Eq. 85) with alpha_x along the tangent frame's T, rotated by beta about n, height-correlated Smith G2 with
the anisotropic Lambda (Eq. 86), Schlick's split-sum channels (1 - Fc, Fc), Fc = (1 - v.h)^5. The l integral is a
product Gauss-Legendre rule in (theta_l, phi_l) graded toward the mirror direction (theta_v, pi) and the horizon
(tests/conftest.py graded_gauss_legendre); beta by the periodic trapezoid rule. At nbeta = 160, order 16, levels 14
it agrees with nbeta = 256, order 20, levels 16 to 1e-15 at (n.v, alpha_x, alpha_y) = (0.02, 0.3, 0.03),
(0.5, 1.0, 0.1), (0.9, 0.05, 0.005), (0.2, 0.3, 0.2); the default nbeta = 96, order 12, levels 12 agrees with that
to 1.2e-10 at those texels and (0.004, 0.1, 0.01), both models (~0.8 s a texel instead of ~2.6 s)."""

import numpy as np
from conftest import graded_gauss_legendre


def lambda_aniso(w, ax, ay):
    return 0.5 * (np.sqrt(w[..., 2] ** 2 + ax * ax * w[..., 0] ** 2 + ay * ay * w[..., 1] ** 2) / w[..., 2] - 1.0)


def averaged_split_sum(nov, ax, ay, nbeta=96, order=12, levels=12, model="microfacet"):
    """(scale, bias) of the view-azimuth-averaged table at n.v = nov (module docstring); ``model``: "microfacet"
    (anisotropic GGX) or "ashikhmin_shirley" (Ashikhmin & Shirley 2000: 4 (v.h) f (n.l) = p_h (n.l) / max(n.l, n.v),
    p_h = sqrt((nu + 1)(nv + 1)) / (2 pi) (n.h)^((nu h_x^2 + nv h_y^2) / (1 - (n.h)^2)), nu = 2 / ax^2 - 2 along x,
    nv = 2 / ay^2 - 2 (both >= 0); its kink at n.l = n.v is a grading point of the l rule: theta_l = theta_v).
    Both lobes are even in beta (the l rule is symmetric about the xz-plane, v in it) and pi-periodic, so the
    trapezoid rule's nodes beta and pi - beta are summed once, twice weighted (``nbeta`` even); what does not depend
    on beta (h, l, Fc, the weights; A-S: n.h, (n.l) / max(n.l, n.v), v.h) is computed once. Equal to the plain sum
    over every node and frame to 3.5e-14 at the texels above."""
    assert nbeta % 2 == 0
    sv = np.sqrt(1.0 - nov * nov)
    t, wt = graded_gauss_legendre(0.0, np.pi / 2, [np.arccos(nov), np.pi / 2], levels=levels, order=order)
    p, wp_ = graded_gauss_legendre(0.0, 2 * np.pi, [np.pi], levels=levels, order=order)
    T, P = np.meshgrid(t, p, indexing="ij")
    W = (np.outer(wt, wp_) * np.sin(T)).ravel()
    l = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    v = np.array([sv, 0.0, nov])
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    fc = (1.0 - h @ v) ** 5
    channels = np.stack([W * (1.0 - fc), W * fc], axis=1)  # (points, 2): the split sum's weights
    h0, h1, l0, l1, l2 = h[:, 0], h[:, 1], l[:, 0], l[:, 1], l[:, 2]
    if model == "microfacet":
        h2sq, l2sq = h[:, 2] ** 2, l2 * l2
    else:
        nu, nv = max(2.0 / ax**2 - 2.0, 0.0), max(2.0 / ay**2 - 2.0, 0.0)
        x = h0 * h0 + h1 * h1
        log_nh = 0.5 * np.log1p(-x) / np.maximum(x, 1e-300)  # ln(n.h) / (1 - (n.h)^2)
        rest = np.sqrt((nu + 1) * (nv + 1)) / (2 * np.pi) * l2 / np.maximum(l2, nov) / (4.0 * (h @ v))
    half = nbeta // 2
    out = np.zeros(2)
    for k in range(half + 1):
        b = k * np.pi / nbeta
        c, s = np.cos(b), np.sin(b)
        hx, hy = c * h0 + s * h1, c * h1 - s * h0  # h in the frame rotated by beta
        if model == "microfacet":
            lx, ly = c * l0 + s * l1, c * l1 - s * l0
            d = (hx / ax) ** 2 + (hy / ay) ** 2 + h2sq
            lam_v = lambda_aniso(np.array([c * sv, -s * sv, nov]), ax, ay)
            lam_l = 0.5 * (np.sqrt(l2sq + ax * ax * lx * lx + ay * ay * ly * ly) / l2 - 1.0)
            f_cos = 1.0 / (np.pi * ax * ay * d * d) / (1.0 + lam_v + lam_l) / (4 * nov)
        else:
            f_cos = rest * np.exp((nu * hx * hx + nv * hy * hy) * log_nh)
        out += (1.0 if k in (0, half) else 2.0) * (f_cos @ channels)
    return out / nbeta
