"""Kind ``diffuse``: the diffuse AmbientBRDF table, NoV x sigma, for any diffuse model (lutbake.integrands.diffuse):

    E(v) = ∫ f(l, v) (n.l) dω_l                       (rho = 1, at the baked f0)

Estimators: ``gauss_legendre`` (default; the microfacet model by the swapped integral, lutbake.sampling.swapped;
the closed forms by GL on 2 x 2 panels over l, lutbake.sampling.diffuse) and ``sobol_cosine`` (cosine-weighted
Sobol' directions l, any model). Axes: x = NoV, y = sigma (its GGX alpha per index in lutbake:axes).
"""

from __future__ import annotations

import json

import numpy as np

from ..axes import SIGMA_TO_ALPHA, TEXELS, Axis, sigma_alpha
from ..catalog import DIFFUSE_MODELS, FACET_FRESNEL, f0_factor
from ..edge import alpha_policy, effective_alpha
from ..runtime.plan import TexelPlan
from ..sampling.plan import Grid, per_texel_plan
from .base import Estimation, Key, declare

DEFAULT_ORDER = {"microfacet": 12}  # base GL order (lutbake.sampling.swapped); closed forms: CLOSED_ORDER
CLOSED_ORDER = 24

KEYS = {
    "size": Key("size", "int_pair", [64, 64], "[NoV, sigma] texel counts", minimum=1),
    "model": Key("model", "str", "microfacet", "the diffuse model integrated", DIFFUSE_MODELS),
    "f0": Key(
        "f0",
        "float",
        0.0,
        "Fresnel reflectance at normal incidence the table is baked for; every model is "
        "g(f0) times an f0-free function (metadata lutbake:f0_factor), so f0 = 0 bakes the f0-free table",
        minimum=0.0,
        maximum=0.999,
    ),
    "sigma_to_alpha": Key("sigma_to_alpha", "str", "sigma", "GGX alpha from sigma (microfacet model)", SIGMA_TO_ALPHA),
    "facet_fresnel": Key(
        "facet_fresnel", "str", "eq6", "Fresnel transmission on each facet (microfacet model)", FACET_FRESNEL
    ),
    "texel": Key("texel", "str", "center", "texel convention of both axes", TEXELS),
    "nov_range": Key("nov_range", "float_range", [0.0, 1.0], "NoV at t = 0 and t = 1", minimum=0.0, maximum=1.0),
    "sigma_range": Key("sigma_range", "float_range", [0.0, 1.0], "sigma at t = 0 and t = 1", minimum=0.0, maximum=1.0),
}

RECONSTRUCTION = (
    "uv = vec2(NoV, sigma) (texel centres per lutbake:axes); E = texture(lut, uv).r; "
    "diffuse = albedo * (irradiance / pi) * E * g(f0) / g(f0_baked), irradiance = ∫ L cos dω "
    "(g = lutbake:f0_factor; with f0_baked = 0: diffuse = albedo * (irradiance / pi) * E * g(f0))"
)


SAMPLES_DOC = (
    "gauss_legendre: the Gauss-Legendre order n per panel and dimension (2 to 64); microfacet: the base "
    "order of the swapped integral (lutbake.sampling.swapped: 4 n^3 + n^2 evaluations per texel per u "
    "panel, 1.5 n in u and n.l where NoV < 0.1), closed forms: outer 4 n^2 directions l; omitted: 12 for "
    "microfacet, 24 otherwise. sobol_cosine: the number of cosine-weighted directions l (default 4096)"
)
MAX_GL_ORDER = 64
DEFAULT_COSINE_SAMPLES = 4096


def order_for(o: dict) -> int:
    """The GL order of the table (the inner m-rule's order for sobol_cosine)."""
    if o["estimator"] == "gauss_legendre" and o["samples"]:
        return o["samples"]
    return DEFAULT_ORDER.get(o["model"], CLOSED_ORDER)


def estimator_of(o: dict, members: int = 1):
    """gauss_legendre: the swapped integral for the microfacet model (``members``: its f0 groups, kind diffuse_3d),
    the 2 x 2-panel rule over l otherwise; sobol_cosine: cosine-weighted Sobol' directions l
    (lutbake.sampling.diffuse)."""
    from ..sampling.diffuse import CosineSobol, DiffuseGaussLegendre
    from ..sampling.swapped import SwappedGaussLegendre

    order = order_for(o)
    if o["estimator"] == "sobol_cosine":
        return CosineSobol(o["samples"] or DEFAULT_COSINE_SAMPLES, o["seed"], inner_order=order)
    if o["model"] == "microfacet":
        return SwappedGaussLegendre(order, members=members)
    return DiffuseGaussLegendre(order)


def diffuse_grid(axes: list[Axis], nov, sigma, f0, sigma_to_alpha: str) -> Grid:
    """Per-texel inputs of a diffuse albedo table: nov, sigma, alpha (GGX alpha of sigma, lutbake.edge policy:
    clamped, no mirror limit) and f0."""
    alpha = sigma_alpha(sigma, sigma_to_alpha)
    return Grid(
        axes,
        {"nov": nov, "sigma": sigma, "alpha": effective_alpha(alpha, False), "f0": np.asarray(f0, np.float64)},
        grazing=nov,
        alpha=alpha.astype(np.float64),
    )


def sigma_record(sig_axis: Axis) -> dict[str, str]:
    return {
        "sigma_alpha": json.dumps(
            [float(a) for a in effective_alpha(sigma_alpha(sig_axis.values(), sig_axis.alpha_map), False)]
        ),
        "alpha_policy": alpha_policy(False),
    }


def check_spec(spec) -> tuple[str, str] | None:
    o = spec.options
    if o["estimator"] == "gauss_legendre" and o["samples"] is not None and o["samples"] > MAX_GL_ORDER:
        return ("samples", f"with estimator 'gauss_legendre' samples is the GL order: at most {MAX_GL_ORDER}")
    return None


def plan(spec) -> TexelPlan:
    from ..integrands.diffuse import diffuse_integrand

    o = spec.options
    n_nov, n_sigma = o["size"]
    axes = [
        Axis("sigma", "y", n_sigma, *o["sigma_range"], texel=o["texel"], alpha_map=o["sigma_to_alpha"]),
        Axis("NoV", "x", n_nov, *o["nov_range"], texel=o["texel"]),
    ]
    sig_axis, nov_axis = axes
    nov = np.tile(nov_axis.values(), n_sigma)
    sigma = np.repeat(sig_axis.values(), n_nov)
    model = o["model"]
    ff = o["facet_fresnel"]
    terms = {"model": model, "f0": str(o["f0"]), "f0_factor": f0_factor(model, ff)}
    if model == "microfacet":
        terms.update(ndf="ggx", masking="smith_height_correlated", facet_fresnel=ff, sigma_to_alpha=o["sigma_to_alpha"])
    extra = {"f0_factor": f0_factor(model, ff), "f0": repr(o["f0"]), "rho": "1", **sigma_record(sig_axis)}
    return per_texel_plan(
        diffuse_integrand(model, ff),
        estimator_of(o),
        diffuse_grid(axes, nov, sigma, np.full(len(nov), o["f0"]), o["sigma_to_alpha"]),
        channels={
            "E": "∫ f_r (n.l) dω_l for rho = 1 at the baked f0: directional diffuse "
            "reflectance under uniform white light"
        },
        reconstruction=RECONSTRUCTION,
        terms=terms,
        extra=extra,
    )


DIFFUSE_ESTIMATORS = {
    "gauss_legendre": "deterministic Gauss-Legendre: the swapped integral for the microfacet model "
    "(lutbake.sampling.swapped), 2 x 2 panels over l for the closed forms (default)",
    "sobol_cosine": "scrambled Sobol' directions l, cosine-weighted (lutbake.sampling.diffuse): a cross-check",
}
DIFFUSE_ESTIMATION = Estimation(DIFFUSE_ESTIMATORS, "gauss_legendre", SAMPLES_DOC, samples_min=2)
DESCRIPTION = (
    "diffuse AmbientBRDF: NoV x sigma, E = ∫ f_r (n.l) dω_l for Lambert, Oren-Nayar variants, Gotanda's "
    "fitted model or the integrated microfacet model (Eq. 4)"
)
DIFFUSE = declare(
    "diffuse", DESCRIPTION, KEYS, plan, DIFFUSE_ESTIMATION, aliases=("ambient_brdf_diffuse",), check=check_spec
)
