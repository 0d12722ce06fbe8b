"""Kind ``diffuse_3d``: the diffuse AmbientBRDF with an f0 axis, NoV x sigma x f0 slices, for the per-facet
Fresnel forms where f0 does not factor out of Eq. 4:

    E(NoV, sigma, f0) = ∫ f_r(l, v; sigma, f0) (n.l) dω_l           (channel R, rho = 1)

With ``facet_fresnel = "dielectric_f0"`` (the default) each facet transmits (1 - F(m.l))(1 - F(m.v)), F the exact
dielectric Fresnel written with f0 (Gotanda 2014, Eq. 2): not g(f0) x an f0-free function, so the 2D ``diffuse``
table cannot be rescaled and f0 becomes a z axis. Stored like specular_3d: a multi-part EXR, one part per f0
(z) slice, its f0 in lutbake:axes and in the part's lutbake:slice_value. For a factoring form (``eq6``,
``schlick``, and every closed model, ``fitted`` included) each slice is the 2D table times g(f0)
(tests/test_diffuse3d.py), and the kind is a convenience for engines that want one code path.
"""

from __future__ import annotations

import numpy as np

from ..axes import Axis
from ..records import FACET_FRESNEL
from ..registry import choices
from ..runtime.plan import TexelPlan
from ..sampling.diffuse_table import diffuse_grid, estimator_of
from ..sampling.groups import key_of, siblings_by_key
from ..sampling.plan import per_texel_plan
from . import diffuse
from .base import Key, declare

KEYS = {
    **{k: v for k, v in diffuse.KEYS.items() if k != "f0"},
    "facet_fresnel": Key(
        "facet_fresnel",
        "str",
        "dielectric_f0",
        "Fresnel transmission on each facet (microfacet model); the default is the form where f0 does not factor out",
        choices(FACET_FRESNEL),
    ),
    "f0_size": Key("f0_size", "int", 16, "f0 slice count (z)", minimum=1, maximum=1024),
    "f0_range": Key(
        "f0_range", "float_range", [0.0, 1.0], "f0 at t = 0 and t = 1 (same texel convention)", minimum=0.0, maximum=1.0
    ),
}
RECONSTRUCTION = (
    "load part k as layer k of a 3D texture; E = texture(lut3d, vec3(NoV, sigma, f0)).r (texel "
    "centres on all three axes: trilinear filtering interpolates f0 between slices); "
    "diffuse = albedo * (irradiance / pi) * E, irradiance = ∫ L cos dω"
)


def plan(spec) -> TexelPlan:
    from ..integrands.diffuse import diffuse_integrand
    from ..sampling.swapped import MEMBERS

    o = spec.options
    n_nov, n_sigma = o["size"]
    f0_axis = Axis("f0", "z", o["f0_size"], *o["f0_range"], texel=o["texel"])
    sig_axis = Axis("sigma", "y", n_sigma, *o["sigma_range"], texel=o["texel"], alpha_map=o["sigma_to_alpha"])
    nov_axis = Axis("NoV", "x", n_nov, *o["nov_range"], texel=o["texel"])
    nz = f0_axis.count
    # texel t = (iz * ny + iy) * nx + ix: f0 slowest, then sigma, then NoV
    nov = np.tile(nov_axis.values(), n_sigma * nz)
    sigma = np.tile(np.repeat(sig_axis.values(), n_nov), nz)
    f0 = np.repeat(f0_axis.values(), n_sigma * n_nov).astype(np.float64)
    model, ff = o["model"], o["facet_fresnel"]
    terms = {"model": model, "f0": "z axis"}
    if model == "microfacet":
        terms.update(ndf="ggx", masking="smith_height_correlated", facet_fresnel=ff, sigma_to_alpha=o["sigma_to_alpha"])
    axes = [f0_axis, sig_axis, nov_axis]
    grid = diffuse_grid(axes, nov, sigma, f0, o["sigma_to_alpha"])
    # a CPU tile lies in one f0 slice: it is evaluated with the same (n.v, sigma) texels of every slice, which the
    # microfacet estimator integrates over one set of nodes (lutbake.sampling.swapped; the same bits)
    estimator = estimator_of(o, MEMBERS)
    grouped = getattr(estimator, "members", 1) > 1
    siblings = siblings_by_key(key_of(grid.inputs["nov"], grid.inputs["alpha"]), np.ones(grid.n_texels, bool))
    return per_texel_plan(
        diffuse_integrand(spec.records["model"], spec.records["facet_fresnel"]),
        estimator,
        grid,
        channels={
            "E": "∫ f_r (n.l) dω_l for rho = 1 at the slice's f0: directional diffuse reflectance under "
            "uniform white light"
        },
        reconstruction=RECONSTRUCTION,
        terms=terms,
        extra={
            "rho": "1",
            "f0_factor": "none: f0 is the z axis (per-slice lutbake:slice_value)",
            "factoring_form": diffuse.f0_factor(spec),
            **diffuse.sigma_record(sig_axis),
        },
        siblings=siblings if grouped else None,
    )


def texel_count(o: dict) -> int:
    """size x f0_size"""
    return o["size"][0] * o["size"][1] * o["f0_size"]


DESCRIPTION = (
    "diffuse AmbientBRDF with an f0 axis: NoV x sigma x f0 slices (R = E), for per-facet Fresnel forms where "
    "f0 does not factor out (exact dielectric, Eq. 2)"
)
RULES = {"aliases": ("ambient_brdf_diffuse_3d",), "check": diffuse.check_spec, "texels": texel_count}
DIFFUSE_3D = declare("diffuse_3d", DESCRIPTION, KEYS, plan, diffuse.DIFFUSE_ESTIMATION, **RULES)
