"""Integrands of the diffuse tables: the diffuse BRDFs f(l, v) for rho = 1, as ``brdf(l, v, sigma, alpha, f0,
rule) -> float64`` (closed forms ignore alpha and the GL arrays; the microfacet model of Gotanda 2014, Eq. 4, is
integrated over m by lutbake.sampling.facets and ignores sigma).

The microfacet diffuse BRDF (Gotanda 2014, course notes, Eq. 4; every facet Lambertian, rho = 1):
    f(l, v) = 1 / (pi (n.l)(n.v)) ∫_Ω (m.l)+ (m.v)+ D(m) F_facet(m.l, m.v) G2(m, l, v) dω_m
GGX D, height-correlated Smith G2 = χ+(m.l) χ+(m.v) / (1 + Λ(n.v) + Λ(n.l)) (Heitz 2014, Eq. 99): apart from
the χ+ (the clamps), G2 does not depend on m and leaves the integral:
    f = G2(l, v) / (pi (n.l)(n.v)) ∫ (m.l)+ (m.v)+ F_facet D(m) dω_m.
At sigma -> 0, D -> delta(m - n) / (n.m) and f -> F_facet(n.l, n.v) / pi: Lambert x Eq. 6 for the Eq. 6 facet form.

The record ``DiffuseIntegrand`` also carries, for the microfacet model, its facet transmission split
F_facet = c(f0) T(m.l) T(m.v) (``transmission`` = T, ``f0_scale`` = c), which the swapped-integral albedo
(lutbake.sampling.swapped) needs. alpha -> 0 has no closed form here: alpha is clamped to ALPHA_MIN (lutbake.edge).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

from ..axes import sigma_alpha
from ..edge import COS_EPS, effective_alpha
from ..records import DIFFUSE, FACET_FRESNEL
from ..runtime.warp_runtime import kernel_factory
from ..sampling.diffuse import DiffuseGaussLegendre, eval_points
from ..sampling.facets import fd_microfacet_for
from ..sampling.swapped import integrate_swapped
from ..terms import diffuse

# the facet form's f0 factor c(f0) in F_facet = c(f0) T(m.l) T(m.v) (its T: the facet record's ``T``)
FACET_F0_SCALE = {
    "eq6": lambda f0: 1.05 * (1.0 - f0),
    "schlick": lambda f0: (1.0 - f0) ** 2,
    "dielectric_f0": lambda f0: 1.0,
}


def diffuse_record(model):
    """``model`` itself, or lutbake's diffuse record of that name (host helpers and tests name lutbake's own)."""
    return DIFFUSE.lookup(model) if isinstance(model, str) else model


def facet_record(facet_fresnel):
    return FACET_FRESNEL.lookup(facet_fresnel) if isinstance(facet_fresnel, str) else facet_fresnel


@kernel_factory
def brdf_for(model, facet):
    """``brdf(l, v, sigma, alpha, f0, rule) -> float64``: the BRDF of a diffuse record for rho = 1 (closed forms,
    the record's ``Fd(rho, NoL, NoV, LoV, sigma[, f0])``, ignore alpha and the GL rule (node, weight) of the
    microfacet model's m-integral; the microfacet model, with its ``facet`` record's F_facet, ignores sigma)."""
    if model.name == "microfacet":
        fm = fd_microfacet_for(facet["F"])

        @wp.func
        def brdf(l: wp.vec3, v: wp.vec3, sigma: float, alpha: float, f0: float, rule: wp.array(dtype=wp.vec2d)):
            return fm(l, v, alpha, f0, rule)

        return brdf
    if model.name == "lambert":

        @wp.func
        def brdf(l: wp.vec3, v: wp.vec3, sigma: float, alpha: float, f0: float, rule: wp.array(dtype=wp.vec2d)):
            if l[2] <= COS_EPS or v[2] <= COS_EPS:
                return wp.float64(0.0)
            return wp.float64(diffuse.Fd_lambert(1.0))

        return brdf
    F = model["Fd"]
    if model.fields["with_f0"]:

        @wp.func
        def closed(l: wp.vec3, v: wp.vec3, sigma: float, f0: float):
            return F(1.0, l[2], v[2], wp.dot(l, v), sigma, f0)
    else:

        @wp.func
        def closed(l: wp.vec3, v: wp.vec3, sigma: float, f0: float):
            return F(1.0, l[2], v[2], wp.dot(l, v), sigma)

    @wp.func
    def brdf(l: wp.vec3, v: wp.vec3, sigma: float, alpha: float, f0: float, rule: wp.array(dtype=wp.vec2d)):
        return wp.float64(closed(l, v, sigma, f0))

    return brdf


@dataclass(frozen=True)
class DiffuseIntegrand:
    """A diffuse BRDF (rho = 1) and, for the microfacet model, its facet transmission split (module docstring)."""

    model: str
    facet_fresnel: str
    brdf: object
    transmission: object | None
    f0_scale: object | None
    facet: object | None = None  # the microfacet model's F_facet(MoL, MoV, f0) (lutbake.sampling.facets)
    nch: int = 1


def diffuse_integrand(model, facet_fresnel="eq6") -> DiffuseIntegrand:
    """The integrand of a diffuse model (a record, or the name of one of lutbake's) and facet form."""
    return _diffuse_integrand(diffuse_record(model), facet_record(facet_fresnel))


@kernel_factory
def _diffuse_integrand(model, facet) -> DiffuseIntegrand:
    if model.name != "microfacet":
        return DiffuseIntegrand(model.name, facet.name, brdf_for(model, facet), None, None)
    T, c = facet["T"], FACET_F0_SCALE[facet.name]
    return DiffuseIntegrand(model.name, facet.name, brdf_for(model, facet), T, c, facet["F"])


@kernel_factory
def lobe_integrand(lobe) -> DiffuseIntegrand:
    """A plugin's cosine-weighted lobe (lutbake.ltc.lobes.custom_lobe) as a diffuse BRDF for the diffuse kind's
    estimators: f(l, v) = f_cos(v, l, x) / (n.l), x its parameter (passed as sigma), 0 where n.l <= COS_EPS."""
    f_cos = lobe.f_cos

    @wp.func
    def brdf(l: wp.vec3, v: wp.vec3, sigma: float, alpha: float, f0: float, rule: wp.array(dtype=wp.vec2d)):
        if l[2] <= COS_EPS:
            return wp.float64(0.0)
        return wp.float64(f_cos(v, l, sigma)) / wp.float64(l[2])

    return DiffuseIntegrand(lobe.name, "", brdf, None, None)


def _alpha(sigma, sigma_to_alpha: str):
    return effective_alpha(sigma_alpha(np.asarray(sigma, np.float32), sigma_to_alpha), False)


def eval_brdf(
    model: str,
    l: np.ndarray,
    v: np.ndarray,
    sigma,
    f0: float = 0.0,
    facet_fresnel: str = "eq6",
    sigma_to_alpha: str = "sigma",
    order: int = 8,
    device: str = "cpu",
) -> np.ndarray:
    """Host helper: f(l_i, v_i) for unit direction arrays (N, 3) (n = +z), rho = 1, the microfacet model's m-rule
    of ``order``; float64 (N,)."""
    n = len(np.asarray(l).reshape(-1, 3))
    s = np.broadcast_to(np.asarray(sigma, dtype=np.float32), (n,))
    return eval_points(diffuse_integrand(model, facet_fresnel), l, v, s, _alpha(s, sigma_to_alpha), f0, order, device)


def albedo_gl(
    model: str,
    nov,
    sigma,
    f0: float = 0.0,
    facet_fresnel: str = "eq6",
    sigma_to_alpha: str = "sigma",
    order: int = 8,
    outer_order: int | None = None,
    device: str = "cpu",
) -> np.ndarray:
    """Host helper: E(nov_i, sigma_i) = ∫ f (n.l) dω_l (rho = 1) by GL over l on 2 x 2 panels
    (lutbake.sampling.diffuse.DiffuseGaussLegendre), float64 (N,)."""
    nov = np.ascontiguousarray(nov, dtype=np.float32)
    s = np.ascontiguousarray(np.broadcast_to(np.asarray(sigma, dtype=np.float32), nov.shape))
    inputs = {"nov": nov, "sigma": s, "alpha": _alpha(s, sigma_to_alpha), "f0": np.full(len(nov), f0)}
    return DiffuseGaussLegendre(order, outer_order).evaluate(diffuse_integrand(model, facet_fresnel), inputs, device)[
        :, 0
    ]


def albedo_swapped(
    nov, alpha, f0=0.0, facet_fresnel: str = "eq6", order: int = 12, orders=None, device: str = "cpu"
) -> np.ndarray:
    """Host helper: the microfacet model's E(nov_i) for GGX alpha_i by the swapped integral
    (lutbake.sampling.swapped), float64 (N,)."""
    return integrate_swapped(diffuse_integrand("microfacet", facet_fresnel), nov, alpha, f0, order, orders, device)
