"""What range a table's values can span, declared per kind, layout and model, so a format that cannot hold
them (png16 stores [0, 1] only) is refused when the config is checked, before any kernel runs (issue 11),
instead of after the bake.

``unit_range(spec)`` is None when every value of the table lies in [0, 1] (up to integration noise, which
png16 clips within PNG_SLACK), or the reason it may not. The reasons are physics, checked by
tests/test_value_bounds.py against bakes of every kind, layout and model:

- a directional albedo of an energy-conserving BRDF (white furnace) lies in [0, 1]: the microfacet model with
  Smith or V-cavity masking (Heitz 2014, "Understanding the Masking-Shadowing Function", Sec. 4-5),
  Cook-Torrance, Ashikhmin & Shirley 2000; every dfg channel of the scale_bias / multiscatter /
  scale_bias_f82 layouts is that albedo times a weight in [0, 1];
- not so the sheen layouts (Ashikhmin's visibility is not energy conserving: the charlie integral reaches
  ~2.8), the normalized Blinn-Phong lobe (no masking: up to ~1.03 at grazing view), the classic
  Oren-Nayar of lecture 003 (its A = 0.57 term: up to ~1.04), and btf, which tabulates BRDF values
  f (peaks above 1; the fitted_slides reading even dips below 0).
"""

from __future__ import annotations

from .layouts import layouts_of

# dfg layouts whose channels are weighted single-scattering albedos (each weight in [0, 1]), and the others: each
# layout record says which (lutbake.layouts.base.Layout.unit_range, with the reason in ``above_one``)
UNIT_LAYOUTS = frozenset(name for name, lay in layouts_of("dfg").items() if lay.unit_range)
ABOVE_ONE_LAYOUTS = frozenset(name for name, lay in layouts_of("dfg").items() if not lay.unit_range)
# specular models whose directional albedo is at most 1 (energy conserving), and the others
UNIT_SPECULAR_MODELS = frozenset({"microfacet", "cook_torrance", "ashikhmin_shirley"})
ABOVE_ONE_SPECULAR_MODELS = frozenset({"blinn_phong"})
# diffuse models whose tabulated albedo ratio is at most 1, and the others (eon: exactly 1 for rho = 1, its GL
# estimate within 1e-7 of it)
UNIT_DIFFUSE_MODELS = frozenset(
    {"lambert", "oren_nayar_improved", "oren_nayar_fresnel", "fitted", "fitted_slides", "microfacet", "eon"}
)
ABOVE_ONE_DIFFUSE_MODELS = frozenset({"oren_nayar"})
# rough dielectrics: E_R, E_T, E_R + E_T <= 1 (single-scattering energy conservation), the OpenPBR complements
# 1 - E and EEVEE's Fresnel-factored scale / bias / transmission factors, every layout (measured on the full EEVEE
# and OpenPBR grids: min >= 0, max <= 1.000000)
DIELECTRIC_KINDS = frozenset({"dielectric", "dielectric_avg"})
SPECULAR_KINDS = frozenset({"dfg", "albedo", "albedo_avg", "specular_3d", "specular_aniso"})
DIFFUSE_KINDS = frozenset({"diffuse", "diffuse_3d"})
UNBOUNDED_KINDS = {
    "btf": "btf tabulates BRDF values f, which peak above 1",
    "ltc": "ltc holds the entries of inverse LTC matrices, far above 1 at low roughness",
    "ltc_aniso": "ltc_aniso holds the entries of LTC matrices, negative off the diagonal and above 1 where stretched",
    "environment_specular": "an environment cube holds radiance, unbounded (the sun of a captured sky: 10^4 and more)",
    "environment_irradiance": "an environment cube holds radiance, unbounded (E / pi of a bright sky is far above 1)",
}


def unit_range(spec) -> str | None:
    """None if every value of ``spec``'s table lies in [0, 1]; otherwise why it may not (names the key)."""
    o = spec.options
    if spec.kind in UNBOUNDED_KINDS:
        return UNBOUNDED_KINDS[spec.kind]
    if spec.kind == "dfg" and o.get("layout", "scale_bias") not in UNIT_LAYOUTS:
        return f"layout {o['layout']!r} holds values above 1 (layouts within [0, 1]: {', '.join(sorted(UNIT_LAYOUTS))})"
    if spec.kind in SPECULAR_KINDS and o.get("model", "microfacet") not in UNIT_SPECULAR_MODELS:
        return f"model {o['model']!r} is not energy conserving: its albedo exceeds 1"
    if spec.kind in DIFFUSE_KINDS and o.get("model", "microfacet") not in UNIT_DIFFUSE_MODELS:
        return f"model {o['model']!r} exceeds 1 (its albedo is not bounded by 1)"
    if spec.kind not in SPECULAR_KINDS | DIFFUSE_KINDS | DIELECTRIC_KINDS:
        return f"kind {spec.kind!r} declares no value range"
    return None
