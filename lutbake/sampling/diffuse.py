"""Quadratures of the diffuse tables over the light direction l, for a diffuse BRDF ``brdf(l, v, sigma, alpha, f0,
xg, wg) -> float64`` (lutbake.integrands.diffuse; xg, wg: the GL rule of the microfacet model's inner m-integral).

AmbientBRDF (directional reflectance under uniform white light, rho = 1):
    E(v) = ∫ f(l, v) (n.l) dω_l = 2 ∫_0^pi dphi_l ∫_0^1 d(n.l) f (n.l)       (f is even in phi_l)
- ``gauss_legendre`` (``DiffuseGaussLegendre``): n-point GL on 2 x 2 panels: n.l split at n.v (the max(n.l, n.v)
  kink of Oren-Nayar) and phi_l at pi/2 (s = l.v - (n.l)(n.v) changes sign there: the branches of Eq. 5, 7, 8 and
  the max(0, cos phi) of Oren-Nayar); 4 n^2 directions l.
- ``sobol_cosine`` (``CosineSobol``): scrambled 2D Sobol' points, l cosine-weighted (pdf (n.l) / pi, Malley's
  method), E = (pi / N) sum f(l_k, v): an independent check of the rule above.
- ``PointEvaluation``: no integral over l: f(l_i, v_i) at given direction pairs (kind btf), the microfacet model
  at a per-texel inner order; ``PointSobol``: the same with the microfacet model's m-integral by Sobol' points
  (lutbake.sampling.facets.fd_microfacet_sobol_for), a cross-check.
The microfacet model's albedo by default uses the swapped integral (lutbake.sampling.swapped).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import warp as wp

from ..terms.frame import view_dir
from . import points
from .facets import fd_microfacet_sobol_for

PI64 = wp.constant(wp.float64(math.pi))
REFINE_ORDER = 8  # the error estimates re-evaluate probe texels with every GL order + 8


@functools.lru_cache(maxsize=None)
def albedo_kernel(brdf):
    """Kernel: E(v) = ∫ f (n.l) dω_l per texel (nov[i], sigma[i], alpha[i], f0[i]); outer GL (xo, wo) on 2 x 2
    panels, inner GL (xg, wg) for the microfacet integral (``brdf``: lutbake.integrands.diffuse)."""

    @wp.kernel(enable_backward=False, module="unique")
    def albedo_gl_kernel(nov: wp.array(dtype=float), sigma: wp.array(dtype=float), alpha: wp.array(dtype=float),
                         f0: wp.array(dtype=float), xo: wp.array(dtype=wp.float64), wo: wp.array(dtype=wp.float64),
                      xg: wp.array(dtype=wp.float64), wg: wp.array(dtype=wp.float64),
                      out: wp.array2d(dtype=wp.float64)):
        i = wp.tid()
        v = view_dir(nov[i])
        cv = wp.float64(v[2])
        half_pi = PI64 * wp.float64(0.5)
        acc = wp.float64(0.0)
        for pm in range(2):
            mlo = wp.float64(0.0)
            mhi = cv
            if pm == 1:
                mlo = cv
                mhi = wp.float64(1.0)
            for pp in range(2):
                plo = half_pi * wp.float64(pp)
                for a in range(xo.shape[0]):
                    mu = mlo + (mhi - mlo) * xo[a]
                    st = wp.sqrt(wp.max(wp.float64(1.0) - mu * mu, wp.float64(0.0)))
                    for b in range(xo.shape[0]):
                        phi = plo + half_pi * xo[b]
                        l = wp.vec3(float(st * wp.cos(phi)), float(st * wp.sin(phi)), float(mu))
                        f = brdf(l, v, sigma[i], alpha[i], f0[i], xg, wg)
                        acc = acc + wo[a] * wo[b] * (mhi - mlo) * half_pi * f * mu
        out[i, 0] = wp.float64(2.0) * acc

    return albedo_gl_kernel


@functools.lru_cache(maxsize=None)
def brdf_kernel(brdf):
    """Kernel: f(l[i], v[i]) for given direction pairs (tests, plots, BTF slices)."""

    @wp.kernel(enable_backward=False, module="unique")
    def brdf_point_kernel(l: wp.array(dtype=wp.vec3), v: wp.array(dtype=wp.vec3), sigma: wp.array(dtype=float),
                          alpha: wp.array(dtype=float), f0: float, xg: wp.array(dtype=wp.float64),
                          wg: wp.array(dtype=wp.float64), out: wp.array(dtype=wp.float64)):
        i = wp.tid()
        out[i] = brdf(l[i], v[i], sigma[i], alpha[i], f0, xg, wg)

    return brdf_point_kernel


@functools.lru_cache(maxsize=None)
def cosine_kernel(brdf):
    """Kernel: E(v) = (pi / N) sum_k f(l_k, v), l_k cosine-weighted from the 2D points ``pts``."""

    @wp.kernel(enable_backward=False, module="unique")
    def albedo_cosine_kernel(nov: wp.array(dtype=float), sigma: wp.array(dtype=float), alpha: wp.array(dtype=float),
                             f0: wp.array(dtype=float), pts: wp.array2d(dtype=float), xg: wp.array(dtype=wp.float64),
                             wg: wp.array(dtype=wp.float64), out: wp.array2d(dtype=wp.float64)):
        i = wp.tid()
        v = view_dir(nov[i])
        acc = wp.float64(0.0)
        n = pts.shape[0]
        for k in range(n):
            r2 = pts[k, 0]
            phi = 2.0 * wp.pi * pts[k, 1]
            st = wp.sqrt(r2)
            l = wp.vec3(st * wp.cos(phi), st * wp.sin(phi), wp.sqrt(wp.max(1.0 - r2, 0.0)))
            acc = acc + brdf(l, v, sigma[i], alpha[i], f0[i], xg, wg)
        out[i, 0] = PI64 * acc / wp.float64(n)

    return albedo_cosine_kernel


def gl_arrays(n: int, device: str) -> list:
    """The n-point GL rule on [0, 1] as two float64 Warp arrays (nodes, weights)."""
    x, w = points.gauss_legendre(n)
    return [wp.array(x, dtype=wp.float64, device=device), wp.array(w, dtype=wp.float64, device=device)]


def _texel_arrays(inputs: dict, device: str) -> list:
    return [wp.array(np.ascontiguousarray(inputs[k], dtype=np.float32), dtype=float, device=device)
            for k in ("nov", "sigma", "alpha", "f0")]


@dataclass(frozen=True)
class DiffuseGaussLegendre:
    """E(v) by GL over l on 2 x 2 panels (module docstring): ``order`` per panel and dimension (``outer_order``
    if given), the microfacet model's inner m-rule at ``order``. Inputs: nov, sigma, alpha, f0."""

    order: int
    outer_order: int | None = None
    name: str = "gauss_legendre"

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["nov"]), 4 * (self.outer_order or self.order) ** 2)

    def prepare(self, integrand, device: str) -> None:
        wp.load_module(albedo_kernel(integrand.brdf).module, device=device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        out = wp.zeros((len(inputs["nov"]), 1), dtype=wp.float64, device=device)
        wp.launch(albedo_kernel(integrand.brdf), dim=len(inputs["nov"]),
                  inputs=[*_texel_arrays(inputs, device), *gl_arrays(self.outer_order or self.order, device),
                          *gl_arrays(self.order, device), out], device=device)
        return out.numpy()

    def refined(self):
        return DiffuseGaussLegendre(self.order + REFINE_ORDER), f"order {self.order} - order {self.order + REFINE_ORDER}"


@dataclass(frozen=True)
class CosineSobol:
    """E(v) by scrambled Sobol' points, l cosine-weighted (module docstring); the microfacet model's inner m-rule
    at ``inner_order``. Inputs: nov, sigma, alpha, f0."""

    budget: int
    seed: int = 0
    inner_order: int = 12
    name: str = "sobol_cosine"

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["nov"]), len(points.sobol(self.budget, self.seed)))

    def prepare(self, integrand, device: str) -> None:
        wp.load_module(cosine_kernel(integrand.brdf).module, device=device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        pts = np.clip(points.sobol(self.budget, self.seed), 0.0, np.nextafter(np.float32(1.0), np.float32(0.0)))
        out = wp.zeros((len(inputs["nov"]), 1), dtype=wp.float64, device=device)
        wp.launch(cosine_kernel(integrand.brdf), dim=len(inputs["nov"]),
                  inputs=[*_texel_arrays(inputs, device), wp.array(pts.astype(np.float32), dtype=float, device=device),
                          *gl_arrays(self.inner_order, device), out], device=device)
        return out.numpy()

    def refined(self):
        return CosineSobol(self.budget, self.seed + 1, self.inner_order), "seed - (seed + 1) (two scramblings)"


def eval_points(integrand, l: np.ndarray, v: np.ndarray, sigma, alpha, f0: float, order: int,
                device: str = "cpu") -> np.ndarray:
    """f(l_i, v_i) for unit direction arrays (N, 3) (n = +z), rho = 1, inner m-rule of ``order``; float64 (N,)."""
    l = np.ascontiguousarray(l, dtype=np.float32).reshape(-1, 3)
    v = np.ascontiguousarray(v, dtype=np.float32).reshape(-1, 3)
    n = len(l)
    s = np.ascontiguousarray(np.broadcast_to(np.asarray(sigma, dtype=np.float32), (n,)))
    a = np.ascontiguousarray(np.broadcast_to(np.asarray(alpha, dtype=np.float32), (n,)))
    out = wp.zeros(n, dtype=wp.float64, device=device)
    wp.launch(brdf_kernel(integrand.brdf), dim=n,
              inputs=[wp.array(l, dtype=wp.vec3, device=device), wp.array(v, dtype=wp.vec3, device=device),
                      wp.array(s, dtype=float, device=device), wp.array(a, dtype=float, device=device), float(f0),
                      *gl_arrays(order, device), out], device=device)
    return out.numpy()


@dataclass(frozen=True)
class PointEvaluation:
    """f(l_i, v_i) per texel (kind btf): inputs l, v (N, 3), sigma, alpha, order (the inner m-rule per texel, plus
    ``extra``); ``f0`` is the table's single f0. ``name``: gauss_legendre (microfacet) or closed_form."""

    f0: float
    extra: int = 0
    name: str = "gauss_legendre"
    evaluations: float = 1.0  # nominal evaluations per texel, for the record

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["order"]), self.evaluations)

    def prepare(self, integrand, device: str) -> None:
        wp.load_module(brdf_kernel(integrand.brdf).module, device=device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        out = np.empty((len(inputs["order"]), 1))
        for n in np.unique(inputs["order"]):
            sel = inputs["order"] == n
            out[sel, 0] = eval_points(integrand, inputs["l"][sel], inputs["v"][sel], inputs["sigma"][sel],
                                      inputs["alpha"][sel], self.f0, int(n) + self.extra, device)
        return out

    def refined(self):
        e = self.extra + REFINE_ORDER
        return PointEvaluation(self.f0, e, self.name, self.evaluations), f"orders - orders + {e}"


@functools.lru_cache(maxsize=None)
def sobol_point_kernel(facet):
    """Kernel: the microfacet f(l[i], v[i]) with its m-integral by the 2D points ``pts`` (``PointSobol``)."""
    f = fd_microfacet_sobol_for(facet)

    @wp.kernel(enable_backward=False, module="unique")
    def brdf_sobol_kernel(lv: wp.array2d(dtype=wp.vec3), alpha: wp.array(dtype=float), f0: float,
                          pts: wp.array2d(dtype=float), out: wp.array(dtype=wp.float64)):
        i = wp.tid()
        out[i] = f(lv[i, 0], lv[i, 1], alpha[i], f0, pts)

    return brdf_sobol_kernel


@dataclass(frozen=True)
class PointSobol:
    """The microfacet model's f(l_i, v_i) (kind btf) with Eq. 4's m-integral by ``budget`` scrambled Sobol' points
    (m from GGX's D(m)(n.m)). Inputs: l, v (N, 3), alpha; ``f0`` is the table's single f0."""

    f0: float
    budget: int = 4096
    seed: int = 0
    name: str = "sobol_ndf"

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["alpha"]), len(points.sobol(self.budget, self.seed)))

    def prepare(self, integrand, device: str) -> None:
        wp.load_module(sobol_point_kernel(integrand.facet).module, device=device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        n = len(inputs["alpha"])
        lv = np.ascontiguousarray(np.stack([inputs["l"], inputs["v"]], axis=1), dtype=np.float32)
        pts = np.clip(points.sobol(self.budget, self.seed), 0.0, np.nextafter(np.float32(1.0), np.float32(0.0)))
        out = wp.zeros(n, dtype=wp.float64, device=device)
        wp.launch(sobol_point_kernel(integrand.facet), dim=n,
                  inputs=[wp.array(lv, dtype=wp.vec3, device=device),
                          wp.array(np.asarray(inputs["alpha"], np.float32), dtype=float, device=device), float(self.f0),
                          wp.array(pts.astype(np.float32), dtype=float, device=device), out], device=device)
        return out.numpy()[:, None]

    def refined(self):
        return PointSobol(self.f0, self.budget, self.seed + 1), "seed - (seed + 1) (two scramblings)"
