"""A straight numpy port of tizian/ltc-sheen fitting/src/bsdfs/sheen_approx.h (ApproxSheenBrdf::eval_impl) and the
parts of fitting/src/sggx.h it calls (Ellipsoid::from_fiber, ndf, sigma, eval_phase_specular), float64, vectorised
over directions: Zeltner, Burley & Chiang 2022's analytic volumetric sheen, f (n.wo). The general SGGX ellipsoid is
kept (not specialised to the z fiber), as the C++ has it. Nothing here imports lutbake.
"""

from __future__ import annotations

import numpy as np


def from_fiber(t, sigma):
    """sggx::Ellipsoid::from_fiber -> (xx, yy, zz, xy, xz, yz)."""
    x, y, z = t
    s2 = sigma * sigma
    return (
        s2 * x * x + y * y + z * z,
        s2 * y * y + x * x + z * z,
        s2 * z * z + x * x + y * y,
        s2 * x * y - x * y,
        s2 * x * z - x * z,
        s2 * y * z - y * z,
    )


def sggx_ndf(wm, S):
    xx, yy, zz, xy, xz, yz = S
    det = xx * yy * zz - xx * yz * yz - yy * xz * xz - zz * xy * xy + 2.0 * xy * xz * yz
    x, y, z = wm[..., 0], wm[..., 1], wm[..., 2]
    den = (
        x * x * (yy * zz - yz * yz)
        + y * y * (xx * zz - xz * xz)
        + z * z * (xx * yy - xy * xy)
        + 2.0 * (x * y * (xz * yz - zz * xy) + x * z * (xy * yz - yy * xz) + y * z * (xy * xz - xx * yz))
    )
    return np.abs(det) ** 1.5 / (np.pi * den * den)


def sggx_sigma(w, S):
    xx, yy, zz, xy, xz, yz = S
    x, y, z = w[..., 0], w[..., 1], w[..., 2]
    s2 = x * x * xx + y * y * yy + z * z * zz + 2.0 * (x * y * xy + x * z * xz + y * z * yz)
    return np.sqrt(np.maximum(0.0, s2))


def phase_specular(wi, wo, S):
    wh = wi + wo
    wh = wh / np.linalg.norm(wh, axis=-1, keepdims=True)
    s = sggx_sigma(wi, S)
    return np.where(s == 0.0, 0.0, 0.25 * sggx_ndf(wh, S) / np.where(s == 0.0, 1.0, s))


M_VALS = [2.0 * 20.0 - 10.2, 20.0, 10.2, 6.14, 4.30, 3.30, 2.55, 2.02, 1.63, 1.33, 1.1, 0.95, 2.0 * 0.95 - 1.1]
B_VALS = [2.0 * 3.7 - 2.23, 3.7, 2.23, 1.06, 0.293, -0.212, -0.641, -0.952, -1.2, -1.4, -1.55, -1.65]
B_VALS.append(2.0 * -1.65 + 1.55)


def mb(sigma):
    r = sigma * 10.0
    ri = int(min(np.floor(r), 9.0))
    y = r - ri
    y2, y3 = y * y, y * y * y
    w = [-y + 2.0 * y2 - y3, 2.0 - 5.0 * y2 + 3.0 * y3, y + 4.0 * y2 - 3.0 * y3, -y2 + y3]
    m = 0.5 * sum(w[k] * M_VALS[ri + k] for k in range(4))
    b = 0.5 * sum(w[k] * B_VALS[ri + k] for k in range(4))
    return m, b


def Ft(sigma, c):
    b = max(0.55, 0.44 + 0.42 * sigma)
    return b + (1 - b) * (1 - (1 - c) ** 12.0)


def eval_approx(wi, wo, alpha):
    """ApproxSheenBrdf(alpha).eval_impl(wi, wo) for one wi (3,) and rows wo (n, 3): f (n.wo)."""
    wi = np.asarray(wi, np.float64)
    wo = np.atleast_2d(np.asarray(wo, np.float64))
    ci, co = wi[2], wo[:, 2]
    sigma = alpha * alpha
    S = from_fiber((0.0, 0.0, 1.0), sigma)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        lam_i = sggx_sigma(wi, S) / ci
        lam_o = sggx_sigma(wo, S) / co
        tmp0 = lam_i + lam_o
        tmp = (1.0 - np.exp(-tmp0)) / (abs(ci) * tmp0)
        value = phase_specular(np.broadcast_to(wi, wo.shape), wo, S) * sggx_sigma(wi, S) * tmp
    m, b = mb(sigma)
    ms = np.exp(b - m * np.sqrt(co * co + ci * ci)) * Ft(sigma, co) * Ft(sigma, ci)
    out = np.where(np.isfinite(value), value + ms * co, 0.0)
    return np.where((ci <= 0.0) | (co < 0.0), 0.0, out)


def albedo(mu, alpha, n=256):
    """∫ f (n.wo) dω_o by a product midpoint rule in (theta_o, phi_o) (phi over [0, pi], doubled: the lobe is
    symmetric about the plane of wi), cos theta_o graded towards the horizon where the lobe peaks."""
    t = (np.arange(n) + 0.5) / n
    theta = 0.5 * np.pi * (1.0 - (1.0 - t) ** 2)  # graded: denser near the horizon
    dtheta = 0.5 * np.pi * 2.0 * (1.0 - t) / n
    phi = (np.arange(n) + 0.5) / n * np.pi
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    wo = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1).reshape(-1, 3)
    wi = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])
    f = eval_approx(wi, wo, alpha).reshape(n, n)
    return 2.0 * np.sum(f * np.sin(th) * dtheta[:, None]) * (np.pi / n)
