"""One object per normal distribution: its ``@wp.func`` terms side by side, so a sampler and its pdf cannot drift
apart (after pbrt-v4's ``TrowbridgeReitzDistribution``, src/pbrt/util/scattering.h, and mitsuba3's
``MicrofacetDistribution``: D, Lambda, G1, G2, pdf and sample in one place).

``Distribution`` (host-side record, cached ``@wp.func`` factories):
- ``D(h, alpha)``, ``Lambda(NoX, alpha)`` (None where no closed-form Smith Lambda exists), ``G2(masking)``;
- ``tan2_from_u`` / ``u_from_tan2``: the inverse and forward CDF of the polar angle under D(m)(n.m);
- ``pdf_ndf`` / ``sample_ndf``: density D(h)(n.h) and its sampler (inverse CDF, phi = 2 pi u2);
- ``pdf_vndf`` / ``sample_vndf``: the visible-normal density G1(v) max(0, v.h) D(h) / (n.v) and its sampler
  (GGX only).
Edge policy (lutbake.edge): alpha >= ALPHA_MIN here; the alpha -> 0 mirror limit is taken by the integrands that
have it (lutbake.integrands.specular), not by a quadrature.
"""

from __future__ import annotations

from dataclasses import dataclass

import warp as wp

from ..edge import COS_EPS
from ..records import NDF
from ..runtime.warp_runtime import kernel_factory
from . import masking


@dataclass(frozen=True)
class Distribution:
    """An NDF's terms (module docstring); its name, description and citation are its record's (lutbake.records, or a
    plugin's through lutbake.plugins.register_ndf)."""

    name: str
    D: object
    Lambda: object | None
    tan2_from_u: object
    u_from_tan2: object
    sample_vndf: object | None = None  # visible-normal sampler, where one exists
    polar_pdf: object | None = None  # the solid-angle density of tan2_from_u's h where it is not D(h)(n.h) (theta_cdf)

    def masking_allowed(self, masking_name: str) -> bool:
        """Smith masking needs this NDF's Lambda; V-cavity goes with any NDF."""
        return masking_name == "v_cavity" or self.Lambda is not None

    def G2(self, masking_name: str):
        return _G2(self, masking_name)

    @property
    def pdf_ndf(self):
        return _pdf_ndf(self)

    @property
    def sample_ndf(self):
        return _sample_ndf(self)

    @property
    def pdf_vndf(self):
        return _pdf_vndf(self)


@kernel_factory
def _G2(d: Distribution, masking_name: str):
    """The composed masking-shadowing ``G2(NoV, NoL, NoH, VoH, alpha)`` of ``d`` and a masking form."""
    Lam = d.Lambda
    if masking_name == "smith_height_correlated":

        @wp.func
        def G2(NoV: float, NoL: float, NoH: float, VoH: float, alpha: float):
            return masking.G2_smith_height_correlated(Lam(NoV, alpha), Lam(NoL, alpha))
    elif masking_name == "smith_separable":

        @wp.func
        def G2(NoV: float, NoL: float, NoH: float, VoH: float, alpha: float):
            return masking.G2_smith_separable(Lam(NoV, alpha), Lam(NoL, alpha))
    elif masking_name == "v_cavity":

        @wp.func
        def G2(NoV: float, NoL: float, NoH: float, VoH: float, alpha: float):
            return masking.G2_v_cavity(NoH, NoV, NoL, VoH, VoH)
    elif masking_name == "smith_joint_approx":

        @wp.func
        def G2(NoV: float, NoL: float, NoH: float, VoH: float, alpha: float):
            return masking.G2_smith_joint_approx(NoV, NoL, alpha)
    elif masking_name == "schlick_ggx_ibl":

        @wp.func
        def G2(NoV: float, NoL: float, NoH: float, VoH: float, alpha: float):
            return masking.G2_schlick_ggx_ibl(NoV, NoL, alpha)
    else:
        raise KeyError(masking_name)
    return G2


@kernel_factory
def _pdf_ndf(d: Distribution):
    """Density of h under NDF sampling: p(h) = D(h) (n.h), or the polar mapping's own (Distribution.polar_pdf)."""
    if d.polar_pdf is not None:
        return d.polar_pdf
    D = d.D

    @wp.func
    def pdf_ndf(v: wp.vec3, h: wp.vec3, alpha: float):
        return D(h, alpha) * h[2]

    return pdf_ndf


@kernel_factory
def _sample_ndf(d: Distribution):
    """h from the NDF's inverse CDF: tan^2 theta = CDF^-1(u1) (float64), phi = 2 pi u2; density ``pdf_ndf``."""
    t2u = d.tan2_from_u

    @wp.func
    def sample_ndf(v: wp.vec3, alpha: float, u1: float, u2: float):
        tan2 = t2u(wp.float64(u1), wp.float64(alpha))
        c = wp.float64(1.0) / wp.sqrt(wp.float64(1.0) + tan2)
        s = float(wp.sqrt(tan2) * c)
        phi = 2.0 * wp.pi * u2
        return wp.vec3(s * wp.cos(phi), s * wp.sin(phi), float(c))

    return sample_ndf


@kernel_factory
def _pdf_vndf(d: Distribution):
    """Density of h under visible-normal sampling (``sample_vndf``): p(h) = G1(v) max(0, v.h) D(h) / (n.v)."""
    D, Lam = d.D, d.Lambda

    @wp.func
    def pdf_vndf(v: wp.vec3, h: wp.vec3, alpha: float):
        VoH = wp.dot(v, h)
        if VoH <= COS_EPS or v[2] <= COS_EPS:
            return 0.0
        return masking.G1_smith(Lam(v[2], alpha)) * VoH * D(h, alpha) / v[2]

    return pdf_vndf


def from_record(record) -> Distribution:
    """The Distribution of an NDF record's terms (lutbake.records: D, Lambda, the CDF pair, the VNDF sampler)."""
    return Distribution(
        record.name,
        record["D"],
        record.get("Lambda"),
        record["tan2_from_u"],
        record["u_from_tan2"],
        record.get("sample_vndf"),
    )


NDFS = {r.name: from_record(r) for r in NDF if r.plugin is None}  # lutbake's own (a plugin's: its record's obj)
GGX, BECKMANN, BLINN_PHONG = NDFS["ggx"], NDFS["beckmann"], NDFS["blinn_phong"]


@kernel_factory
def theta_cdf():
    """(tan2_from_u, u_from_tan2, pdf) of the plain polar angle, u = theta / (pi/2), phi = 2 pi u2: the outer variable
    of the Gauss-Legendre panels for an NDF that gives no CDF of its own (a plugin's, lutbake.plugins.register_ndf).
    Its solid-angle density: du dphi / (2 pi) = p dω with dω = sin(theta) dtheta dphi, so p = 1 / (pi^2 sin(theta))."""

    @wp.func
    def tan2_from_u(u: wp.float64, alpha: wp.float64):
        t = wp.tan(u * wp.float64(wp.pi / 2.0))
        return t * t

    @wp.func
    def u_from_tan2(tan2: wp.float64, alpha: wp.float64):
        return wp.atan(wp.sqrt(tan2)) / wp.float64(wp.pi / 2.0)

    @wp.func
    def pdf(v: wp.vec3, h: wp.vec3, alpha: float):
        s = wp.sqrt(h[0] * h[0] + h[1] * h[1])
        return 1.0 / (wp.pi * wp.pi * wp.max(s, 1.0e-30))

    return tan2_from_u, u_from_tan2, pdf


def distribution(ndf) -> Distribution:
    """``ndf`` itself, or lutbake's Distribution of that name (host helpers and tests name lutbake's own)."""
    return NDFS[ndf] if isinstance(ndf, str) else ndf
