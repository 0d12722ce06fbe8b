"""Kinds ``albedo`` and ``albedo_avg``: the tables of Kulla & Conty's energy compensation (Kulla & Conty
2017, "Revisiting physically based shading at Imageworks", SIGGRAPH course, slides 16-19).

    E(mu, r)  = ∫ f(l, v) (n.l) dω_l  with F = 1, mu = n.v    (directional albedo: kind albedo, R = E)
    E_avg(r)  = 2 ∫_0^1 E(mu, r) mu dmu                        (hemispherical average: kind albedo_avg)
The multiple-scattering lobe that restores the energy single scattering loses,
    f_ms(l, v) = (1 - E(n.v)) (1 - E(n.l)) / (pi (1 - E_avg)),
integrates with the cosine to exactly 1 - E(n.v), so E + E_ms = 1 for every view (the white furnace:
tests/test_albedo.py). With Fresnel, f_ms is scaled by
    F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)),  F_avg = 2 ∫ F(mu) mu dmu  (lutbake.tables.fresnel.f_avg).
E is the `dfg` integral with channels (1, 0) (lutbake.tables.specular.channels_albedo); E_avg runs the same
kernel at Gauss-Legendre nodes in mu (MU_PANELS, mu_order nodes each) and sums 2 w E mu per roughness.
"""

from __future__ import annotations

import numpy as np

from ..axes import Axis
from . import dfg, specular
from .base import Key, Kind, Plan
from .fresnel import mu_nodes

ALBEDO_KEYS = {k: v for k, v in dfg.KEYS.items() if k != "layout"}
ALBEDO_CHANNELS = {"e": "E = ∫ f/F (n.l) dω_l: single-scattering directional albedo with F = 1"}
ALBEDO_RECONSTRUCTION = (
    "E_v = texture(albedo, vec2(NoV, roughness)).r; E_l = texture(albedo, vec2(NoL, roughness)).r; "
    "E_avg = texture(albedo_avg, vec2(roughness, 0.5)).r; "
    "f_ms = (1 - E_v) (1 - E_l) / (pi (1 - E_avg)) * F_ms, F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)); "
    "or, for image-based lighting, specular *= 1 + f0 (1 / E_v - 1)"
)

AVG_KEYS = {
    **dfg.COMMON_KEYS,
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


def plan_albedo(spec) -> Plan:
    o = spec.options
    axes = dfg.axes_for(o)
    nov, alpha = dfg.texel_grid(axes)
    form, nd, mk = dfg.terms_of(o)
    return specular.hemisphere_plan(
        key=(nd, mk, "albedo", o["estimator"], form),
        nov=nov,
        alpha=alpha,
        param=None,
        samples=o["samples"],
        seed=o["seed"],
        nch=1,
        axes=axes,
        channels=ALBEDO_CHANNELS,
        reconstruction=ALBEDO_RECONSTRUCTION,
        terms=dfg.terms_record(o, "none (F = 1)"),
    )


def avg_roughness_axis(o: dict) -> Axis:
    rname = "perceptual_roughness" if o["roughness"] == "perceptual" else "alpha"
    return Axis(rname, "x", o["roughness_size"], *o["roughness_range"], texel=o["texel"])


def plan_albedo_avg(spec) -> Plan:
    o = spec.options
    rough = avg_roughness_axis(o)
    est = o["estimator"]
    samples = o["samples"] or specular.DEFAULT_SAMPLES[est]
    form, nd, mk = dfg.terms_of(o)
    key = (nd, mk, "albedo", est, form)
    mu, w = mu_nodes(o["mu_order"])
    alphas = rough.alpha()

    def run_tile(start: int, stop: int, device: str) -> np.ndarray:
        k = specular.kernel_for(*key)
        n = stop - start
        nov = np.tile(mu, n)
        alpha = np.repeat(alphas[start:stop], len(mu))
        E = specular.integrate(k, nov, alpha, est, samples, o["seed"], 2, device)[:, 0].reshape(n, len(mu))
        return (2.0 * E @ (w * mu))[:, None]

    eff = specular.effective_samples(est, samples)
    return Plan(
        axes=[rough],
        channels=AVG_CHANNELS,
        reconstruction=AVG_RECONSTRUCTION,
        n_texels=rough.count,
        n_channels=1,
        run_tile=run_tile,
        prepare=lambda d: specular.load(specular.kernel_for(*key), d),
        samples=eff * len(mu),
        estimator=est,
        terms=dfg.terms_record(o, "none (F = 1)"),
        cost=float(rough.count) * len(mu) * eff,
        extra={"mu_nodes": str(len(mu))},
    )


ALBEDO = Kind(
    "albedo",
    "Kulla-Conty directional albedo E(NoV, roughness) with F = 1 (R = E)",
    ALBEDO_KEYS,
    plan_albedo,
    aliases=("e_ss",),
    check=dfg.check_spec,
)
ALBEDO_AVG = Kind(
    "albedo_avg",
    "Kulla-Conty average albedo E_avg(roughness) = 2 ∫ E mu dmu: one row",
    AVG_KEYS,
    plan_albedo_avg,
    aliases=("e_avg",),
    check=dfg.check_spec,
)
