"""Kinds ``albedo`` and ``albedo_avg``: the tables of Kulla & Conty's energy compensation (Kulla & Conty
2017, "Revisiting physically based shading at Imageworks", SIGGRAPH course, slides 16-19).

    E(mu, r)  = ∫ f(l, v) (n.l) dω_l  with F = 1, mu = n.v    (directional albedo: kind albedo, R = E)
    E_avg(r)  = 2 ∫_0^1 E(mu, r) mu dmu                        (hemispherical average: kind albedo_avg)
The multiple-scattering lobe that restores the energy single scattering loses,
    f_ms(l, v) = (1 - E(n.v)) (1 - E(n.l)) / (pi (1 - E_avg)),
integrates with the cosine to exactly 1 - E(n.v), so E + E_ms = 1 for every view (the white furnace:
tests/test_albedo.py). With Fresnel, f_ms is scaled by
    F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)),  F_avg = 2 ∫ F(mu) mu dmu  (lutbake.integrands.fresnel.f_avg).
E is the `dfg` integral with channels (1, 0) (lutbake.integrands.specular.channels_albedo); E_avg evaluates the
same integrand at Gauss-Legendre nodes in mu (two panels, mu_order nodes each: the grid's ``nodes``) and sums
2 w E mu per roughness.
"""

from __future__ import annotations

import numpy as np

from ..axes import Axis
from ..sampling.plan import Grid, TexelPlan, per_texel_plan
from ..tolerance import tolerance_of
from . import dfg
from .base import Key, declare

ALBEDO_KEYS = {k: v for k, v in dfg.KEYS.items() if k != "layout"}
ALBEDO_CHANNELS = {"e": "E = ∫ f/F (n.l) dω_l: single-scattering directional albedo with F = 1"}
ALBEDO_RECONSTRUCTION = (
    "E_v = texture(albedo, vec2(NoV, roughness)).r; E_l = texture(albedo, vec2(NoL, roughness)).r; "
    "E_avg = texture(albedo_avg, vec2(roughness, 0.5)).r; "
    "f_ms = (1 - E_v) (1 - E_l) / (pi (1 - E_avg)) * F_ms, F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)); "
    "or, for image-based lighting, specular *= 1 + f0 (1 / E_v - 1)"
)

AVG_KEYS = {
    "roughness_size": Key("roughness_size", "int", 128, "roughness texel count (the table is one row)", minimum=1),
    "mu_order": Key(
        "mu_order",
        "int",
        24,
        "Gauss-Legendre nodes in mu = n.v per panel (two panels, split at 0.2)",
        minimum=2,
        maximum=256,
    ),
    **{k: dfg.KEYS[k] for k in ("roughness", "ndf", "masking", "model", "texel", "roughness_range")},
}
AVG_CHANNELS = {"e_avg": "E_avg = 2 ∫ E(mu) mu dmu: hemispherical albedo with F = 1"}
AVG_RECONSTRUCTION = "E_avg = texture(albedo_avg, vec2(roughness, 0.5)).r (one row; x = roughness)"


def integrand_of(o: dict):
    from ..integrands.specular import specular_integrand

    form, nd, mk = dfg.terms_of(o)
    return specular_integrand(nd, mk, "albedo", form, 1)


def plan_albedo(spec) -> TexelPlan:
    from ..sampling.hemisphere import estimator_for

    o = spec.options
    axes = dfg.axes_for(o)
    integrand = integrand_of(o)
    return per_texel_plan(
        integrand,
        estimator_for(o["estimator"], o["samples"], o["seed"], tolerance_of(o)),
        dfg.grid_for(axes, integrand),
        channels=ALBEDO_CHANNELS,
        reconstruction=ALBEDO_RECONSTRUCTION,
        terms=dfg.terms_record(o, "none (F = 1)"),
        extra=dfg.specular_extra(integrand),
    )


def avg_roughness_axis(o: dict) -> Axis:
    rname = "perceptual_roughness" if o["roughness"] == "perceptual" else "alpha"
    return Axis(rname, "x", o["roughness_size"], *o["roughness_range"], texel=o["texel"])


def plan_albedo_avg(spec) -> TexelPlan:
    """E_avg(r) = sum_k (2 w_k mu_k) E(mu_k, r): a texel is the weighted sum over the mu nodes (Grid.nodes)."""
    from ..integrands.fresnel import mu_nodes
    from ..sampling.hemisphere import estimator_for

    o = spec.options
    rough = avg_roughness_axis(o)
    integrand = integrand_of(o)
    mu, w = mu_nodes(o["mu_order"])
    n = rough.count
    alpha = np.repeat(rough.alpha(), len(mu))
    grid = Grid(
        [rough],
        {"nov": np.tile(mu, n), "alpha": integrand.alpha_input(alpha), "param": np.zeros(n * len(mu), np.float32)},
        nodes=w * mu,
        scale=2.0,
    )
    return per_texel_plan(
        integrand,
        estimator_for(o["estimator"], o["samples"], o["seed"], tolerance_of(o)),
        grid,
        channels=AVG_CHANNELS,
        reconstruction=AVG_RECONSTRUCTION,
        terms=dfg.terms_record(o, "none (F = 1)"),
        extra={"mu_nodes": str(len(mu)), **dfg.specular_extra(integrand)},
        error_estimate=False,
    )


ALBEDO_DESCRIPTION = "Kulla-Conty directional albedo E(NoV, roughness) with F = 1 (R = E)"
ALBEDO = declare(
    "albedo",
    ALBEDO_DESCRIPTION,
    ALBEDO_KEYS,
    plan_albedo,
    dfg.SPECULAR_ESTIMATION,
    aliases=("e_ss",),
    check=dfg.check_spec,
)


def avg_texels(o: dict) -> int:
    """roughness_size"""
    return o["roughness_size"]


AVG_DESCRIPTION = "Kulla-Conty average albedo E_avg(roughness) = 2 ∫ E mu dmu: one row"
AVG_RULES = {"aliases": ("e_avg",), "check": dfg.check_spec, "texels": avg_texels}
ALBEDO_AVG = declare("albedo_avg", AVG_DESCRIPTION, AVG_KEYS, plan_albedo_avg, dfg.SPECULAR_ESTIMATION, **AVG_RULES)
