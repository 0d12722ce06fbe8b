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
same integrand at the Gauss-Kronrod nodes of adaptive mu panels (lutbake.sampling.mu_average) and sums 2 W E mu per
roughness, to the tolerance, with an estimate per texel.
"""

from __future__ import annotations

import numpy as np

from ..axes import Axis
from ..runtime.plan import TexelPlan
from ..sampling.mu_average import mu_averages, mu_target
from ..sampling.plan import per_texel_plan
from ..tolerance import Tolerance, over_tolerance, tolerance_of
from . import dfg
from .base import Key, declare

ALBEDO_KEYS = {k: v for k, v in dfg.KEYS.items() if k not in ("layout", "fresnel")}  # F = 1
ALBEDO_CHANNELS = {"e": "E = ∫ f/F (n.l) dω_l: single-scattering directional albedo with F = 1"}
ALBEDO_RECONSTRUCTION = (
    "E_v = texture(albedo, vec2(NoV, roughness)).r; E_l = texture(albedo, vec2(NoL, roughness)).r; "
    "E_avg = texture(albedo_avg, vec2(roughness, 0.5)).r; "
    "f_ms = (1 - E_v) (1 - E_l) / (pi (1 - E_avg)) * F_ms, F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)); "
    "or, for image-based lighting, specular *= 1 + f0 (1 / E_v - 1)"
)

# kind albedo_avg's mu rule (lutbake.sampling.mu_average): first panels (E(mu) varies fastest near grazing), the
# shares of the tolerance of the mu rule and of the inner rule (they add up to the texel's estimate), the bisection cap
MU_STARTS = np.array([0.0, 0.2, 1.0])
MU_SHARE = 0.25
INNER_SHARE = 1.0 - MU_SHARE
MU_MAX_PANELS = 40

AVG_KEYS = {
    "roughness_size": Key("roughness_size", "int", 128, "roughness texel count (the table is one row)", minimum=1),
    "mu_order": Key(
        "mu_order",
        "int",
        7,
        "Gauss points n of the Gauss-Kronrod pair (n, 2n + 1) per mu = n.v panel (from 0, 0.2, 1; bisected to the "
        "tolerance)",
        minimum=2,
        maximum=64,
    ),
    **{k: dfg.KEYS[k] for k in ("roughness", "ndf", "masking", "model", "texel", "roughness_range")},
}
AVG_CHANNELS = {"e_avg": "E_avg = 2 ∫ E(mu) mu dmu: hemispherical albedo with F = 1"}
AVG_RECONSTRUCTION = "E_avg = texture(albedo_avg, vec2(roughness, 0.5)).r (one row; x = roughness)"


def integrand_of(spec):
    from ..integrands.specular import specular_integrand

    form, nd, mk = dfg.terms_of(spec)
    return specular_integrand(nd.obj, mk, "albedo", form, 1)


def plan_albedo(spec) -> TexelPlan:
    from ..sampling.hemisphere import estimator_for

    o = spec.options
    axes = dfg.axes_for(o)
    integrand = integrand_of(spec)
    return per_texel_plan(
        integrand,
        estimator_for(o["estimator"], o["samples"], o["seed"], tolerance_of(o)),
        dfg.grid_for(axes, integrand),
        channels=ALBEDO_CHANNELS,
        reconstruction=ALBEDO_RECONSTRUCTION,
        terms=dfg.terms_record(spec, "none (F = 1)"),
        extra=dfg.specular_extra(integrand),
        interpolate=o["interpolation"] == "verified",
    )


def avg_roughness_axis(o: dict) -> Axis:
    rname = "perceptual_roughness" if o["roughness"] == "perceptual" else "alpha"
    return Axis(rname, "x", o["roughness_size"], *o["roughness_range"], texel=o["texel"])


def plan_albedo_avg(spec) -> TexelPlan:
    """E_avg(r) = 2 ∫ E(mu, r) mu dmu per roughness texel by lutbake.sampling.mu_average: Gauss-Kronrod panels from
    mu = 0, 0.2, 1, bisected until the mu rule's estimate is within MU_SHARE of the tolerance; the inner integral E(mu)
    by the kind's estimator, to INNER_SHARE of it where it adapts (the default), whose per-node bounds add up into
    the texel's estimate (recorded as lutbake:error_estimate; a fixed-order or QMC inner estimator records none)."""
    from ..sampling.hemisphere import estimator_for

    o = spec.options
    rough = avg_roughness_axis(o)
    integrand = integrand_of(spec)
    tol = tolerance_of(o)
    inner = Tolerance(INNER_SHARE * tol.absolute, INNER_SHARE * tol.relative)
    estimator = estimator_for(o["estimator"], o["samples"], o["seed"], inner)
    adaptive = hasattr(estimator, "evaluate_with_error")
    alpha = rough.alpha()
    order = o["mu_order"]
    nch = integrand.nch

    def e_at(t, mu, device):
        """E (and its bounds, where the estimator adapts) at (alpha[t], mu), one launch."""
        inputs = {
            "nov": mu.astype(np.float32),
            "alpha": integrand.alpha_input(alpha[t]),
            "param": np.zeros(len(mu), np.float32),
        }
        if adaptive:
            v, e = estimator.evaluate_with_error(integrand, inputs, device)
            return v[:, :nch], e[:, :nch]
        return estimator.evaluate(integrand, inputs, device)[:, :nch], None

    def run(s, e, device):
        """E_avg of texels [s, e), then each texel's estimate (mu rule + inner bounds: the aux column)."""
        t = np.arange(s, e)
        r = mu_averages(
            lambda tt, mu: e_at(tt, mu, device),
            t,
            [MU_STARTS] * len(t),
            order,
            mu_target(tol, MU_SHARE),
            MU_MAX_PANELS,
        )
        return np.concatenate([r.values, r.mu_error + r.inner_error], axis=1)

    def error_estimate(data: np.ndarray, device: str) -> tuple[float, str, str]:
        full = data.reshape(rough.count, -1)
        values, err = full[:, :nch], full[:, nch:]
        ratios = np.max(err / np.maximum(tol.absolute, tol.relative * np.abs(values)), axis=1)
        return (
            float(np.max(err)),
            f"per texel: sum over mu panels of |Q(Kronrod {2 * order + 1}) - Q(Gauss {order})| + 2 sum W mu e(mu) over "
            f"the Kronrod nodes, e the inner rule's own estimate at each node; max error / tolerance = "
            f"{float(np.max(ratios)):.3g}",
            over_tolerance(ratios, [rough]),
        )

    per = int(estimator.samples({"nov": [0.0]})[0]) * len(MU_STARTS) * (2 * order + 1)  # nominal: the first panels
    return TexelPlan(
        axes=[rough],
        channels=AVG_CHANNELS,
        reconstruction=AVG_RECONSTRUCTION,
        n_texels=rough.count,
        n_channels=nch,
        run_tile=run,
        prepare=lambda d: estimator.prepare(integrand, d),
        samples=per,
        estimator=estimator.name,
        terms=dfg.terms_record(spec, "none (F = 1)"),
        cost=float(rough.count) * per,
        extra={
            "mu_quadrature": f"Gauss-Kronrod ({order}, {2 * order + 1}) per panel from mu = 0, 0.2, 1; the worst panel "
            f"bisected until the sum of |Kronrod - Gauss| is within {MU_SHARE:g} x the tolerance (at most "
            f"{MU_MAX_PANELS} panels); the inner rule to {INNER_SHARE:g} x the tolerance",
            "tolerance": tol.text(),
            **dfg.specular_extra(integrand),
        },
        error_estimate=error_estimate if adaptive else None,
        aux_channels=nch,
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
