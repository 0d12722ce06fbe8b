"""Kind ``dfg``: the split-sum specular table (Karis 2013), NoV x roughness.

    E(NoV, r) = ∫ f(l, v) (n.l) dω_l,   f = D F G2 / (4 (n.l)(n.v)),   F = f0 + (1 - f0) Fc, Fc = (1 - v.h)^5
Schlick F makes f0 factor out, so two channels hold the whole table:
    scale_bias   R = ∫ f/F (1 - Fc) (n.l) dω,  G = ∫ f/F Fc (n.l) dω       E = f0 R + G
    multiscatter R = ∫ f/F Fc (n.l) dω,        G = ∫ f/F (n.l) dω          E = mix(R, G, f0); E(F=1) = G
Two layouts add a third channel B: ``scale_bias_f82`` (Blender EEVEE) B = ∫ f/F (v.h)(1 - v.h)^6 (n.l) dω,
the F82-tint term; ``multiscatter_cloth`` (Filament) B = ∫ D_charlie V_ashikhmin (n.l) dω, the cloth DV.
The sheen layouts integrate the KHR_materials_sheen lobe alone (no GGX, F = 1): ``charlie`` B = ∫ D_charlie
V_ashikhmin (n.l) dω (the glTF Sample Viewer's lut_charlie), ``sheen_albedo`` R = E = ∫ D_charlie V_charlie (n.l) dω
(the spec's albedo scaling), G = the same with V_ashikhmin; ``*_clamped`` clamp V to [0, 1] as the viewer does.
Axes, by default: x (columns) = NoV, y (rows) = roughness; image row 0 is the first roughness value
(smoothest). The engine conventions are explicit keys: ``axis_order`` (which quantity is x),
``row_order`` (image row 0 = t near 0 or near 1), ``nov_mapping`` / ``roughness_mapping`` (how t maps to
the value) and ``nov_clamp`` (lutbake.axes).
Integrand: lutbake.integrands.specular (SpecularIntegrand); estimators: lutbake.sampling.hemisphere, where the
integral is derived.
"""

from __future__ import annotations

import re

import numpy as np

from ..axes import MAPPINGS, ORDERS, ROUGHNESS_PARAMS, TEXELS, Axis
from ..catalog import (
    HEMISPHERE_ESTIMATORS,
    MASKINGS,
    NDF_DESCRIPTIONS,
    SHEEN_LAYOUTS,
    SPECULAR_MODELS,
    VNDF_NDFS,
    masking_allowed,
    model_terms,
)
from ..edge import ALPHA_MIN, alpha_policy
from ..sampling.plan import Grid, TexelPlan, per_texel_plan
from ..tolerance import tolerance_of
from . import engine_layouts
from .base import Estimation, Key, declare

LAYOUTS = {
    "scale_bias": "R = scale, G = bias: E = f0 * R + G (Karis 2013)",
    "multiscatter": "R = ∫Fc·f, G = ∫f: E = mix(R, G, f0), E(F=1) = G (Filament)",
    "scale_bias_f82": "scale_bias + B = ∫ f/F (v.h)(1 - v.h)^6 (n.l): the F82-tint term (Blender EEVEE)",
    "multiscatter_cloth": "multiscatter + B = ∫ D_charlie V_ashikhmin (n.l): cloth DV (Filament --ibl-dfg-cloth)",
    "charlie": "sheen lobe alone: R = G = 0, B = ∫ D_charlie V_ashikhmin (n.l): the glTF Sample Viewer's lut_charlie "
    "(KHR_materials_sheen IBL; gauss_legendre only)",
    "sheen_albedo": "sheen lobe alone: R = E = ∫ D_charlie V_charlie (n.l) (KHR_materials_sheen albedo scaling, "
    "Charlie visibility), G = the same with V_ashikhmin (gauss_legendre only)",
    "charlie_clamped": "charlie with V_ashikhmin clamped to [0, 1]: the glTF Sample Viewer's LUT() integrand exactly",
    "sheen_albedo_clamped": "sheen_albedo with each V clamped to [0, 1], as the glTF Sample Viewer's V_Sheen / "
    "V_Ashikhmin",
}
CHANNELS = {
    "scale_bias": {
        "scale": "∫ f/F (1 - (1 - v.h)^5) (n.l) dω_l: multiplies f0",
        "bias": "∫ f/F (1 - v.h)^5 (n.l) dω_l: added",
    },
    "multiscatter": {
        "fc": "∫ f/F (1 - v.h)^5 (n.l) dω_l: the f90 = 1 weight",
        "e_ss": "∫ f/F (n.l) dω_l: single-scattering directional albedo with F = 1",
    },
}
CHANNELS["scale_bias_f82"] = {
    **CHANNELS["scale_bias"],
    "f82": "∫ f/F (v.h)(1 - v.h)^6 (n.l) dω_l: the F82-tint term (Hoffman 2023 / Blender EEVEE metal_bias)",
}
CHANNELS["multiscatter_cloth"] = {
    **CHANNELS["multiscatter"],
    "cloth_dv": "∫ D_charlie(h; alpha) V_ashikhmin (n.l) dω_l, no Fresnel: sheen/cloth directional albedo "
    "(Estevez & Kulla 2017 NDF, Ashikhmin 2007 visibility 1/(4 (n.l + n.v - (n.l)(n.v))))",
}
CHANNELS["charlie"] = {
    "zero_r": "0 (the viewer's lut_charlie leaves R empty)",
    "zero_g": "0",
    "charlie_dv": "∫ D_charlie(h; alpha) V_ashikhmin (n.l) dω_l, no Fresnel: the sheen lobe's DFG for IBL "
    "(Estevez & Kulla 2017 NDF, Ashikhmin & Premoze 2007 visibility 1/(4 (n.l + n.v - (n.l)(n.v))))",
}
CHANNELS["sheen_albedo"] = {
    "sheen_e": "E(n.v) = ∫ D_charlie V_charlie (n.l) dω_l: directional albedo of the KHR_materials_sheen BRDF with its "
    "Charlie visibility 1/((1 + Lambda(n.v) + Lambda(n.l)) 4 (n.v)(n.l)) (Estevez & Kulla 2017 fit)",
    "sheen_e_ashikhmin": "∫ D_charlie V_ashikhmin (n.l) dω_l: the same with the spec's cheaper Ashikhmin visibility "
    "(may exceed 1: not energy conserving, as the spec warns)",
}
CHANNELS["charlie_clamped"] = {**CHANNELS["charlie"], "charlie_dv": "∫ D_charlie min(V_ashikhmin, 1) (n.l) dω_l"}
CHANNELS["sheen_albedo_clamped"] = {
    "sheen_e": "∫ D_charlie min(V_charlie, 1) (n.l) dω_l",
    "sheen_e_ashikhmin": "∫ D_charlie min(V_ashikhmin, 1) (n.l) dω_l",
}
RECONSTRUCTION = {
    "scale_bias": "uv = vec2(NoV, roughness) (texel centres per lutbake:axes); t = texture(lut, uv).rg; "
    "specular = prefiltered * (f0 * t.r + t.g)",
    "multiscatter": "uv = vec2(NoV, roughness); t = texture(lut, uv).rg; "
    "E = mix(t.r, t.g, f0) = (1 - f0) t.r + f0 t.g; specular = prefiltered * E; "
    "energy compensation = 1 + f0 (1 / t.g - 1)",
}
RECONSTRUCTION["scale_bias_f82"] = (
    RECONSTRUCTION["scale_bias"] + "; F82 tint (Blender EEVEE): b = mix(f0, 1, (6/7)^5) * 7/(6/7)^6 * (1 - f82_tint), "
    "specular = prefiltered * (f0 * t.r + f90 * t.g - b * t.b)"
)
RECONSTRUCTION["multiscatter_cloth"] = (
    RECONSTRUCTION["multiscatter"] + "; cloth/sheen: sheen = prefiltered_charlie * sheen_color * t.b"
)
RECONSTRUCTION["charlie"] = (
    "uv = vec2(NoV, roughness); KHR_materials_sheen IBL (glTF Sample Viewer getIBLRadianceCharlie): "
    "sheen = prefiltered_charlie * sheenColor * texture(lut, uv).b, at uv = vec2(NdotV, sheenRoughness)"
)
RECONSTRUCTION["sheen_albedo"] = (
    "uv = vec2(NoV, roughness); KHR_materials_sheen albedo scaling: E = texture(lut, uv).r at uv = vec2(NdotV, "
    "sheenRoughness); sheenAlbedoScaling = 1 - max3(sheenColor) * E (or min over E(NdotV), E(NdotL)); "
    "f = f_sheen + (f_diffuse + f_specular) * sheenAlbedoScaling; .g is E with Ashikhmin visibility"
)
RECONSTRUCTION["charlie_clamped"] = RECONSTRUCTION["charlie"]
RECONSTRUCTION["sheen_albedo_clamped"] = RECONSTRUCTION["sheen_albedo"]
LAYOUTS.update(engine_layouts.LAYOUTS)
CHANNELS.update(engine_layouts.CHANNELS)
RECONSTRUCTION.update(engine_layouts.RECONSTRUCTION)
AXIS_ORDERS = {
    "nov_x": "columns (x) = NoV, rows (y) = roughness: sample at vec2(NoV, roughness) (Filament, glTF, UE4)",
    "roughness_x": "columns (x) = roughness, rows (y) = NoV: sample at vec2(roughness, NoV-coordinate) (Blender EEVEE)",
}
NOV_MAPPINGS = {k: MAPPINGS[k] for k in ("linear", "one_minus_t2", "square")}
ROUGHNESS_MAPPINGS = {k: MAPPINGS[k] for k in ("linear", "texel_offset")}

INTERPOLATIONS = {
    "verified": "interpolated from the coarse texels wherever each texel's own error estimate meets the tolerance, "
    "else integrated (lutbake.sampling.interpolation)",
    "off": "every texel integrated",
}
KEYS = {
    "size": Key("size", "int_pair", [128, 128], "[NoV, roughness] texel counts", minimum=1),
    "roughness": Key("roughness", "str", "perceptual", "what the roughness axis holds", ROUGHNESS_PARAMS),
    "ndf": Key("ndf", "str", "ggx", "normal distribution function", NDF_DESCRIPTIONS),
    "masking": Key("masking", "str", "smith_height_correlated", "masking-shadowing G2", MASKINGS),
    "model": Key(
        "model",
        "str",
        "microfacet",
        "the BRDF's term set (lecture 003); other than microfacet, it fixes ndf and masking (leave them unset)",
        SPECULAR_MODELS,
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
    model = o.get("model", "microfacet")
    if model != "microfacet" and (o["ndf"], o["masking"]) != (KEYS["ndf"].default, KEYS["masking"].default):
        return (
            "model",
            f"{model!r} fixes the NDF and the masking; ndf and masking are only for model = 'microfacet' "
            f"(got ndf = {o['ndf']!r}, masking = {o['masking']!r})",
        )
    form, nd, mk = terms_of(o)
    if form == "microfacet" and not masking_allowed(nd, mk):
        return ("masking", f"ndf {nd!r} has no Smith Lambda: use masking = 'v_cavity' with it, not {mk!r}")
    if o["estimator"] == "sobol_vndf" and nd not in VNDF_NDFS:
        return (
            "estimator",
            f"'sobol_vndf' needs an NDF with a visible-normal sampler (ndf = 'ggx'), not ndf = {nd!r}"
            + (f" (model {model!r})" if model != "microfacet" else ""),
        )
    if o.get("layout") == "multiscatter_cloth" and o["estimator"] != "gauss_legendre":
        return (
            "estimator",
            "layout 'multiscatter_cloth' needs estimator 'gauss_legendre': the QMC estimators draw "
            "h from the GGX NDF and miss the Charlie NDF's grazing lobe of the cloth channel",
        )
    if engine_layouts.BASE_LAYOUT.get(o.get("layout"), o.get("layout")) in SHEEN_LAYOUTS:
        if o["estimator"] != "gauss_legendre":
            return (
                "estimator",
                f"layout {o['layout']!r} needs estimator 'gauss_legendre': the QMC estimators draw h "
                f"from the GGX NDF and miss the Charlie NDF's grazing lobe (got {o['estimator']!r})",
            )
        if model != "microfacet" or (o["ndf"], o["masking"]) != (KEYS["ndf"].default, KEYS["masking"].default):
            return (
                "layout",
                f"layout {o['layout']!r} integrates the sheen lobe (Charlie NDF) alone: leave model, ndf "
                "and masking unset",
            )
    if o.get("roughness_mapping") == "texel_offset" and o["texel"] != "center":
        return ("roughness_mapping", "'texel_offset' is defined on texel centres (texel = 'center')")
    return None


def terms_of(o: dict) -> tuple[str, str, str]:
    """(integrand form, ndf, masking) of a spec's options (lutbake.catalog.model_terms)."""
    return model_terms(o.get("model", "microfacet"), o["ndf"], o["masking"])


def terms_record(o: dict, fresnel: str) -> dict:
    """The EXR's lutbake:terms record: model, ndf, masking (as integrated) and Fresnel."""
    form, nd, mk = terms_of(o)
    model = o.get("model", "microfacet")
    if form == "microfacet":
        return {"model": model, "ndf": nd, "masking": mk, "fresnel": fresnel}
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
    """The layout's shader formula, with the uv of this table's axes written out (lutbake.axes.Axis.uv)."""
    y_axis, x_axis = axes

    def u(a: Axis) -> str:
        return re.sub(r"\bx\b", {"NoV": "NoV", "alpha": "alpha"}.get(a.name, "roughness"), a.uv_formula())

    uv = f"uv = vec2({u(x_axis)}, {u(y_axis)})"
    text = RECONSTRUCTION[layout]
    return text.replace("uv = vec2(NoV, roughness) (texel centres per lutbake:axes)", uv).replace(
        "uv = vec2(NoV, roughness)", uv
    )


def texel_grid(axes: list[Axis]) -> tuple[np.ndarray, np.ndarray]:
    """Per-texel (NoV, alpha) of a [y, x] grid (either axis order), row-major: texel t = iy * nx + ix."""
    y_axis, x_axis = axes
    if x_axis.name == "NoV":
        return np.tile(x_axis.values(), y_axis.count), np.repeat(y_axis.alpha(), x_axis.count)
    return np.repeat(y_axis.values(), x_axis.count), np.tile(x_axis.alpha(), y_axis.count)


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


def plan(spec, points: dict | None = None) -> TexelPlan:
    """The plan of ``spec``'s table; with ``points`` ({"nov", "alpha", "rough"}: flat arrays, "rough" the perceptual
    roughness an engine diffuse channel reads) the same integrand and estimator at those texels instead of the grid
    (lutbake.pipeline.compute_at: audit's and size's reference)."""
    from ..integrands import engine_diffuse
    from ..integrands.specular import N_CHANNELS, specular_integrand
    from ..sampling.hemisphere import estimator_for

    o = spec.options
    axes = axes_for(o)
    form, nd, mk = terms_of(o)
    base = engine_layouts.BASE_LAYOUT.get(o["layout"], o["layout"])  # the specular integrand's layout
    integrand = specular_integrand(nd, mk, base, form, N_CHANNELS[base])
    cloth = {"cloth": "D_charlie + V_ashikhmin"} if o["layout"] == "multiscatter_cloth" else {}
    terms = {**terms_record(o, "schlick"), "layout": o["layout"], **cloth}
    if base in SHEEN_LAYOUTS:
        vis = {"charlie": "ashikhmin", "sheen_fgd": "charlie (Estevez-Kulla Lambda fit), R and G"}.get(
            base.removesuffix("_clamped"), "R: charlie (Estevez-Kulla Lambda fit), G: ashikhmin"
        )
        if o["layout"].endswith("_clamped"):
            vis += " (V clamped to [0, 1], as the glTF Sample Viewer)"
        terms = {
            "model": "sheen",
            "ndf": "charlie (alpha = the roughness axis' alpha)",
            "masking": vis,
            "fresnel": "none (F = 1)",
            "layout": o["layout"],
            "gauss_legendre_panels": "the GGX CDF in theta_h (panelling only; the integrand is the sheen lobe)",
        }
    if base != o["layout"]:
        terms["diffuse"] = engine_layouts.DIFFUSE_TERMS[o["layout"]]
    plan = per_texel_plan(
        integrand,
        estimator_for(o["estimator"], o["samples"], o["seed"], tolerance_of(o)),
        grid_for(axes, integrand) if points is None else points_grid(points, integrand),
        channels=CHANNELS[o["layout"]],
        reconstruction=reconstruction(o["layout"], axes),
        terms=terms,
        extra=specular_extra(integrand),
        interpolate=o["interpolation"] == "verified" and points is None,
        error_estimate=points is None,
    )
    if base != o["layout"]:
        nov = texel_grid(axes)[0] if points is None else np.asarray(points["nov"])
        rough = engine_diffuse.perceptual_roughness_grid(axes) if points is None else np.asarray(points["rough"])
        plan = engine_diffuse.with_diffuse_channel(plan, nov, rough, o["layout"])
    return plan


SAMPLES_DOC = "integrand evaluations per texel; omitted: the estimator's default quality"
SPECULAR_ESTIMATION = Estimation(HEMISPHERE_ESTIMATORS, "gauss_legendre", SAMPLES_DOC)
DESCRIPTION = "split-sum specular DFG: NoV x roughness, scale/bias or multiscatter (Σ Fc·V, Σ V) channels"
DFG = declare("dfg", DESCRIPTION, KEYS, plan, SPECULAR_ESTIMATION, aliases=("split_sum",), check=check_spec)
