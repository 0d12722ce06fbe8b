"""Deterministic point sets on [0, 1) and [0, 1)^2, computed in float64 on the host."""

from __future__ import annotations

import functools

import numpy as np


@functools.lru_cache(maxsize=64)
def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss-Legendre rule mapped to [0, 1]: nodes x_i, weights w_i with sum w_i = 1.
    Exact for polynomials of degree 2n - 1 (numpy.polynomial.legendre.leggauss)."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


@functools.lru_cache(maxsize=16)
def gauss_kronrod(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The (n, 2n + 1) Gauss-Kronrod pair mapped to [0, 1]: the 2n + 1 nodes x_i (ascending), the Kronrod weights
    (exact to degree 3n + 1) and the n-point Gauss-Legendre weights at its own nodes (0 at the n + 1 Kronrod
    nodes): Kronrod, "Nodes and weights of quadrature formulas" (1965). The added nodes are the roots of the
    Stieltjes polynomial E_(n+1), orthogonal to every polynomial of degree <= n under the weight P_n (its Legendre
    coefficients from those n + 1 conditions, integrated exactly by leggauss(2n + 4)); the weights solve the
    moment equations in the Legendre basis. n = 7 reproduces QUADPACK's dqk15 (Piessens et al. 1983) to rounding
    (tests/test_gauss_legendre_rules.py)."""
    leg = np.polynomial.legendre
    xg, wg = leg.leggauss(n)
    xq, wq = leg.leggauss(2 * n + 4)
    v = leg.legvander(xq, n + 1)
    a = (v[:, : n + 1] * (wq * leg.legval(xq, [0.0] * n + [1.0]))[:, None]).T @ v  # a[j, k] = ∫ P_j P_n P_k
    e = np.append(np.linalg.solve(a[:, : n + 1], -a[:, n + 1]), 1.0)
    x = np.sort(np.concatenate([xg, leg.legroots(e).real]))
    moments = np.zeros(2 * n + 1)
    moments[0] = 2.0
    wk = np.linalg.solve(leg.legvander(x, 2 * n).T, moments)
    g = np.zeros(2 * n + 1)
    g[np.searchsorted(x, xg - 1e-12)] = wg
    return 0.5 * (x + 1.0), 0.5 * wk, 0.5 * g


@functools.lru_cache(maxsize=64)
def sobol(n: int, seed: int) -> np.ndarray:
    """n points of the 2D Sobol' sequence with Owen scrambling (scipy.stats.qmc), seeded:
    deterministic for a given (n, seed). n is rounded up to a power of two (balance properties)."""
    from scipy.stats import qmc

    m = max(0, int(np.ceil(np.log2(max(n, 1)))))
    return qmc.Sobol(d=2, scramble=True, rng=np.random.default_rng(seed)).random_base2(m)


@functools.lru_cache(maxsize=64)
def hammersley(n: int) -> np.ndarray:
    """The 2D Hammersley set (i/n, radical inverse base 2 of i), as Filament's cmgen uses."""
    i = np.arange(n, dtype=np.uint64)
    bits = np.zeros(n, dtype=np.float64)
    scale, k = 0.5, i.copy()
    while np.any(k):
        bits += (k & 1).astype(np.float64) * scale
        k >>= np.uint64(1)
        scale *= 0.5
    return np.stack([i.astype(np.float64) / n, bits], axis=1)


@functools.lru_cache(maxsize=64)
def sobol3(n: int, seed: int) -> np.ndarray:
    """n points of the 3D Owen-scrambled Sobol' sequence (as ``sobol``, d = 3; n rounded up to a power of two)."""
    from scipy.stats import qmc

    m = max(0, int(np.ceil(np.log2(max(n, 1)))))
    return qmc.Sobol(d=3, scramble=True, rng=np.random.default_rng(seed)).random_base2(m)
