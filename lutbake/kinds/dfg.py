"""Kind ``dfg``: the split-sum specular table (Karis 2013), NoV x roughness.

    E(NoV, r) = ∫ f(l, v) (n.l) dω_l,   f = D F G2 / (4 (n.l)(n.v)),   F = f0 + (1 - f0) Fc, Fc = (1 - v.h)^5
Schlick F makes f0 factor out, so two channels hold the whole table:
    scale_bias   R = ∫ f/F (1 - Fc) (n.l) dω,  G = ∫ f/F Fc (n.l) dω       E = f0 R + G
    multiscatter R = ∫ f/F Fc (n.l) dω,        G = ∫ f/F (n.l) dω          E = mix(R, G, f0); E(F=1) = G
The layouts (key ``layout``) are records of lutbake.layouts, one module per engine: the pairs above (plain.py), the
F82-tint third channel (eevee.py), the cloth DV (filament.py), the sheen lobe alone (gltf.py), HDRP's diffuse channel
(hdrp.py); each says its channels, the map from the integrand's channels to the stored ones and its shader text.
Axes, by default: x (columns) = NoV, y (rows) = roughness; image row 0 is the first roughness value
(smoothest). The engine conventions are explicit keys: ``axis_order`` (which quantity is x),
``row_order`` (image row 0 = t near 0 or near 1), ``nov_mapping`` / ``roughness_mapping`` (how t maps to
the value) and ``nov_clamp`` (lutbake.axes).
Integrand: lutbake.integrands.specular (SpecularIntegrand); estimators: lutbake.sampling.hemisphere, where the
integral is derived.
"""

from __future__ import annotations

import numpy as np

from ..axes import MAPPINGS, ORDERS, ROUGHNESS_PARAMS, TEXELS, Axis
from ..edge import ALPHA_MIN, alpha_policy
from ..layouts import layouts_of, lookup_layout, summaries
from ..layouts.base import nov_alpha_grid as texel_grid
from ..records import FRESNEL, HEMISPHERE_ESTIMATOR, MASKING, MODEL, NDF
from ..registry import Record, choices
from ..runtime.plan import TexelPlan
from ..sampling.plan import Grid, StoredMap, per_texel_plan
from ..tolerance import tolerance_of
from .base import Estimation, Key, declare

# the layouts (lutbake.layouts: one record per layout, one module per engine): name -> summary, name -> channels
LAYOUTS = summaries("dfg")
CHANNELS = {name: lay.channels for name, lay in layouts_of("dfg").items()}
AXIS_ORDERS = {
    "nov_x": "columns (x) = NoV, rows (y) = roughness: sample at vec2(NoV, roughness) (Filament, glTF, UE4)",
    "roughness_x": "columns (x) = roughness, rows (y) = NoV: sample at vec2(roughness, NoV-coordinate) (Blender EEVEE)",
}
NOV_MAPPINGS = {k: MAPPINGS[k] for k in ("linear", "one_minus_t2", "square")}
ROUGHNESS_MAPPINGS = {k: MAPPINGS[k] for k in ("linear", "texel_offset")}


def linear_in_f0(record: Record) -> bool:
    """A Fresnel record the split sum can factor: F = f0 + (1 - f0) Fc(c)."""
    return bool(record.fields.get("linear_in_f0"))


FRESNEL_LAYOUTS = ("scale_bias", "multiscatter")  # the layouts whose channels take the config's Fresnel


INTERPOLATIONS = {
    "verified": "interpolated from the coarse texels wherever each texel's own error estimate meets the tolerance, "
    "else integrated (lutbake.sampling.interpolation)",
    "off": "every texel integrated",
}
KEYS = {
    "size": Key("size", "int_pair", [128, 128], "[NoV, roughness] texel counts", minimum=1),
    "roughness": Key("roughness", "str", "perceptual", "what the roughness axis holds", ROUGHNESS_PARAMS),
    "ndf": Key("ndf", "str", "ggx", "normal distribution function", choices(NDF)),
    "masking": Key("masking", "str", "smith_height_correlated", "masking-shadowing G2", choices(MASKING)),
    "model": Key(
        "model",
        "str",
        "microfacet",
        "the BRDF's term set (lecture 003); other than microfacet, it fixes ndf and masking (leave them unset)",
        choices(MODEL),
    ),
    "fresnel": Key(
        "fresnel",
        "str",
        "schlick",
        "the Fresnel term, linear in f0 (F = f0 + (1 - f0) Fc): the layouts scale_bias and multiscatter store the "
        "pair it factors into; the other layouts fix Schlick's",
        choices(FRESNEL, linear_in_f0, "the split sum factors f0 out of Fresnel terms linear in f0 only"),
    ),
    "layout": Key("layout", "str", "scale_bias", "channel layout", LAYOUTS),
    "texel": Key("texel", "str", "center", "texel convention of both axes", TEXELS),
    "nov_range": Key("nov_range", "float_range", [0.0, 1.0], "NoV at t = 0 and t = 1", minimum=0.0, maximum=1.0),
    "roughness_range": Key(
        "roughness_range", "float_range", [0.0, 1.0], "roughness at t = 0 and t = 1", minimum=0.0, maximum=1.0
    ),
    "axis_order": Key("axis_order", "str", "nov_x", "which quantity runs along the columns (x)", AXIS_ORDERS),
    "row_order": Key("row_order", "str", "lo_first", "which end of the row (y) axis is image row 0", ORDERS),
    "nov_mapping": Key("nov_mapping", "str", "linear", "how t maps to NoV", NOV_MAPPINGS),
    "roughness_mapping": Key("roughness_mapping", "str", "linear", "how t maps to roughness", ROUGHNESS_MAPPINGS),
    "nov_clamp": Key(
        "nov_clamp",
        "float_range",
        [0.0, 1.0],
        "NoV clamped to [lo, hi] after the mapping (Blender EEVEE: [1e-4, 0.9999])",
        minimum=0.0,
        maximum=1.0,
    ),
    "interpolation": Key(
        "interpolation",
        "str",
        "verified",
        "how the texels between every 4th row and column are found (tables of >= 128 x 128 to a tolerance)",
        INTERPOLATIONS,
    ),
}


def check_spec(spec) -> tuple[str, str] | None:
    """Cross-key rules, checked at config load; returns (key, message) or None."""
    o = spec.options
    model = spec.records["model"]
    if model.name != "microfacet" and (o["ndf"], o["masking"]) != (KEYS["ndf"].default, KEYS["masking"].default):
        return (
            "model",
            f"{model.name!r} fixes the NDF and the masking; ndf and masking are only for model = 'microfacet' "
            f"(got ndf = {o['ndf']!r}, masking = {o['masking']!r})",
        )
    form, nd, mk = terms_of(spec)
    if form == "microfacet" and MASKING.lookup(mk).fields["smith"] and not nd.fields["smith"]:
        return ("masking", f"ndf {nd.name!r} has no Smith Lambda: use masking = 'v_cavity' with it, not {mk!r}")
    if o["estimator"] == "sobol_vndf" and not nd.fields["vndf"]:
        return (
            "estimator",
            f"'sobol_vndf' needs an NDF with a visible-normal sampler (ndf = 'ggx'), not ndf = {nd.name!r}"
            + (f" (model {model.name!r})" if model.name != "microfacet" else ""),
        )
    if o["estimator"] in ("sobol_ndf", "hammersley_ndf") and not nd.fields.get("sampler", True):
        return ("estimator", f"{o['estimator']!r} samples the NDF's own CDF, which ndf {nd.name!r} does not give")
    layout = o.get("layout", "scale_bias")
    lay = spec.records["layout"].obj if "layout" in spec.records else lookup_layout("dfg", layout)
    if o.get("fresnel", "schlick") != "schlick" and layout not in FRESNEL_LAYOUTS:
        return (
            "fresnel",
            f"layout {layout!r} fixes Schlick's Fresnel; a fresnel goes with layout scale_bias or multiscatter",
        )
    if o["format"] == "threejs_dfg" and (len(lay.channels) != 2 or o["dtype"] != "half"):
        return ("format", "threejs_dfg is three.js's RG16F DFG module: a two-channel layout and dtype = 'half'")
    if lay.gauss_legendre_only and o["estimator"] != "gauss_legendre":
        return ("estimator", lay.gauss_legendre_only.format(layout=lay.name, estimator=o["estimator"]))
    if lay.terms.ndf is not None and (
        model.name != "microfacet" or (o["ndf"], o["masking"]) != (KEYS["ndf"].default, KEYS["masking"].default)
    ):
        return (
            "layout",
            f"layout {o['layout']!r} integrates the sheen lobe (Charlie NDF) alone: leave model, ndf and masking unset",
        )
    if o.get("roughness_mapping") == "texel_offset" and o["texel"] != "center":
        return ("roughness_mapping", "'texel_offset' is defined on texel centres (texel = 'center')")
    return None


def terms_of(spec) -> tuple[str, Record, str]:
    """(integrand form, NDF record, masking name) of a spec: the model's own where it fixes them (cook_torrance:
    beckmann and v_cavity; the lobe models: the Blinn-Phong NDF their estimators sample, no masking), else the
    config's."""
    model = spec.records["model"]
    nd = model.fields["ndf"] or spec.records["ndf"]
    return model.fields["form"], nd, model.fields["masking"] or spec.options["masking"]


def terms_record(spec, fresnel: str) -> dict:
    """The EXR's lutbake:terms record: model, ndf, masking (as integrated) and Fresnel."""
    form, nd, mk = terms_of(spec)
    model = spec.options.get("model", "microfacet")
    if form == "microfacet":
        return {"model": model, "ndf": nd.name, "masking": mk, "fresnel": fresnel}
    return {
        "model": model,
        "ndf": f"{model} lobe (sampled with the blinn_phong CDF)",
        "masking": "none (implicit in the lobe)",
        "fresnel": fresnel,
        "shininess": "s = 2 / alpha^2 - 2",
    }


def axes_for(o: dict) -> list[Axis]:
    """[y axis, x axis] of a dfg table, per axis_order / row_order / mappings."""
    n_nov, n_rough = o["size"]
    rname = "perceptual_roughness" if o["roughness"] == "perceptual" else "alpha"
    nov_x = o.get("axis_order", "nov_x") == "nov_x"
    row_order = o.get("row_order", "lo_first")
    clamp = o.get("nov_clamp", [0.0, 1.0])
    rough = Axis(
        rname,
        "x" if not nov_x else "y",
        n_rough,
        *o["roughness_range"],
        texel=o["texel"],
        mapping=o.get("roughness_mapping", "linear"),
        order="lo_first" if not nov_x else row_order,
    )
    nov = Axis(
        "NoV",
        "x" if nov_x else "y",
        n_nov,
        *o["nov_range"],
        texel=o["texel"],
        mapping=o.get("nov_mapping", "linear"),
        order=row_order if not nov_x else "lo_first",
        clamp=None if list(clamp) == [0.0, 1.0] else tuple(clamp),
    )
    return [rough, nov] if nov_x else [nov, rough]


def reconstruction(layout: str, axes: list[Axis]) -> str:
    """The layout's shader formula, with the uv of this table's axes written out (lutbake.layouts.base.uv_of)."""
    return lookup_layout("dfg", layout).reconstruction(axes)


def grid_for(axes: list[Axis], integrand, param=None, repeat: int = 1) -> Grid:
    """The texels of a [(z,) y, x] specular table: (NoV, alpha) of the [y, x] grid (either axis order), row-major,
    tiled ``repeat`` times (z slowest), and the per-texel ``param`` (f0 of specular_3d; 0 otherwise). ``smooth``
    (lutbake.sampling.interpolation): both axes' values regular (Axis.regular) and alpha >= ALPHA_MIN (no mirror
    limit, no clamp: lutbake.edge)."""
    nov, alpha = (np.tile(x, repeat) for x in texel_grid(axes[-2:]))
    y_axis, x_axis = axes[-2:]
    regular = np.outer(y_axis.regular(), x_axis.regular()).ravel()
    param = np.zeros(len(nov), np.float32) if param is None else param
    return Grid(
        axes,
        {"nov": nov, "alpha": integrand.alpha_input(alpha), "param": param},
        grazing=nov,
        alpha=alpha.astype(np.float64),
        smooth=np.tile(regular, repeat) & (alpha >= ALPHA_MIN),
    )


def specular_extra(integrand) -> dict[str, str]:
    return {"alpha_policy": alpha_policy(integrand.mirror is not None)}


def points_grid(points: dict, integrand) -> Grid:
    """Texels at arbitrary (NoV, alpha): ``points`` {"nov", "alpha"} (flat, one per texel) as a one-axis grid."""
    n = len(points["nov"])
    nov = np.asarray(points["nov"], np.float32)
    return Grid(
        [Axis("i", "x", n)],
        {"nov": nov, "alpha": integrand.alpha_input(points["alpha"]), "param": np.zeros(n, np.float32)},
        grazing=nov,
        alpha=np.asarray(points["alpha"], np.float64),
    )


def layout_terms(spec, lay) -> dict:
    """The lutbake:terms record of a spec in layout ``lay``: the layout's own (sheen) or the kind's, plus what the
    layout adds (the cloth channel, an engine's diffuse term)."""
    fresnel = spec.records["fresnel"].name
    terms = dict(lay.terms_record) if lay.terms_record else {**terms_record(spec, fresnel), "layout": lay.name}
    terms.update(lay.terms_extra)
    if lay.engine_channel is not None:
        terms["diffuse"] = lay.engine_channel.description
    return terms


def plan(spec, points: dict | None = None) -> TexelPlan:
    """The plan of ``spec``'s table; with ``points`` ({"nov", "alpha", "rough"}: flat arrays, "rough" the perceptual
    roughness an engine diffuse channel reads) the same integrand and estimator at those texels instead of the grid
    (lutbake.pipeline.compute_at: audit's and size's reference)."""
    from ..integrands import engine_diffuse
    from ..integrands.specular import N_CHANNELS, specular_integrand
    from ..sampling.hemisphere import estimator_for

    o = spec.options
    lay = spec.records["layout"].obj
    axes = axes_for(o)
    form, nd, mk = terms_of(spec)
    fresnel = spec.records["fresnel"] if lay.name in FRESNEL_LAYOUTS else None
    integrand = specular_integrand(nd.obj, mk, lay.integrand, form, N_CHANNELS[lay.integrand], fresnel)
    stored = (StoredMap.of_values(lay.to_stored, lay.from_stored),) if lay.to_stored is not None else ()
    if lay.engine_channel is not None:
        nov = texel_grid(axes)[0] if points is None else np.asarray(points["nov"])
        rough = engine_diffuse.perceptual_roughness_grid(axes) if points is None else np.asarray(points["rough"])
        stored += (engine_diffuse.diffuse_channel(lay.engine_channel, nov, rough),)
    return per_texel_plan(
        integrand,
        estimator_for(o["estimator"], o["samples"], o["seed"], tolerance_of(o)),
        grid_for(axes, integrand) if points is None else points_grid(points, integrand),
        channels=lay.channels,
        reconstruction=lay.reconstruction(axes),
        terms=layout_terms(spec, lay),
        extra=specular_extra(integrand),
        interpolate=o["interpolation"] == "verified" and points is None,
        error_estimate=points is None,
        stored=stored,
    )


SAMPLES_DOC = "integrand evaluations per texel; omitted: the estimator's default quality"
SPECULAR_ESTIMATION = Estimation(choices(HEMISPHERE_ESTIMATOR), "gauss_legendre", SAMPLES_DOC)
DESCRIPTION = "split-sum specular DFG: NoV x roughness, scale/bias or multiscatter (Σ Fc·V, Σ V) channels"
DFG = declare("dfg", DESCRIPTION, KEYS, plan, SPECULAR_ESTIMATION, aliases=("split_sum",), check=check_spec)
