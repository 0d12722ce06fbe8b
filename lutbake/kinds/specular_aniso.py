"""Kind ``specular_aniso``: split-sum tables of anisotropic lobes, NoV x roughness x anisotropy.

    E(NoV, r, a) = ∫ f(l, v) (n.l) dω_l,  f anisotropic: tangent T = +x, bitangent B = +y, n = +z,
stored as z slices over the anisotropy a (a multi-part EXR, one part per a, as specular_3d stores f0), with the
split-sum channels of ``dfg`` (Schlick F: scale/bias or multiscatter; the sheen and F82 layouts are not defined
for these lobes). The lobes and the anisotropy -> (alpha_x, alpha_y) mapping: lutbake.integrands.anisotropic;
the estimators: ``gauss_legendre`` (the default) with the view azimuth averaged, the panelled rule of
lutbake.sampling.hemisphere over the azimuth-averaged integrand of either lobe (lutbake.integrands.anisotropic.
averaged_integrand), to the tolerance with a per-texel estimate; ``sobol``, ``sobol_cosine`` (QMC,
lutbake.sampling.anisotropic) at a fixed view azimuth, without an estimate.

Key ``view_azimuth``: ``average`` (default) integrates the view azimuth out, E = (1/2 pi) ∫ E(phi_v) dphi_v, which
is what a shader looking up a 3D table without the azimuth should use (at a = 0 it is the isotropic table);
``tangent`` fixes phi_v = 0 (v in the T-n plane), ``bitangent`` phi_v = pi/2. Recorded in lutbake:view_azimuth.
"""

from __future__ import annotations

import numpy as np

from ..axes import Axis
from ..edge import alpha_policy
from ..records import ANISO_ESTIMATOR, ANISO_MODEL
from ..registry import choices
from ..runtime.plan import TexelPlan
from ..sampling.plan import Grid, per_texel_plan
from ..tolerance import tolerance_of
from . import dfg
from .base import Estimation, Key, declare

ANISO_LAYOUTS = ("scale_bias", "multiscatter")  # the dfg layouts an anisotropic table stores
AXES_FORMULA = (
    "aspect = sqrt(1 - 0.9 |a|); alpha_x = alpha / aspect, alpha_y = alpha * aspect (a >= 0; swapped for a < 0)"
)

VIEW_AZIMUTHS = {
    "average": "E averaged over the view azimuth phi_v in [0, 2 pi) (default)",
    "tangent": "phi_v = 0: v in the plane of the tangent and the normal",
    "bitangent": "phi_v = pi/2: v in the plane of the bitangent and the normal",
}
PHI_V = {"average": -1.0, "tangent": 0.0, "bitangent": 0.5 * np.pi}
AZIMUTH_RULES = {
    "microfacet": "inside the integrand: the lobe averaged over the tangent frame's orientation beta in [0, pi) by the "
    "periodic trapezoid rule, M = 16 alpha_max / alpha_min nodes rounded up to a power of two (<= 256; 1 when "
    "isotropic), its error estimated by |Q_M - Q_(M/2)| and added to each texel's estimate; the panels of the "
    "isotropic lobe at alpha_min (lutbake.integrands.anisotropic.averaged_integrand)",
    "ashikhmin_shirley": "inside the integrand, in closed form: the lobe's mean over the tangent frame's orientation "
    "beta, exp(log(n.h) min(nu, nv)) i0e(|log(n.h)| |nu - nv| / 2) (Abramowitz & Stegun 1964, Eq. 9.6.16; exact, no "
    "azimuth error); the panels of the isotropic lobe at alpha_min, split along n.l = n.v "
    "(lutbake.integrands.anisotropic.averaged_weight_ashikhmin_shirley)",
}

KEYS = {
    "model": Key("model", "str", "microfacet", "the anisotropic lobe", choices(ANISO_MODEL)),
    "layout": Key(
        "layout", "str", "scale_bias", "channel layout (Schlick split sum)", {k: dfg.LAYOUTS[k] for k in ANISO_LAYOUTS}
    ),
    **{k: dfg.KEYS[k] for k in ("size", "roughness", "texel", "nov_range", "roughness_range")},
    "anisotropy_size": Key("anisotropy_size", "int", 8, "anisotropy slice count (z)", minimum=1, maximum=1024),
    "anisotropy_range": Key(
        "anisotropy_range",
        "float_range",
        [0.0, 1.0],
        "anisotropy at t = 0 and t = 1 (same texel convention); a < 0 stretches along B",
        minimum=-1.0,
        maximum=1.0,
    ),
    "view_azimuth": Key("view_azimuth", "str", "average", "the view azimuth about n, from the tangent", VIEW_AZIMUTHS),
}
RECONSTRUCTION = {
    "scale_bias": "load part k as layer k of a 3D texture; t = texture(lut3d, vec3(NoV, roughness, anisotropy)).rg; "
    "specular = prefiltered * (f0 * t.r + t.g) (texel centres on all three axes)",
    "multiscatter": "t = texture(lut3d, vec3(NoV, roughness, anisotropy)).rg; E = mix(t.r, t.g, f0); "
    "energy compensation = 1 + f0 (1 / t.g - 1)",
}


def axes_for(o: dict) -> list[Axis]:
    return [Axis("anisotropy", "z", o["anisotropy_size"], *o["anisotropy_range"], texel=o["texel"])] + dfg.axes_for(o)


def panelled(o: dict) -> bool:
    """True where the table takes the panelled ``gauss_legendre`` rule: it is asked for (the default) and the view
    azimuth averaged (lutbake.integrands.anisotropic.averaged_integrand, either lobe); otherwise QMC (``sobol``): at a
    fixed view azimuth the lobe's azimuthal peak would sit on the panels' inner rule unaveraged."""
    return o["estimator"] == "gauss_legendre" and o["view_azimuth"] == "average"


def plan(spec) -> TexelPlan:
    from ..integrands.anisotropic import alpha_xy, aniso_integrand

    o = spec.options
    axes = axes_for(o)
    an_axis, rough, nov_axis = axes
    nx, ny, nz = nov_axis.count, rough.count, an_axis.count
    qmc = aniso_integrand(o["model"], o["layout"])
    # texel t = (iz * ny + iy) * nx + ix: anisotropy slowest, then roughness, then NoV
    nov = np.tile(nov_axis.values(), ny * nz)
    alpha = np.tile(np.repeat(rough.alpha(), nx), nz)
    ax, ay = alpha_xy(alpha, np.repeat(an_axis.values(), ny * nx), qmc.mirror)
    if panelled(o):
        from ..integrands.anisotropic import AVERAGED_NODES, averaged_integrand
        from ..sampling.anisotropic import AzimuthAveragedGaussLegendre
        from ..sampling.hemisphere import GaussLegendre

        integrand = averaged_integrand(o["model"], o["layout"])
        tol = tolerance_of(o)
        estimator = (
            GaussLegendre(o["samples"])
            if o["samples"]
            else AzimuthAveragedGaussLegendre(tol.absolute, tol.relative, azimuth_nodes=AVERAGED_NODES[o["model"]])
        )
        inputs = {"nov": nov, "alpha": np.minimum(ax, ay), "param": np.maximum(ax, ay)}
        how = {"view_azimuth_rule": AZIMUTH_RULES[o["model"]]}
    else:
        from ..sampling.anisotropic import AnisoSobol

        integrand = qmc
        estimator = AnisoSobol(
            "sobol_cosine" if o["estimator"] == "sobol_cosine" else "sobol",
            o["samples"] or AnisoSobol.budget,
            o["seed"],
        )
        inputs = {
            "nov": nov,
            "alpha_x": ax,
            "alpha_y": ay,
            "phi_v": np.full(len(nov), PHI_V[o["view_azimuth"]], np.float32),
        }
        how = {}
    terms = {
        "model": o["model"],
        "ndf": "ggx_aniso" if o["model"] == "microfacet" else "ashikhmin_shirley",
        "masking": "smith_height_correlated (anisotropic Lambda)"
        if o["model"] == "microfacet"
        else "none (implicit in the lobe)",
        "fresnel": "schlick",
        "layout": o["layout"],
    }
    return per_texel_plan(
        integrand,
        estimator,
        Grid(axes, inputs, grazing=nov),
        channels=dfg.CHANNELS[o["layout"]],
        reconstruction=RECONSTRUCTION[o["layout"]],
        terms=terms,
        extra={
            "view_azimuth": f"{o['view_azimuth']}: {VIEW_AZIMUTHS[o['view_azimuth']]}",
            "anisotropy_mapping": f"Burley 2012, Addenda B.2: {AXES_FORMULA}",
            "tangent_frame": "T = +x (phi = 0), B = +y, n = +z",
            "alpha_policy": alpha_policy(qmc.mirror),
            **how,
        },
        # QMC: no estimate recorded (two scramblings' spread is not a bound: docs/estimators.md)
        error_estimate=panelled(o),
    )


def texel_count(o: dict) -> int:
    """size x anisotropy_size"""
    return o["size"][0] * o["size"][1] * o["anisotropy_size"]


DESCRIPTION = (
    "anisotropic split-sum: NoV x roughness x anisotropy slices (anisotropic GGX or Ashikhmin-Shirley), "
    "scale/bias or multiscatter"
)
ESTIMATION = Estimation(choices(ANISO_ESTIMATOR), "gauss_legendre", dfg.SAMPLES_DOC)
SPECULAR_ANISO = declare("specular_aniso", DESCRIPTION, KEYS, plan, ESTIMATION, aliases=("aniso",), texels=texel_count)
