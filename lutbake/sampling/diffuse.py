"""Quadratures of the diffuse tables over the light direction l, for a diffuse BRDF ``brdf(l, v, sigma, alpha, f0,
rule) -> float64`` (lutbake.integrands.diffuse; rule: the GL (node, weight) pairs of the microfacet model's inner
m-integral). Kernel inputs per texel are packed: (n.v, sigma, alpha, f0) as a vec4.

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

import math
from dataclasses import dataclass, replace

import numpy as np
import warp as wp

from ..runtime.warp_runtime import kernel_factory, load_module, unique_kernel
from ..terms.frame import view_dir
from . import points
from .arrays import Floats, Levels, LightView, Points2, Rows64, Rule, Values64
from .facets import (
    FACET_ORDERS,
    MAX_U_PANELS,
    fd_microfacet_adaptive_azimuths_for,
    fd_microfacet_adaptive_for,
    fd_microfacet_sobol_for,
)
from .rules import gl_levels

PI64 = wp.constant(wp.float64(math.pi))
REFINE_ORDER = 8  # the error estimates re-evaluate probe texels with every GL order + 8


@kernel_factory
def albedo_kernel(brdf):
    """Kernel: E(v) = ∫ f (n.l) dω_l per texel (n.v, sigma, alpha, f0); outer GL rule_o on 2 x 2 panels, inner GL
    rule for the microfacet integral (``brdf``: lutbake.integrands.diffuse)."""

    @unique_kernel
    def albedo_gl_kernel(texel: wp.array(dtype=wp.vec4), rule_o: Rule, rule: Rule, out: Rows64):
        i = wp.tid()
        t = texel[i]
        v = view_dir(t[0])
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
                for a in range(rule_o.shape[0]):
                    mu = mlo + (mhi - mlo) * rule_o[a][0]
                    st = wp.sqrt(wp.max(wp.float64(1.0) - mu * mu, wp.float64(0.0)))
                    for b in range(rule_o.shape[0]):
                        phi = plo + half_pi * rule_o[b][0]
                        l = wp.vec3(float(st * wp.cos(phi)), float(st * wp.sin(phi)), float(mu))
                        f = brdf(l, v, t[1], t[2], t[3], rule)
                        acc = acc + rule_o[a][1] * rule_o[b][1] * (mhi - mlo) * half_pi * f * mu
        out[i, 0] = wp.float64(2.0) * acc

    return albedo_gl_kernel


@kernel_factory
def brdf_kernel(brdf):
    """Kernel: f(l, v) at direction pairs lv[i] = (l, v) with sa[i] = (sigma, alpha) (tests, plots, BTF slices)."""

    @unique_kernel
    def brdf_point_kernel(lv: LightView, sa: wp.array(dtype=wp.vec2), f0: float, rule: Rule, out: Values64):
        i = wp.tid()
        out[i] = brdf(lv[i, 0], lv[i, 1], sa[i][0], sa[i][1], f0, rule)

    return brdf_point_kernel


@kernel_factory
def cosine_kernel(brdf):
    """Kernel: E(v) = (pi / N) sum_k f(l_k, v), l_k cosine-weighted from the 2D points ``pts``."""

    @unique_kernel
    def albedo_cosine_kernel(texel: wp.array(dtype=wp.vec4), pts: Points2, rule: Rule, out: Rows64):
        i = wp.tid()
        t = texel[i]
        v = view_dir(t[0])
        acc = wp.float64(0.0)
        n = pts.shape[0]
        for k in range(n):
            r2 = pts[k, 0]
            phi = 2.0 * wp.pi * pts[k, 1]
            st = wp.sqrt(r2)
            l = wp.vec3(st * wp.cos(phi), st * wp.sin(phi), wp.sqrt(wp.max(1.0 - r2, 0.0)))
            acc = acc + brdf(l, v, t[1], t[2], t[3], rule)
        out[i, 0] = PI64 * acc / wp.float64(n)

    return albedo_cosine_kernel


def gl_rule(n: int, device: str):
    """The n-point GL rule on [0, 1] as a Warp array of (node, weight) float64 pairs."""
    return wp.array(np.stack(points.gauss_legendre(n), axis=1), dtype=wp.vec2d, device=device)


def sobol_points(budget: int, seed: int, device: str):
    """``budget`` scrambled 2D Sobol' points (rounded up to a power of two) in [0, 1), float32, as a Warp array."""
    pts = np.clip(points.sobol(budget, seed), 0.0, np.nextafter(np.float32(1.0), np.float32(0.0)))
    return wp.array(pts.astype(np.float32), dtype=float, device=device)


def launch_rows(kernel, arrays: list, n: int, device: str, shape=None) -> np.ndarray:
    """Launch ``kernel`` over n texels with ``arrays`` + a float64 output of ``shape`` (default (n, 1))."""
    out = wp.zeros(shape or (n, 1), dtype=wp.float64, device=device)
    wp.launch(kernel, dim=n, inputs=[*arrays, out], device=device)
    return out.numpy()


def texel_array(inputs: dict, device: str):
    """The per-texel (n.v, sigma, alpha, f0) of the diffuse albedo kernels, as a vec4 (float32) array."""
    t = np.stack([np.asarray(inputs[k], np.float32) for k in ("nov", "sigma", "alpha", "f0")], axis=1)
    return wp.array(np.ascontiguousarray(t), dtype=wp.vec4, device=device)


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
        load_module(albedo_kernel(integrand.brdf).module, device=device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        rules = [gl_rule(self.outer_order or self.order, device), gl_rule(self.order, device)]
        return launch_rows(
            albedo_kernel(integrand.brdf), [texel_array(inputs, device), *rules], len(inputs["nov"]), device
        )

    def refined(self):
        n = self.order + REFINE_ORDER
        return DiffuseGaussLegendre(n), f"order {self.order} - order {n}"


@dataclass(frozen=True)
class ScrambledSobol:
    """Base of the Sobol' estimators here: ``budget`` points (rounded up to a power of two), scrambled by ``seed``;
    refined by another scrambling."""

    budget: int = 4096
    seed: int = 0

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(next(iter(inputs.values()))), len(points.sobol(self.budget, self.seed)))

    def refined(self):
        return replace(self, seed=self.seed + 1), "seed - (seed + 1) (two scramblings)"


@dataclass(frozen=True)
class CosineSobol(ScrambledSobol):
    """E(v) by scrambled Sobol' points, l cosine-weighted (module docstring); the microfacet model's inner m-rule
    at ``inner_order``. Inputs: nov, sigma, alpha, f0."""

    inner_order: int = 12
    name: str = "sobol_cosine"

    def prepare(self, integrand, device: str) -> None:
        load_module(cosine_kernel(integrand.brdf).module, device=device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        arrays = [
            texel_array(inputs, device),
            sobol_points(self.budget, self.seed, device),
            gl_rule(self.inner_order, device),
        ]
        return launch_rows(cosine_kernel(integrand.brdf), arrays, len(inputs["nov"]), device)


def eval_points(
    integrand, l: np.ndarray, v: np.ndarray, sigma, alpha, f0: float, order: int, device: str = "cpu"
) -> np.ndarray:
    """f(l_i, v_i) for unit direction arrays (N, 3) (n = +z), rho = 1, inner m-rule of ``order``; float64 (N,)."""
    lv = np.stack([np.asarray(l, np.float32).reshape(-1, 3), np.asarray(v, np.float32).reshape(-1, 3)], axis=1)
    n = len(lv)
    sa = np.stack([np.broadcast_to(np.asarray(x, dtype=np.float32), (n,)) for x in (sigma, alpha)], axis=1)
    arrays = [
        wp.array(np.ascontiguousarray(lv), dtype=wp.vec3, device=device),
        wp.array(np.ascontiguousarray(sa), dtype=wp.vec2, device=device),
        float(f0),
        gl_rule(order, device),
    ]
    return launch_rows(brdf_kernel(integrand.brdf), arrays, n, device, (n,))


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
        load_module(brdf_kernel(integrand.brdf).module, device=device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        out = np.empty((len(inputs["order"]), 1))
        for n in np.unique(inputs["order"]):
            sel = inputs["order"] == n
            rows = {k: inputs[k][sel] for k in ("l", "v", "sigma", "alpha")}
            out[sel, 0] = eval_points(integrand, **rows, f0=self.f0, order=int(n) + self.extra, device=device)
        return out

    def refined(self):
        e = self.extra + REFINE_ORDER
        return replace(self, extra=e), f"orders - orders + {e}"


@kernel_factory
def sobol_point_kernel(facet):
    """Kernel: the microfacet f(l, v) at lv[i] = (l, v) with its m-integral by the 2D points ``pts``."""
    f = fd_microfacet_sobol_for(facet)

    @unique_kernel
    def brdf_sobol_kernel(lv: LightView, alpha: Floats, f0: float, pts: Points2, out: Values64):
        i = wp.tid()
        out[i] = f(lv[i, 0], lv[i, 1], alpha[i], f0, pts)

    return brdf_sobol_kernel


@dataclass(frozen=True)
class PointSobol(ScrambledSobol):
    """The microfacet model's f(l_i, v_i) (kind btf) with Eq. 4's m-integral by ``budget`` scrambled Sobol' points
    (m from GGX's D(m)(n.m)). Inputs: l, v (N, 3), alpha; ``f0`` is the table's single f0."""

    f0: float = 0.0
    name: str = "sobol_ndf"

    def prepare(self, integrand, device: str) -> None:
        load_module(sobol_point_kernel(integrand.facet).module, device=device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        lv = np.ascontiguousarray(np.stack([inputs["l"], inputs["v"]], axis=1), dtype=np.float32)
        arrays = [
            wp.array(lv, dtype=wp.vec3, device=device),
            wp.array(np.asarray(inputs["alpha"], np.float32), dtype=float, device=device),
            float(self.f0),
            sobol_points(self.budget, self.seed, device),
        ]
        return launch_rows(sobol_point_kernel(integrand.facet), arrays, len(lv), device, (len(lv),))[:, None]


@kernel_factory
def adaptive_point_kernel(facet):
    """Kernel: the microfacet f(l, v) at lv[i] = (l, v) to the tolerance ``tol`` (absolute, relative), and its error
    estimate (lutbake.sampling.facets.fd_microfacet_adaptive_for)."""
    f = fd_microfacet_adaptive_for(facet)

    @unique_kernel
    def brdf_adaptive_kernel(
        lv: LightView, alpha: Floats, f0: float, tol: wp.vec2d, rules: Rule, levels: Levels, out: Rows64
    ):
        i = wp.tid()
        fe = f(lv[i, 0], lv[i, 1], alpha[i], f0, rules, levels, tol)
        out[i, 0] = fe[0]  # f
        out[i, 1] = fe[1]  # its error estimate

    return brdf_adaptive_kernel


@kernel_factory
def adaptive_azimuths_kernel(facet):
    """Kernel: ``adaptive_point_kernel`` for groups of texels that differ only in the azimuth of l, one thread per
    group (texels start[g] .. start[g + 1] - 1): the u nodes are computed once per group
    (lutbake.sampling.facets.fd_microfacet_adaptive_azimuths_for); the same values as adaptive_point_kernel."""
    f = fd_microfacet_adaptive_azimuths_for(facet)

    @unique_kernel
    def brdf_adaptive_azimuths_kernel(
        lv: LightView,
        alpha: Floats,
        f0: float,
        tol: wp.vec2d,
        rules: Rule,
        levels: Levels,
        start: wp.array(dtype=int),
        azl: wp.array(dtype=wp.vec3d),
        panels: Rows64,
        out: Rows64,
    ):
        g = wp.tid()
        f(lv, alpha, f0, rules, levels, tol, start[g], start[g + 1], azl, panels, out)

    return brdf_adaptive_azimuths_kernel


def azimuth_groups(l: np.ndarray, v: np.ndarray, alpha: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(order, start): a permutation of the rows grouping those with equal v, n.l and alpha (they differ only in
    the azimuth of l), and each group's first position in that order (plus the row count at the end)."""
    key = np.concatenate([v, l[:, 2:], alpha[:, None]], axis=1)
    order = np.lexsort(key.T[::-1])
    k = key[order]
    new = np.ones(len(k), dtype=bool)
    new[1:] = np.any(k[1:] != k[:-1], axis=1)
    return order, np.append(np.flatnonzero(new), len(k)).astype(np.int32)


def eval_points_adaptive(integrand, l, v, alpha, f0: float, tol, orders=FACET_ORDERS, device: str = "cpu"):
    """The microfacet f(l_i, v_i) to the tolerance ``tol`` (absolute, relative): (values, error estimates), float64
    (N, 1) each. Rows that differ only in the azimuth of l share their u nodes (adaptive_azimuths_kernel)."""
    l, v, alpha = (np.asarray(x, np.float32) for x in (l, v, alpha))
    order, start = azimuth_groups(l, v, alpha)
    lv = np.ascontiguousarray(np.stack([l[order], v[order]], axis=1))
    n = len(lv)
    rules, levels = gl_levels(tuple(orders))
    arrays = [
        wp.array(lv, dtype=wp.vec3, device=device),
        wp.array(alpha[order], dtype=float, device=device),
        float(f0),
        wp.vec2d(*tol),
        wp.array(rules, dtype=wp.vec2d, device=device),
        wp.array(levels, dtype=wp.vec2i, device=device),
        wp.array(start, dtype=int, device=device),
        wp.zeros(n, dtype=wp.vec3d, device=device),
        wp.zeros((2 * MAX_U_PANELS, n), dtype=wp.float64, device=device),
    ]
    out = wp.zeros((n, 2), dtype=wp.float64, device=device)
    wp.launch(adaptive_azimuths_kernel(integrand.facet), dim=len(start) - 1, inputs=[*arrays, out], device=device)
    res = np.empty((n, 2))
    res[order] = out.numpy()
    return res[:, :1], res[:, 1:]


@dataclass(frozen=True)
class PointAdaptive:
    """The microfacet model's f(l_i, v_i) (kind btf) to a tolerance: the u panels of the m-integral up the orders
    FACET_ORDERS (lutbake.sampling.facets.fd_microfacet_adaptive_for); ``evaluate_with_error`` also returns each
    texel's error estimate. Inputs: l, v (N, 3), alpha. Rows with equal inputs (kind btf gives a texel and its
    reciprocal the same ones) are integrated once: the value of a row never depends on the others."""

    absolute: float
    relative: float
    f0: float = 0.0
    orders: tuple[int, ...] = FACET_ORDERS
    evaluations: float = 1.0  # nominal evaluations per texel, for the record
    name: str = "gauss_legendre"

    def samples(self, inputs: dict) -> np.ndarray:
        return np.full(len(inputs["alpha"]), self.evaluations)

    def prepare(self, integrand, device: str) -> None:
        load_module(adaptive_azimuths_kernel(integrand.facet).module, device=device)

    def evaluate_with_error(self, integrand, inputs: dict, device: str) -> tuple[np.ndarray, np.ndarray]:
        n = len(inputs["alpha"])
        rows = np.concatenate([np.asarray(inputs[k], np.float32).reshape(n, -1) for k in ("l", "v", "alpha")], 1)
        uniq, back = np.unique(rows, axis=0, return_inverse=True)
        tol = (self.absolute, self.relative)
        values, err = eval_points_adaptive(
            integrand, uniq[:, :3], uniq[:, 3:6], uniq[:, 6], self.f0, tol, self.orders, device
        )
        back = back.reshape(-1)
        return values[back], err[back]

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        return self.evaluate_with_error(integrand, inputs, device)[0]

    def refined(self):
        return replace(self, absolute=self.absolute / 100, relative=self.relative / 100), "tolerance / 100"
