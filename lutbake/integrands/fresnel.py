"""The Fresnel terms by name, evaluated on the host through one Warp kernel, and their hemispherical
averages F_avg (Kulla & Conty 2017, "Revisiting physically based shading at Imageworks", slide 18):

    F_avg = 2 ∫_0^1 F(mu) mu dmu          (mu = cos theta; the cosine-weighted mean over the hemisphere)

For Schlick it is closed form, F_avg = f0 + (1 - f0)/21 = (20 f0 + 1)/21. Kulla-Conty's multiple-scattering
Fresnel uses it: F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)).
"""

from __future__ import annotations

import functools

import numpy as np
import warp as wp

from ..catalog import FRESNELS
from ..metals import LAZANYI_ALPHA
from ..runtime.warp_runtime import unique_kernel
from ..sampling.arrays import Floats
from ..terms import fresnel as fr

COLUMNS = tuple(FRESNELS)


@functools.lru_cache(maxsize=None)
def _kernel():
    @unique_kernel
    def eval_fresnel(f0: Floats, n: Floats, k: Floats, a: Floats, c: Floats, out: wp.array2d(dtype=float)):
        i = wp.tid()
        out[i, 0] = fr.F_schlick(f0[i], c[i])
        out[i, 1] = fr.F_schlick_sg(f0[i], c[i])
        out[i, 2] = fr.F_improved_sg(f0[i], c[i])
        out[i, 3] = fr.F_dielectric_f0(f0[i], c[i])
        out[i, 4] = fr.F_conductor(n[i], k[i], c[i])
        out[i, 5] = fr.F_lazanyi(n[i], k[i], a[i], wp.static(LAZANYI_ALPHA), c[i])

    return eval_fresnel


def evaluate(c, f0=0.04, n=1.5, k=0.0, a=0.0) -> dict[str, np.ndarray]:
    """Every Fresnel term at cosines ``c`` (broadcast with f0, n, k, a): name -> float64 array.
    schlick*, improved_sg and dielectric_f0 read f0; conductor and lazanyi read n, k (and a)."""
    arrs = np.broadcast_arrays(*(np.asarray(x, dtype=np.float32) for x in (f0, n, k, a, c)))
    shape = arrs[0].shape
    ins = [wp.array(np.ascontiguousarray(x.ravel()), dtype=float, device="cpu") for x in arrs]
    out = wp.zeros((arrs[0].size, len(COLUMNS)), dtype=float, device="cpu")
    wp.launch(_kernel(), dim=arrs[0].size, inputs=ins + [out], device="cpu")
    o = out.numpy().astype(np.float64)
    return {name: o[:, j].reshape(shape) for j, name in enumerate(COLUMNS)}


def mu_nodes(order: int = 48) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights for ∫_0^1 dmu, in two panels split at mu = 0.2
    (the Fresnel curves vary fastest near grazing)."""
    x, w = np.polynomial.legendre.leggauss(order)
    nodes, weights = [], []
    for lo, hi in ((0.0, 0.2), (0.2, 1.0)):
        nodes.append(lo + (hi - lo) * (x + 1) / 2)
        weights.append(w * (hi - lo) / 2)
    return np.concatenate(nodes), np.concatenate(weights)


def f_avg(name: str, f0=0.04, n=1.5, k=0.0, a=0.0, order: int = 48) -> float:
    """F_avg = 2 ∫_0^1 F(mu) mu dmu of the term ``name`` (FRESNELS), by Gauss-Legendre in mu."""
    if name not in FRESNELS:
        raise KeyError(f"unknown Fresnel term {name!r}; valid: {', '.join(FRESNELS)}")
    mu, w = mu_nodes(order)
    F = evaluate(mu, f0, n, k, a)[name]
    return float(2.0 * np.sum(w * F * mu))
