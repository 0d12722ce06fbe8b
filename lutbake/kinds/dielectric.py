"""Kinds ``dielectric`` and ``dielectric_avg``: energy tables of the rough dielectric BSDF (Walter, Marschner, Li &
Torrance 2007, "Microfacet models for refraction through rough surfaces") over the relative index of refraction.

    E_R(mu, r, eta) = ∫ f_r |n.o| dω_o over the incident side,   E_T(mu, r, eta) = ∫ f_t |n.o| dω_o over the other side
    E_avg(r, eta)   = 2 ∫_0^1 E(mu) mu dmu   (kind dielectric_avg; panels split at
                                             mu = 0.2 and at cos theta_c for eta < 1)
eta = eta_o / eta_i is the relative IOR seen from the view's side: eta > 1 outside a denser medium, eta < 1 inside it
(total internal reflection past the critical angle). The integrands are lutbake.integrands.dielectric, the default
quadrature lutbake.sampling.dielectric (panelled Gauss-Legendre split at every kink; kind dielectric to the
tolerance, kind dielectric_avg at a fixed order); docs/transmission.md has the
derivation and the measured accuracy, docs/glass-layouts.md every engine's conventions.

Layouts (key ``layout``; lutbake.layouts: energy in plain.py, eevee_btdf / eevee_bsdf in eevee.py, openpbr in
openpbr.py) fix the channels and, for the engine layouts, the whole grid; the estimators are
lutbake.sampling.dielectric_layout's, kind dielectric_avg's quadrature lutbake.sampling.dielectric_avg.
"""

from __future__ import annotations

import numpy as np

from ..axes import Axis
from ..edge import alpha_policy
from ..layouts import exclusive_owner, layouts_of, lookup_layout, summaries
from ..layouts.base import IOR_MAPPINGS, ior_axis, ior_values
from ..records import HEMISPHERE_ESTIMATOR, MASKING, NDF
from ..registry import Record, choices
from ..runtime.plan import TexelPlan
from ..sampling.plan import Grid, per_texel_plan
from ..tolerance import tolerance_of
from . import dfg
from .base import Estimation, Key, declare


def lutbakes_smith(record: Record) -> bool:
    """lutbake's NDFs with a closed-form Smith Lambda (the glass integrands build their G from it)."""
    return record.plugin is None and bool(record.fields["smith"])


def for_transmission(record: Record) -> bool:
    return bool(record.fields["transmission"])


# both kinds reach the tolerance that format / dtype set (lutbake.tolerance; kind dielectric_avg through its mu rule):
# no layout keys
AVG_LAYOUT_KEYS = ()
LAYOUTS = summaries("dielectric")
CHANNELS = {name: lay.channels for name, lay in layouts_of("dielectric").items()}
AVG_CHANNELS = {name: lay.channels for name, lay in layouts_of("dielectric_avg").items()}
GEOMETRY_KEYS = {
    k: dfg.KEYS[k]
    for k in (
        "roughness",
        "texel",
        "roughness_range",
        "nov_range",
        "axis_order",
        "row_order",
        "nov_mapping",
        "roughness_mapping",
        "nov_clamp",
    )
}
KEYS = {
    "layout": Key("layout", "str", "energy", "channels (and, for the engine layouts, the whole grid)", LAYOUTS),
    "size": Key("size", "int_pair", [32, 32], "[NoV, roughness] texel counts (layout energy)", minimum=1),
    "ior_size": Key("ior_size", "int", 32, "IOR slice count (z; layout energy)", minimum=1, maximum=1024),
    "ior_range": Key(
        "ior_range",
        "float_range",
        [1.0, 2.5],
        "relative IOR eta = eta_o / eta_i at t = 0 and t = 1 (eta < 1: seen from inside)",
        minimum=0.05,
        maximum=20.0,
    ),
    "ior_mapping": Key("ior_mapping", "str", "linear", "how the IOR index maps to eta", IOR_MAPPINGS),
    "ndf": Key(
        "ndf",
        "str",
        "ggx",
        "normal distribution function",
        choices(NDF, lutbakes_smith, "the rough-glass BSDF needs an NDF's Smith Lambda (lutbake's ggx, beckmann)"),
    ),
    "masking": Key(
        "masking",
        "str",
        "smith_separable",
        "Smith G2, evaluated with |n.o| on both sides",
        choices(MASKING, for_transmission, "Smith forms are defined for transmission"),
    ),
    **GEOMETRY_KEYS,
}
AVG_KEYS = {
    **{
        k: v
        for k, v in KEYS.items()
        if k not in ("size", "nov_range", "axis_order", "row_order", "nov_mapping", "nov_clamp", "layout")
    },
    "layout": Key("layout", "str", "energy", "channels (openpbr: the grid too)", summaries("dielectric_avg")),
    "roughness_size": Key("roughness_size", "int", 32, "roughness texel count (x; layout energy)", minimum=1),
    "mu_order": Key(
        "mu_order",
        "int",
        7,
        "Gauss points n in mu per panel of the (n, 2n + 1) Gauss-Kronrod pair (panels from 0.2, eta and cos theta_c, "
        "bisected to the tolerance)",
        minimum=2,
        maximum=64,
    ),
}


def texel_grid(o: dict, lay=None) -> tuple[list[Axis], np.ndarray, np.ndarray, np.ndarray, dict]:
    """(axes slowest first, per-texel NoV, alpha, eta in row-major order, extra metadata) of a spec: the layout's fixed
    grid, else IOR slices of the dfg kind's NoV x roughness grid. ``lay``: the spec's layout record's Layout (None:
    the one ``o`` names, for benchmarks)."""
    lay = lay or lookup_layout("dielectric", o["layout"])
    if lay.grid is not None:
        return lay.grid(o)
    etas = ior_values(o["ior_size"], *o["ior_range"], o["texel"], o["ior_mapping"])
    yx = dfg.axes_for(o)
    nov, alpha = dfg.texel_grid(yx)
    return (
        [ior_axis(etas, "z")] + yx,
        np.tile(nov, len(etas)),
        np.tile(alpha, len(etas)),
        np.repeat(etas, len(nov)),
        {"ior_axis": f"{IOR_MAPPINGS[o['ior_mapping']]}, range {list(o['ior_range'])}"},
    )


def terms_of(o: dict, lay=None) -> tuple[str, str]:
    """(ndf, masking) integrated: EEVEE's and OpenPBR's layouts fix GGX with separable Smith (their G_V G_L)."""
    fixed = (lay or lookup_layout("dielectric", o["layout"])).terms
    return fixed.ndf or o["ndf"], fixed.masking or o["masking"]


def terms_record(key: tuple, layout: str) -> dict:
    return {
        "model": "rough dielectric BSDF (Walter et al. 2007)",
        "ndf": key[0],
        "masking": key[1],
        "fresnel": key[2],
        "layout": layout,
    }


def plan(spec) -> TexelPlan:
    from ..integrands.dielectric import dielectric_integrand
    from ..sampling.dielectric import sibling_tiles
    from ..sampling.dielectric_layout import layout_estimator

    o = spec.options
    lay = spec.records["layout"].obj
    axes, nov, alpha, eta, extra = texel_grid(o, lay)
    nd, mk = terms_of(o, lay)
    integrand = dielectric_integrand(nd, mk, lay.integrand, len(lay.channels))
    inputs = {
        "nov": np.asarray(nov, np.float32),
        "alpha": integrand.alpha_input(alpha),
        "param": np.asarray(eta, np.float32),
    }
    grid = Grid(axes, inputs, grazing=inputs["nov"], alpha=np.asarray(alpha, np.float64))
    est = layout_estimator(o, lay, members=bool(np.any(np.asarray(eta) >= 1.0)))
    return per_texel_plan(
        integrand,
        est,
        grid,
        channels=lay.channels,
        reconstruction=lay.reconstruction(),
        terms=terms_record((nd, mk, lay.integrand), lay.name),
        extra={**extra, "alpha_policy": alpha_policy(True)},
        siblings=sibling_tiles(inputs),
    )


def avg_grid(o: dict, lay) -> tuple[list[Axis], np.ndarray, np.ndarray]:
    """(axes [ior (y), roughness (x)], alpha and eta per texel, row-major): the layout's fixed grid, else the config's
    IOR and roughness axes."""
    if lay.grid is not None:
        return lay.grid(o)
    etas = ior_values(o["ior_size"], *o["ior_range"], o["texel"], o["ior_mapping"])
    rname = "perceptual_roughness" if o["roughness"] == "perceptual" else "alpha"
    rough = Axis(
        rname, "x", o["roughness_size"], *o["roughness_range"], texel=o["texel"], mapping=o["roughness_mapping"]
    )
    return [ior_axis(etas, "y"), rough], np.tile(rough.alpha(), len(etas)), np.repeat(etas, rough.count)


def plan_avg(spec) -> TexelPlan:
    """E_avg per (eta, roughness) texel (lutbake.sampling.dielectric_avg.average_plan): the inner rule's panels merged
    as the adaptive kernel's; ``samples`` unset: its order climbs until the probe fits the tolerance."""
    from ..integrands.dielectric import dielectric_integrand
    from ..sampling.dielectric_avg import average_plan
    from ..sampling.dielectric_layout import estimator_of

    o = spec.options
    lay = spec.records["layout"].obj
    axes, alpha, eta = avg_grid(o, lay)
    nd, mk = terms_of(o, lay)
    integrand = dielectric_integrand(nd, mk, lay.integrand)
    estimator = estimator_of(o["estimator"], o["samples"], o["seed"], merged=True)
    climb = o["samples"] is None and o["estimator"] == "gauss_legendre"
    terms = terms_record((nd, mk, lay.integrand), lay.name)
    return average_plan(integrand, estimator, axes, alpha, eta, lay, o["mu_order"], tolerance_of(o), climb, terms)


def check_spec(spec) -> tuple[str, str] | None:
    o = spec.options
    lay = spec.records["layout"].obj
    nd, _ = terms_of(o, lay)
    if o["estimator"] == "sobol_vndf" and not NDF.lookup(nd).fields["vndf"]:
        return ("estimator", f"'sobol_vndf' needs ndf = 'ggx' (a visible-normal sampler), not {nd!r}")
    if o.get("ior_mapping") == "symmetric" and (o["ior_range"][1] <= 1.0 or o["ior_size"] % 2):
        return ("ior_mapping", "'symmetric' needs ior_range[1] > 1 (the largest eta) and an even ior_size")
    fixed = lay.terms
    if fixed.ndf is not None and (o["ndf"], o["masking"]) != (fixed.ndf, fixed.masking):
        return (
            "layout",
            f"layout {o['layout']!r} fixes ndf = {fixed.ndf!r} and masking = {fixed.masking!r} (the engine's)",
        )
    owner = exclusive_owner(spec.kind, o.get("format"))
    if owner is not None and owner.name != o["layout"]:
        return (
            "format",
            f"{o['format']!r} writes the {owner.name} layout's arrays: it needs layout = {owner.name!r}, "
            f"not {o['layout']!r}",
        )
    return None


def texel_count(o: dict) -> int:
    """size x ior_size (the engine layouts: their fixed grids)"""
    lay = lookup_layout("dielectric", o["layout"])
    return lay.texels(o) if lay.texels is not None else o["size"][0] * o["size"][1] * o["ior_size"]


def avg_texel_count(o: dict) -> int:
    """roughness_size x ior_size"""
    lay = lookup_layout("dielectric_avg", o["layout"])
    return lay.texels(o) if lay.texels is not None else o["roughness_size"] * o["ior_size"]


SAMPLES_DOC = (
    "integrand evaluations per texel; omitted: gauss_legendre adapts to the tolerance (kind dielectric; "
    "dielectric_avg: 432 = order 12 per panel), sobol_vndf 16384"
)
ESTIMATION = Estimation(choices(HEMISPHERE_ESTIMATOR), "gauss_legendre", SAMPLES_DOC)


DIELECTRIC = declare(
    "dielectric",
    "rough dielectric BSDF energies E_R, E_T, E_R + E_T: NoV x roughness x IOR slices "
    "(eta < 1: seen from inside), or an engine's layout (EEVEE btdf/bsdf, OpenPBR)",
    KEYS,
    plan,
    ESTIMATION,
    aliases=("glass", "btdf"),
    check=check_spec,
    texels=texel_count,
)
DIELECTRIC_AVG = declare(
    "dielectric_avg",
    "hemispherical averages 2 ∫ E mu dmu of the dielectric energies: IOR (rows) x roughness (columns)",
    AVG_KEYS,
    plan_avg,
    ESTIMATION,
    aliases=("glass_avg",),
    check=check_spec,
    texels=avg_texel_count,
    layout_keys=AVG_LAYOUT_KEYS,
)
