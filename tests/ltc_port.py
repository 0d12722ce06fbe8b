"""A straight numpy port of selfshadow/ltc_code fit/fitLTC.cpp for GGX (BrdfGGX, LTC, computeAvgTerms,
computeError, NelderMead, fitTab's chained loop), float64, the sample loops vectorised over the N x N grid.

Used by the tests as an independent implementation of Heitz's error metric and by `make bench` as the
single-threaded baseline of the fit (benchmarks/bench_ltc.py). Nothing here imports lutbake.ltc.fit.
"""

from __future__ import annotations

import numpy as np

PI = np.pi


def grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    u = (np.arange(n) + 0.5) / n
    u1, u2 = np.meshgrid(u, u)  # U1 = (i + 0.5)/N fastest
    return u1.ravel(), u2.ravel()


def ggx_lambda(alpha, c):
    c = np.asarray(c, np.float64)
    out = np.zeros_like(c)
    ok = (c < 1.0) & (c > 0.0)
    a = 1.0 / alpha / np.tan(np.arccos(c[ok]))
    out[ok] = 0.5 * (-1.0 + np.sqrt(1.0 + 1.0 / (a * a)))
    return out


def ggx_eval(v, l, alpha):
    """BrdfGGX::eval -> (f (n.l), pdf) for rows of l."""
    lam_v = ggx_lambda(alpha, np.array([v[2]]))[0]
    lz = l[:, 2]
    g2 = np.where(lz > 0, 1.0 / (1.0 + lam_v + ggx_lambda(alpha, np.maximum(lz, 1e-300))), 0.0)
    h = v + l
    h = h / np.linalg.norm(h, axis=1, keepdims=True)
    sx, sy = h[:, 0] / h[:, 2], h[:, 1] / h[:, 2]
    d = 1.0 / (1.0 + (sx * sx + sy * sy) / alpha / alpha)
    d = d * d / (PI * alpha * alpha * h[:, 2] ** 4)
    pdf = np.abs(d * h[:, 2] / 4.0 / (h @ v))
    return d * g2 / 4.0 / v[2], pdf


def ggx_sample(v, alpha, u1, u2):
    phi = 2.0 * PI * u1
    r = alpha * np.sqrt(u2 / (1.0 - u2))
    n = np.stack([r * np.cos(phi), r * np.sin(phi), np.ones_like(r)], axis=1)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return -v + 2.0 * n * (n @ v)[:, None]


def ltc_matrix(x, y, z, m11, m22, m13):
    return np.column_stack([x, y, z]) @ np.array([[m11, 0, m13], [0, m22, 0], [0, 0, 1.0]])


def ltc_eval(m, magnitude, l):
    """LTC::eval for rows of l."""
    inv = np.linalg.inv(m)
    lo = l @ inv.T
    lo /= np.linalg.norm(lo, axis=1, keepdims=True)
    l_ = lo @ m.T
    ln = np.linalg.norm(l_, axis=1)
    jac = abs(np.linalg.det(m)) / ln**3
    d = np.maximum(0.0, lo[:, 2]) / PI
    return magnitude * d / jac


def ltc_sample(m, u1, u2):
    theta = np.arccos(np.sqrt(u1))
    phi = 2.0 * PI * u2
    d = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=1) @ m.T
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def compute_error(m, magnitude, v, alpha, n=32):
    """computeError: MIS estimate of ∫ |f - ltc|^3 over the LTC's and the BRDF's N x N samples."""
    u1, u2 = grid(n)
    err = 0.0
    for l in (ltc_sample(m, u1, u2), ggx_sample(v, alpha, u1, u2)):
        fb, pb = ggx_eval(v, l, alpha)
        fl = ltc_eval(m, magnitude, l)
        pl = fl / magnitude
        e = np.abs(fb - fl) ** 3
        q = pl + pb
        err += np.sum(np.where(q > 0, e / np.where(q > 0, q, 1.0), 0.0))
    return err / (n * n)


def avg_terms(v, alpha, n=32):
    """computeAvgTerms: (norm, fresnel, average direction)."""
    u1, u2 = grid(n)
    l = ggx_sample(v, alpha, u1, u2)
    f, pdf = ggx_eval(v, l, alpha)
    w = np.where(pdf > 0, f / np.where(pdf > 0, pdf, 1.0), 0.0)
    h = v + l
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    norm = w.sum() / (n * n)
    fres = np.sum(w * (1.0 - np.maximum(h @ v, 0.0)) ** 5) / (n * n)
    avg = (w[:, None] * l).sum(axis=0)
    avg[1] = 0.0
    return norm, fres, avg / np.linalg.norm(avg)


def nelder_mead(fn, start, delta, tol=1e-5, iters=100):
    """nelder_mead.h, scalar."""
    dim = len(start)
    s = np.array([start] + [np.array(start) + delta * np.eye(dim)[i] for i in range(dim)], dtype=np.float64)
    f = np.array([fn(p) for p in s])
    lo = 0
    for _ in range(iters):
        lo = hi = nh = 0
        for i in range(1, dim + 1):
            if f[i] < f[lo]:
                lo = i
            if f[i] > f[hi]:
                nh, hi = hi, i
            elif f[i] > f[nh]:
                nh = i
        a, b = abs(f[lo]), abs(f[hi])
        if 2.0 * abs(a - b) < (a + b) * tol:
            break
        o = (s.sum(axis=0) - s[hi]) / dim
        r = o + (o - s[hi])
        fr = fn(r)
        if fr < f[nh]:
            if fr < f[lo]:
                e = o + 2.0 * (o - s[hi])
                fe = fn(e)
                if fe < fr:
                    s[hi], f[hi] = e, fe
                    continue
            s[hi], f[hi] = r, fr
            continue
        c = o - 0.5 * (o - s[hi])
        fc = fn(c)
        if fc < f[hi]:
            s[hi], f[hi] = c, fc
            continue
        for k in range(dim + 1):
            if k != lo:
                s[k] = s[lo] + 0.5 * (s[k] - s[lo])
                f[k] = fn(s[k])
    return s[lo], f[lo]


def fit_tab(n_tab: int = 64, texels=None, n: int = 32, min_alpha: float = 1e-5):
    """fitTab's loop (a from N - 1 down, t from 0 up, each texel seeded by the previous one), for the texels
    listed (default all, in fitTab's order; a subset still follows fitTab's order and chains within the subset).
    Returns {(t, a): (M, norm, error)}."""
    out = {}
    order = [(a, t) for a in range(n_tab - 1, -1, -1) for t in range(n_tab)]
    want = None if texels is None else set(texels)
    m11, m22, m13 = 1.0, 1.0, 0.0
    x, y, z = np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0])
    for a, t in order:
        if want is not None and (t, a) not in want:
            continue
        xx = t / (n_tab - 1)
        theta = min(1.57, np.arccos(1.0 - xx * xx))
        v = np.array([np.sin(theta), 0.0, np.cos(theta)])
        alpha = max((a / (n_tab - 1)) ** 2, min_alpha)
        norm, _, avg = avg_terms(v, alpha, n)
        iso = t == 0
        if iso:
            x, y, z = np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0])
            prev = out.get((t, a + 1))
            m11 = m22 = 1.0 if prev is None else prev[0][0, 0]
            m13 = 0.0
        else:
            z = avg
            x, y = np.array([z[2], 0.0, -z[0]]), np.array([0, 1.0, 0])

        def fn(p, x=x, y=y, z=z, iso=iso):
            a11, a22 = max(p[0], 1e-7), max(p[1], 1e-7)
            if iso:
                a22, a13 = a11, 0.0
            else:
                a13 = p[2]
            return compute_error(ltc_matrix(x, y, z, a11, a22, a13), norm, v, alpha, n)

        p, err = nelder_mead(fn, [m11, m22, m13], 0.05)
        m11, m22 = max(p[0], 1e-7), max(p[1], 1e-7)
        m13 = 0.0 if iso else p[2]
        if iso:
            m22 = m11
        out[(t, a)] = (ltc_matrix(x, y, z, m11, m22, m13), norm, err)
    return out
