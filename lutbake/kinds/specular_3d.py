"""Kind ``specular_3d``: the specular AmbientBRDF when F is not linear in f0 (Gotanda 2014 course notes,
Sec. 2: a reflectance map is what artists handle, and Eq. 2 / Eq. 3 are not of Schlick's form
f0 + (1 - f0) w(c) for every term), so the split sum's 2D scale/bias no longer holds and the table gains
an f0 axis:

    E(NoV, r, f0) = ∫ D F(f0, v.h) G2 / (4 (n.l)(n.v)) (n.l) dω_l              (channel R)

stored as z slices over f0 (a multi-part EXR, one part per f0, slice values in lutbake:axes and each
part's lutbake:slice_value). For Schlick it collapses to the dfg table: E = f0 scale + bias
(tests/test_specular3d.py). With ``metal = "<name>"`` the table is 2D, NoV x roughness, and R, G, B hold
E with F = F_conductor(n_c + i k_c, v.h) for the metal's three wavelengths (lutbake.metals).
"""

from __future__ import annotations

import numpy as np

from ..axes import Axis
from ..metals import METALS
from ..records import FRESNEL
from ..registry import Record, choices
from ..runtime.plan import TexelPlan
from ..sampling.plan import per_texel_plan
from ..tolerance import tolerance_of
from . import dfg
from .base import Key, declare


def of_f0(record: Record) -> bool:
    """A Fresnel term of f0, F(f0, c) (not of a complex index)."""
    return record.fields["param"] == "f0"


KEYS = {
    **{k: v for k, v in dfg.KEYS.items() if k != "layout"},
    "fresnel": Key(
        "fresnel",
        "str",
        "dielectric_f0",
        "the Fresnel term integrated (ignored with metal)",
        choices(FRESNEL, of_f0, "the f0 slices take a Fresnel term of f0; a complex index: metal = ..."),
    ),
    "f0_size": Key("f0_size", "int", 16, "f0 slice count (z); ignored with metal", minimum=1, maximum=1024),
    "f0_range": Key(
        "f0_range", "float_range", [0.0, 1.0], "f0 at t = 0 and t = 1 (same texel convention)", minimum=0.0, maximum=1.0
    ),
    "metal": Key(
        "metal",
        "str",
        None,
        "a conductor by name: a 2D NoV x roughness RGB table with exact complex Fresnel instead of the f0 slices",
        {k: m.source for k, m in METALS.items()},
    ),
}
RECONSTRUCTION_3D = (
    "load part k as layer k of a 3D texture; E = texture(lut3d, vec3(NoV, roughness, f0)).r "
    "(texel centres on all three axes: trilinear filtering interpolates f0 between slices); "
    "specular = prefiltered * E"
)
RECONSTRUCTION_METAL = "E = texture(lut, vec2(NoV, roughness)).rgb; specular = prefiltered * E (per channel)"


def axes_for(o: dict) -> list[Axis]:
    axes = dfg.axes_for(o)
    if o["metal"] is not None:
        return axes
    return [Axis("f0", "z", o["f0_size"], *o["f0_range"], texel=o["texel"])] + axes


def plan(spec) -> TexelPlan:
    from ..integrands.specular import metal_param, specular_integrand
    from ..sampling.hemisphere import estimator_for

    o = spec.options
    axes = axes_for(o)
    metal = o["metal"]
    form, nd, mk = dfg.terms_of(spec)
    nch = 3 if metal else 1
    fresnel = None if metal else spec.records["fresnel"]
    integrand = specular_integrand(nd.obj, mk, "metal" if metal else "F", form, nch, fresnel)
    nz = 1 if metal else axes[0].count
    # texel t = (iz * ny + iy) * nx + ix: z (f0) slowest, then roughness, then NoV; a metal's param is its row of
    # lutbake.integrands.specular.METAL_NK
    n_image = axes[-2].count * axes[-1].count
    f0 = np.full(n_image, metal_param(metal), np.float32) if metal else np.repeat(axes[0].values(), n_image)
    if metal:
        m = METALS[metal]
        channels = {
            f"e_{c}": f"E with F_conductor({n} + {k}i) at {w:g} nm"
            for c, n, k, w in zip("rgb", m.n, m.k, m.wavelengths_nm)
        }
        terms = {**dfg.terms_record(spec, "conductor"), "metal": metal}
        extra = {"metal_source": m.source}
    else:
        channels = {"e": f"E = ∫ f (n.l) dω_l with F = {o['fresnel']}(f0 of the slice, v.h)"}
        terms = dfg.terms_record(spec, o["fresnel"])
        extra = {}
    return per_texel_plan(
        integrand,
        estimator_for(o["estimator"], o["samples"], o["seed"], tolerance_of(o)),
        dfg.grid_for(axes, integrand, f0, nz),
        channels=channels,
        reconstruction=RECONSTRUCTION_METAL if metal else RECONSTRUCTION_3D,
        terms=terms,
        extra={**extra, **dfg.specular_extra(integrand)},
        interpolate=o["interpolation"] == "verified",
    )


def texel_count(o: dict) -> int:
    """size x f0_size"""
    return o["size"][0] * o["size"][1] * (1 if o["metal"] else o["f0_size"])


DESCRIPTION = (
    "specular AmbientBRDF for any Fresnel: NoV x roughness x f0 slices (R = E), or NoV x roughness RGB for "
    "a named metal"
)
RULES = {"aliases": ("ambient_brdf_3d",), "check": dfg.check_spec, "texels": texel_count}
SPECULAR_3D = declare("specular_3d", DESCRIPTION, KEYS, plan, dfg.SPECULAR_ESTIMATION, **RULES)
