"""numpy reference of the view-azimuth-averaged anisotropic GGX split sum (independent of lutbake's @wp.funcs and of
its panelled rule): E = (1/pi) ∫_0^pi dbeta ∫ f(l, v) (n.l) dω_l, f = D G2 / (4 (n.l)(n.v)), anisotropic GGX
(Heitz 2014, Eq. 85) with alpha_x along the tangent frame's T, rotated by beta about n, height-correlated Smith G2 with
the anisotropic Lambda (Eq. 86), Schlick's split-sum channels (1 - Fc, Fc), Fc = (1 - v.h)^5. The l integral is a
product Gauss-Legendre rule in (theta_l, phi_l) graded toward the mirror direction (theta_v, pi) and the horizon
(tests/conftest.py graded_gauss_legendre); beta by the periodic trapezoid rule. At nbeta = 160, order 16, levels 14
it agrees with nbeta = 256, order 20, levels 16 to 1e-15 at (n.v, alpha_x, alpha_y) = (0.02, 0.3, 0.03),
(0.5, 1.0, 0.1), (0.9, 0.05, 0.005), (0.2, 0.3, 0.2); ~2 s a texel."""

import numpy as np
from conftest import graded_gauss_legendre


def lambda_aniso(w, ax, ay):
    return 0.5 * (np.sqrt(w[..., 2] ** 2 + ax * ax * w[..., 0] ** 2 + ay * ay * w[..., 1] ** 2) / w[..., 2] - 1.0)


def averaged_split_sum(nov, ax, ay, nbeta=160, order=16, levels=14):
    """(scale, bias) of the view-azimuth-averaged table at n.v = nov (module docstring)."""
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
        d = (hr[..., 0] / ax) ** 2 + (hr[..., 1] / ay) ** 2 + hr[..., 2] ** 2
        f_cos = (
            1.0 / (np.pi * ax * ay * d * d) / (1.0 + lambda_aniso(vr, ax, ay) + lambda_aniso(lr, ax, ay)) / (4 * nov)
        )
        out += [np.sum(W * f_cos * (1.0 - fc)), np.sum(W * f_cos * fc)]
    return out / nbeta
