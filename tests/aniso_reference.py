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


def ashikhmin_shirley_f_cos(hr, lr, nov, ax, ay):
    """Ashikhmin & Shirley 2000: 4 (v.h) f (n.l) = p_h (n.l) / max(n.l, n.v), p_h = sqrt((nu + 1)(nv + 1)) / (2 pi)
    (n.h)^((nu h_x^2 + nv h_y^2) / (1 - (n.h)^2)), nu = 2 / ax^2 - 2 along x, nv = 2 / ay^2 - 2 (both >= 0)."""
    nu, nv = max(2.0 / ax**2 - 2.0, 0.0), max(2.0 / ay**2 - 2.0, 0.0)
    x = hr[..., 0] ** 2 + hr[..., 1] ** 2
    e = (nu * hr[..., 0] ** 2 + nv * hr[..., 1] ** 2) / np.maximum(x, 1e-300)
    p_h = np.sqrt((nu + 1) * (nv + 1)) / (2 * np.pi) * np.exp(e * 0.5 * np.log1p(-x))
    return p_h * lr[..., 2] / np.maximum(lr[..., 2], nov)


def averaged_split_sum(nov, ax, ay, nbeta=96, order=12, levels=12, model="microfacet"):
    """(scale, bias) of the view-azimuth-averaged table at n.v = nov (module docstring); ``model``:
    "microfacet" (anisotropic GGX) or "ashikhmin_shirley" (its kink at n.l = n.v is a grading point of the l
    rule: theta_l = theta_v)."""
    sv = np.sqrt(1.0 - nov * nov)
    t, wt = graded_gauss_legendre(0.0, np.pi / 2, [np.arccos(nov), np.pi / 2], levels=levels, order=order)
    p, wp_ = graded_gauss_legendre(0.0, 2 * np.pi, [np.pi], levels=levels, order=order)
    T, P = np.meshgrid(t, p, indexing="ij")
    W = np.outer(wt, wp_) * np.sin(T)
    l = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1)
    v = np.array([sv, 0.0, nov])
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    fc = (1.0 - h @ v) ** 5
    out = np.zeros(2)
    for b in np.arange(nbeta) * np.pi / nbeta:
        c, s = np.cos(b), np.sin(b)
        r = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # into the frame rotated by beta
        hr, lr, vr = h @ r.T, l @ r.T, r @ v
        if model == "microfacet":
            d = (hr[..., 0] / ax) ** 2 + (hr[..., 1] / ay) ** 2 + hr[..., 2] ** 2
            g2 = 1.0 + lambda_aniso(vr, ax, ay) + lambda_aniso(lr, ax, ay)
            f_cos = 1.0 / (np.pi * ax * ay * d * d) / g2 / (4 * nov)
        else:
            f_cos = ashikhmin_shirley_f_cos(hr, lr, nov, ax, ay) / (4.0 * (hr @ vr))
        out += [np.sum(W * f_cos * (1.0 - fc)), np.sum(W * f_cos * fc)]
    return out / nbeta
