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
from ..edge import alpha_policy, effective_alpha
from ..limits import MAX_GL_ORDER
from ..records import DIFFUSE, FACET_FRESNEL
from ..registry import choices
from ..runtime.plan import TexelPlan
from ..sampling.diffuse_table import diffuse_grid, estimator_of
from ..sampling.plan import per_texel_plan
from .base import Estimation, Key, declare

KEYS = {
    "size": Key("size", "int_pair", [64, 64], "[NoV, sigma] texel counts", minimum=1),
    "model": Key("model", "str", "microfacet", "the diffuse model integrated", choices(DIFFUSE)),
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
        "facet_fresnel", "str", "eq6", "Fresnel transmission on each facet (microfacet model)", choices(FACET_FRESNEL)
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


def sigma_record(sig_axis: Axis) -> dict[str, str]:
    return {
        "sigma_alpha": json.dumps(
            [float(a) for a in effective_alpha(sigma_alpha(sig_axis.values(), sig_axis.alpha_map), False)]
        ),
        "alpha_policy": alpha_policy(False),
    }


def f0_factor(spec) -> str:
    """How E scales with f0 (lutbake:f0_factor): the model's, or for the microfacet model its facet form's."""
    return spec.records["model"].fields["f0_factor"] or spec.records["facet_fresnel"].fields["f0_factor"]


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
    terms = {"model": model, "f0": str(o["f0"]), "f0_factor": f0_factor(spec)}
    if model == "microfacet":
        terms.update(ndf="ggx", masking="smith_height_correlated", facet_fresnel=ff, sigma_to_alpha=o["sigma_to_alpha"])
    extra = {"f0_factor": f0_factor(spec), "f0": repr(o["f0"]), "rho": "1", **sigma_record(sig_axis)}
    return per_texel_plan(
        diffuse_integrand(spec.records["model"], spec.records["facet_fresnel"]),
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
