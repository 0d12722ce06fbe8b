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

import json

import numpy as np
import warp as wp

from ..axes import Axis
from . import diffuse, diffuse_albedo
from .base import Key, Kind, Plan

KEYS = {
    **{k: v for k, v in diffuse.KEYS.items() if k != "f0"},
    "facet_fresnel": Key(
        "facet_fresnel",
        "str",
        "dielectric_f0",
        "Fresnel transmission on each facet (microfacet model); the default is the form where f0 does not factor out",
        diffuse.FACET_FRESNEL,
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


def plan(spec) -> Plan:
    o = spec.options
    n_nov, n_sigma = o["size"]
    f0_axis = Axis("f0", "z", o["f0_size"], *o["f0_range"], texel=o["texel"])
    sig_axis = Axis("sigma", "y", n_sigma, *o["sigma_range"], texel=o["texel"])
    nov_axis = Axis("NoV", "x", n_nov, *o["nov_range"], texel=o["texel"])
    nz = f0_axis.count
    # texel t = (iz * ny + iy) * nx + ix: f0 slowest, then sigma, then NoV
    nov = np.tile(nov_axis.values(), n_sigma * nz)
    sigma = np.tile(np.repeat(sig_axis.values(), n_nov), nz)
    f0 = np.repeat(f0_axis.values(), n_sigma * n_nov).astype(np.float64)
    model, ff = o["model"], o["facet_fresnel"]
    order = diffuse.order_for(o)
    terms = {"model": model, "f0": "z axis"}
    if model == "microfacet":
        terms.update(ndf="ggx", masking="smith_height_correlated", facet_fresnel=ff, sigma_to_alpha=o["sigma_to_alpha"])
    fields = dict(
        axes=[f0_axis, sig_axis, nov_axis],
        channels={
            "E": "∫ f_r (n.l) dω_l for rho = 1 at the slice's f0: directional diffuse reflectance under "
            "uniform white light"
        },
        reconstruction=RECONSTRUCTION,
        terms=terms,
        extra={
            "rho": "1",
            "f0_factor": "none: f0 is the z axis (per-slice lutbake:slice_value)",
            "factoring_form": diffuse.f0_factor(model, ff),
            "sigma_alpha": json.dumps(
                [float(a) for a in diffuse.alpha_from_sigma(sig_axis.values(), o["sigma_to_alpha"])]
            ),
        },
    )
    if model == "microfacet":
        alpha = diffuse.alpha_from_sigma(sigma, o["sigma_to_alpha"])
        return diffuse_albedo.microfacet_albedo_plan(
            nov=nov, alpha=alpha, f0=f0, facet_fresnel=ff, order=order, **fields
        )
    key = (model, ff)

    def run(idx, n, device):
        idx = np.arange(len(nov))[idx]
        out = np.empty((len(idx), 1))
        for value in np.unique(f0[idx]):  # closed forms take one f0 per launch
            sel = f0[idx] == value
            out[sel, 0] = diffuse.albedo(
                model, nov[idx][sel], sigma[idx][sel], float(value), ff, o["sigma_to_alpha"], n, device=device
            )
        return out

    def error_estimate(data: np.ndarray, device: str) -> tuple[float, str]:
        idx = np.unique(
            np.concatenate(
                [np.arange(0, len(nov), max(1, len(nov) // 256)), np.flatnonzero(nov <= nov.min())[:: max(1, nz)]]
            )
        )
        err = float(np.max(np.abs(data[idx] - run(idx, order + 8, device))))
        return err, f"max |order {order} - order {order + 8}| over {len(idx)} probe texels"

    evals = 4 * order * order
    return Plan(
        n_texels=len(nov),
        n_channels=1,
        run_tile=lambda s, e, d: run(slice(s, e), order, d),
        prepare=lambda d: wp.load_module(diffuse.albedo_kernel_for(*key).module, device=d),
        samples=evals,
        estimator="gauss_legendre",
        cost=float(len(nov)) * evals,
        error_estimate=error_estimate,
        **fields,
    )


def check_spec(spec) -> str | None:
    o = spec.options
    n = o["size"][0] * o["size"][1] * o["f0_size"]
    if n > 1 << 26:
        return f"size x f0_size = {n} texels: at most {1 << 26}"
    return None


DIFFUSE_3D = Kind(
    "diffuse_3d",
    "diffuse AmbientBRDF with an f0 axis: NoV x sigma x f0 slices (R = E), for per-facet "
    "Fresnel forms where f0 does not factor out (exact dielectric, Eq. 2)",
    KEYS,
    plan,
    aliases=("ambient_brdf_diffuse_3d",),
    check=check_spec,
)
