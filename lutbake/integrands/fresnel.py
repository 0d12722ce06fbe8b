"""The Fresnel terms by name, evaluated on the host through one Warp kernel, and their hemispherical
averages F_avg (Kulla & Conty 2017, "Revisiting physically based shading at Imageworks", slide 18):

    F_avg = 2 ∫_0^1 F(mu) mu dmu          (mu = cos theta; the cosine-weighted mean over the hemisphere)

For Schlick it is closed form, F_avg = f0 + (1 - f0)/21 = (20 f0 + 1)/21. Kulla-Conty's multiple-scattering
Fresnel uses it: F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)).
"""

from __future__ import annotations

import numpy as np
import warp as wp

from ..metals import LAZANYI_ALPHA
from ..records import FRESNEL
from ..runtime.warp_runtime import kernel_factory, unique_kernel
from ..sampling.arrays import Floats


@kernel_factory
def _kernel(fresnel):
    """out[i] = F(c[i]) of a Fresnel record, reading f0 (param "f0"), n and k ("nk") or n, k and Lazanyi's a ("nka")."""
    F, param = fresnel["F"], fresnel.fields["param"]

    @unique_kernel
    def eval_fresnel(f0: Floats, n: Floats, k: Floats, a: Floats, c: Floats, out: wp.array(dtype=float)):
        i = wp.tid()
        if wp.static(param == "f0"):
            out[i] = F(f0[i], c[i])
        elif wp.static(param == "nk"):
            out[i] = F(n[i], k[i], c[i])
        else:
            out[i] = F(n[i], k[i], a[i], wp.static(LAZANYI_ALPHA), c[i])

    return eval_fresnel


def evaluate(c, f0=0.04, n=1.5, k=0.0, a=0.0, fresnels=None) -> dict[str, np.ndarray]:
    """Fresnel terms at cosines ``c`` (broadcast with f0, n, k, a): name -> float64 array, for the records
    ``fresnels`` (default: every Fresnel record). Terms of f0 read f0; conductor and lazanyi read n, k (and a)."""
    arrs = np.broadcast_arrays(*(np.asarray(x, dtype=np.float32) for x in (f0, n, k, a, c)))
    shape = arrs[0].shape
    ins = [wp.array(np.ascontiguousarray(x.ravel()), dtype=float, device="cpu") for x in arrs]
    values = {}
    for fresnel in FRESNEL if fresnels is None else fresnels:
        out = wp.zeros(arrs[0].size, dtype=float, device="cpu")
        wp.launch(_kernel(fresnel), dim=arrs[0].size, inputs=ins + [out], device="cpu")
        values[fresnel.name] = out.numpy().astype(np.float64).reshape(shape)
    return values


def mu_nodes(order: int = 48) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights for ∫_0^1 dmu, in two panels split at mu = 0.2
    (the Fresnel curves vary fastest near grazing)."""
    x, w = np.polynomial.legendre.leggauss(order)
    nodes, weights = [], []
    for lo, hi in ((0.0, 0.2), (0.2, 1.0)):
        nodes.append(lo + (hi - lo) * (x + 1) / 2)
        weights.append(w * (hi - lo) / 2)
    return np.concatenate(nodes), np.concatenate(weights)


def f_avg(fresnel, f0=0.04, n=1.5, k=0.0, a=0.0, order: int = 48) -> float:
    """F_avg = 2 ∫_0^1 F(mu) mu dmu of a Fresnel record (or the name of one of lutbake's), by Gauss-Legendre in
    mu."""
    fresnel = FRESNEL.lookup(fresnel) if isinstance(fresnel, str) else fresnel
    mu, w = mu_nodes(order)
    F = evaluate(mu, f0, n, k, a, [fresnel])[fresnel.name]
    return float(2.0 * np.sum(w * F * mu))
