"""Kind ``dfg``: the split-sum specular table (Karis 2013), NoV x roughness.

    E(NoV, r) = ∫ f(l, v) (n.l) dω_l,   f = D F G2 / (4 (n.l)(n.v)),   F = f0 + (1 - f0) Fc, Fc = (1 - v.h)^5
Schlick F makes f0 factor out, so two channels hold the whole table:
    scale_bias   R = ∫ f/F (1 - Fc) (n.l) dω,  G = ∫ f/F Fc (n.l) dω       E = f0 R + G
    multiscatter R = ∫ f/F Fc (n.l) dω,        G = ∫ f/F (n.l) dω          E = mix(R, G, f0); E(F=1) = G
Axes: x (columns) = NoV, y (rows) = roughness; image row 0 is the first roughness value (smoothest).
The integral and its estimators are derived in lutbake.sampling.estimators.
"""
from __future__ import annotations

import numpy as np

from ..axes import ROUGHNESS_PARAMS, TEXELS, Axis
from ..terms.sets import MASKINGS, MODELS, NDFS, model_terms, pair_allowed
from . import specular
from .base import Key, Kind, Plan

MAX_SAMPLES = 1 << 24  # per texel; beyond this a point set alone needs > 128 MiB and a table takes days
MAX_SEED = (1 << 64) - 1

LAYOUTS = {
    "scale_bias": "R = scale, G = bias: E = f0 * R + G (Karis 2013)",
    "multiscatter": "R = ∫Fc·f, G = ∫f: E = mix(R, G, f0), E(F=1) = G (Filament)",
}
CHANNELS = {
    "scale_bias": {"scale": "∫ f/F (1 - (1 - v.h)^5) (n.l) dω_l: multiplies f0",
                   "bias": "∫ f/F (1 - v.h)^5 (n.l) dω_l: added"},
    "multiscatter": {"fc": "∫ f/F (1 - v.h)^5 (n.l) dω_l: the f90 = 1 weight",
                     "e_ss": "∫ f/F (n.l) dω_l: single-scattering directional albedo with F = 1"},
}
RECONSTRUCTION = {
    "scale_bias": "uv = vec2(NoV, roughness) (texel centres per lutbake:axes); t = texture(lut, uv).rg; "
                  "specular = prefiltered * (f0 * t.r + t.g)",
    "multiscatter": "uv = vec2(NoV, roughness); t = texture(lut, uv).rg; E = mix(t.r, t.g, f0) = (1 - f0) t.r + f0 t.g; "
                    "specular = prefiltered * E; energy compensation = 1 + f0 (1 / t.g - 1)",
}

COMMON_KEYS = {
    "name": Key("name", "name", None, "output stem: <out-dir>/<name>.exr; letters, digits, - and _ only", required=True),
    "kind": Key("kind", "str", None, "table kind (lutbake list)", required=True),
    "samples": Key("samples", "int", None, "integrand evaluations per texel; omitted: the estimator's default "
                   "quality", minimum=1, maximum=MAX_SAMPLES),
    "dtype": Key("dtype", "str", "float32", "pixel type written", {"float32": "32-bit float", "half": "16-bit float"}),
    "estimator": Key("estimator", "str", "gauss_legendre", "how the integral is estimated", specular.ESTIMATORS),
    "seed": Key("seed", "int", 0, "scrambling seed of the Sobol' points (QMC estimators)", minimum=0,
                maximum=MAX_SEED),
}

KEYS = {
    **COMMON_KEYS,
    "size": Key("size", "int_pair", [128, 128], "[NoV, roughness] texel counts", minimum=1),
    "roughness": Key("roughness", "str", "perceptual", "what the roughness axis holds", ROUGHNESS_PARAMS),
    "ndf": Key("ndf", "str", "ggx", "normal distribution function", {k: v.description for k, v in NDFS.items()}),
    "masking": Key("masking", "str", "smith_height_correlated", "masking-shadowing G2", MASKINGS),
    "model": Key("model", "str", "microfacet", "the BRDF's term set (lecture 003); other than microfacet, it fixes "
                  "ndf and masking (leave them unset)", MODELS),
    "layout": Key("layout", "str", "scale_bias", "channel layout", LAYOUTS),
    "texel": Key("texel", "str", "center", "texel convention of both axes", TEXELS),
    "nov_range": Key("nov_range", "float_range", [0.0, 1.0], "NoV at t = 0 and t = 1", minimum=0.0, maximum=1.0),
    "roughness_range": Key("roughness_range", "float_range", [0.0, 1.0], "roughness at t = 0 and t = 1",
                           minimum=0.0, maximum=1.0),
}


def check_spec(spec) -> tuple[str, str] | None:
    """Cross-key rules, checked at config load; returns (key, message) or None."""
    o = spec.options
    model = o.get("model", "microfacet")
    if model != "microfacet" and (o["ndf"], o["masking"]) != (KEYS["ndf"].default, KEYS["masking"].default):
        return ("model", f"{model!r} fixes the NDF and the masking; ndf and masking are only for model = 'microfacet' "
                         f"(got ndf = {o['ndf']!r}, masking = {o['masking']!r})")
    form, nd, mk = terms_of(o)
    if form == "microfacet" and not pair_allowed(nd, mk):
        return ("masking", f"ndf {nd!r} has no Smith Lambda: use masking = 'v_cavity' with it, not {mk!r}")
    if o["estimator"] == "sobol_vndf" and NDFS[nd].vndf is None:
        return ("estimator", f"'sobol_vndf' needs an NDF with a visible-normal sampler (ndf = 'ggx'), not ndf = {nd!r}"
                             + (f" (model {model!r})" if model != "microfacet" else ""))
    return None


def terms_of(o: dict) -> tuple[str, str, str]:
    """(integrand form, ndf, masking) of a spec's options (lutbake.terms.sets.model_terms)."""
    return model_terms(o.get("model", "microfacet"), o["ndf"], o["masking"])


def terms_record(o: dict, fresnel: str) -> dict:
    """The EXR's lutbake:terms record: model, ndf, masking (as integrated) and Fresnel."""
    form, nd, mk = terms_of(o)
    model = o.get("model", "microfacet")
    if form == "microfacet":
        return {"model": model, "ndf": nd, "masking": mk, "fresnel": fresnel}
    return {"model": model, "ndf": f"{model} lobe (sampled with the blinn_phong CDF)",
            "masking": "none (implicit in the lobe)", "fresnel": fresnel,
            "shininess": "s = 2 / alpha^2 - 2"}


def axes_for(o: dict) -> list[Axis]:
    n_nov, n_rough = o["size"]
    rname = "perceptual_roughness" if o["roughness"] == "perceptual" else "alpha"
    return [Axis(rname, "y", n_rough, *o["roughness_range"], texel=o["texel"]),
            Axis("NoV", "x", n_nov, *o["nov_range"], texel=o["texel"])]


def texel_grid(axes: list[Axis]) -> tuple[np.ndarray, np.ndarray]:
    """Per-texel (NoV, alpha) of a [roughness (y), NoV (x)] grid, row-major: texel t = iy * nx + ix."""
    rough, nov_axis = axes
    return np.tile(nov_axis.values(), rough.count), np.repeat(rough.alpha(), nov_axis.count)


def plan(spec) -> Plan:
    o = spec.options
    axes = axes_for(o)
    nov, alpha = texel_grid(axes)
    form, nd, mk = terms_of(o)
    return specular.hemisphere_plan(
        key=(nd, mk, o["layout"], o["estimator"], form), nov=nov, alpha=alpha, param=None,
        samples=o["samples"], seed=o["seed"], nch=2, axes=axes, channels=CHANNELS[o["layout"]],
        reconstruction=RECONSTRUCTION[o["layout"]], terms={**terms_record(o, "schlick"), "layout": o["layout"]})


DFG = Kind("dfg", "split-sum specular DFG: NoV x roughness, scale/bias or multiscatter (Σ Fc·V, Σ V) channels",
           KEYS, plan, aliases=("split_sum",), check=check_spec)
