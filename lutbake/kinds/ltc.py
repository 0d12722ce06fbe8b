"""Kind ``ltc``: Linearly Transformed Cosine tables (Heitz et al. 2016) in selfshadow/ltc_code's layout.

Two RGBA textures, stored as the two z slices of one table (slice 0 = ltc_code's ltc_1, slice 1 = ltc_2):
    ltc_1 = (M^-1_00, M^-1_20, M^-1_02, M^-1_22) / M^-1_11   (the shader's mat3(vec3(x, 0, y), vec3(0, 1, 0),
                                                              vec3(z, 0, w)), columns)
    ltc_2 = (magnitude, fresnel, fit_error, sphere)
magnitude = ∫ f (n.l) dω with F = 1 and fresnel = ∫ f (1 - v.h)^5 (n.l) dω, both from lutbake's Gauss-Legendre
integrators (the ``albedo`` kind's kernel and the ``dfg`` multiscatter kernel: exact, not fitted); a shader
forms the Schlick-weighted magnitude f0 * magnitude + (1 - f0) * fresnel (ltc_code ltc_quad.fs:
spec *= scol * t2.x + (1 - scol) * t2.y). Lobes without Fresnel (charlie, lambert) store fresnel = magnitude,
so that mix is the magnitude for every f0. fit_error is Heitz's L3 error of the texel's fit, relative
(lutbake.ltc.fit; ltc_code leaves this channel 0 and no engine reads it; engine layouts write 0). sphere is
the horizon-clipped sphere/disk integral table (lutbake.ltc.sphere; its own axes, see below).

Axes (ltc_code fitLTC.cpp fitTab, read not guessed): x (columns) = roughness at endpoint texels a/(N - 1)
(alpha = r^2 for GGX / Beckmann; alpha = the value for charlie, whose axis is sheenRoughness); y (rows) =
t = sqrt(1 - cos theta_v) at endpoint texels t/(N - 1), theta_v <= 1.57 rad (NoV >= cos 1.57 = 7.96e-4).
Shaders sample uv = vec2(roughness, sqrt(1 - NoV)) * (N - 1)/N + 0.5/N. Differences from ltc_code, all recorded
in the metadata: alpha >= 1e-4 (lutbake.edge; ltc_code 1e-5), magnitude and fresnel integrated exactly
(ltc_code: 32^2 samples), every texel fitted independently from a coarse pass (ltc_code: chained).
Keys ``nov_mapping`` ("one_minus_t2", default: ltc_code's rows; "linear": NoV = t) and ``texel`` ("endpoint", default;
"center") change both axes' grid (Zeltner et al.'s sheen tables are linear in NoV; Babylon.js samples its fuzz table
at texel centres: preset ``babylon-fuzz``, format ``babylon_fuzz``, lutbake.layouts.babylon).
Key ``fit``: "l3" (default) as above; "shaded" refines the L3 fit's texels to the polygon-light integrals the shader
computes, magnitude and fresnel included (lutbake.ltc.shaded; docs/ltc_shaded.md).
The sphere channel's own axes: x = z * 0.5 + 0.5 (z = cos of the form-factor direction's elevation), y =
len = |form factor|, both endpoint (ltc_code genSphereTab).
"""

from __future__ import annotations

import numpy as np

from ..axes import MAPPINGS, TEXELS, Axis
from ..edge import ALPHA_MIN
from ..layouts.base import uv_of
from ..limits import LTC_FIT_GRID
from ..ltc.magnitude import MAGNITUDE_SAMPLES
from ..ltc.metadata import fit_error_stats, fit_record
from ..ltc.table import LtcBake
from ..records import LTC_LOBE
from ..registry import choices
from ..sampling.plan import TexelPlan
from ..tolerance import tolerance_of
from .base import Estimation, Key, declare

THETA_MAX = 1.57  # ltc_code fitTab: theta = min(1.57, acos(1 - x^2))
NOV_LO = float(np.cos(np.float32(THETA_MAX)))
FORMATS = {
    "exr": "OpenEXR, two parts (slice_0 = ltc_1, slice_1 = ltc_2), lutbake:* attributes (default)",
    "npy": "NumPy (2, N, N, 4) + .json sidecar",
    "ltc_dds": "ltc_code's two files <name>_1.dds, <name>_2.dds: RGBA16F (dtype half, as ltc_code) or RGBA32F",
    "js": "three.js ES module: LTC_MAT_1 / LTC_MAT_2 Float32Arrays as RectAreaLightTexturesLib's, .z of LTC_MAT_2 = 0",
    "c": "Blender EEVEE C arrays ltc_mat_<lobe>[N][N][4], ltc_mag_<lobe>[N][N][2], ltc_disk_integral[N][N][1]",
    "cs": "Unity HDRP C# table s_LtcMatrixData_BRDF_<LOBE> (ushort FP16 bits, one RGBA16F slice of _LtcData): "
    "(M^-1_00, M^-1_20, M^-1_11, M^-1_02) / M^-1_22",
    "babylon_ltc": "Babylon.js RectAreaLight's areaLightsLTC.bin: per texel ltc_1 RGBA then ltc_2 RGBA, always FP16 "
    "(Babylon uploads it as HALF_FLOAT)",
    "babylon_fuzz": "Babylon.js scene.environmentFuzzBRDFTexture: one DDS, RGBA16F (half) or RGBA32F, (A, B, R_i) of "
    "a normal-frame fit (lobe zeltner) coded by getFuzzBRDFLookup's mix() ranges (lutbake.layouts.babylon)",
}
ESTIMATORS = {
    "gauss_legendre": "the fit (Heitz's L3 metric, Nelder-Mead per texel: lutbake.ltc.fit) with magnitude and fresnel "
    "by Gauss-Legendre (default)",
    "sobol_ndf": "the same fit with magnitude and fresnel by scrambled Sobol' points, NDF importance sampling (a "
    "second, independent estimator of the integrals the fit depends on; ggx and beckmann)",
}
KEYS = {
    "lobe": Key("lobe", "str", "ggx", "the lobe fitted", choices(LTC_LOBE)),
    "size": Key("size", "int_pair", [64, 64], "[view, roughness] texel counts (ltc_code: 64 x 64)", minimum=2),
    "fit_samples": Key(
        "fit_samples",
        "int",
        LTC_FIT_GRID,
        "N: the error metric's N x N stratified grid per sampling technique (ltc_code Nsample = 32)",
        minimum=4,
        maximum=256,
    ),
    "alpha_min": Key(
        "alpha_min",
        "float",
        ALPHA_MIN,
        "smallest NDF alpha fitted (lutbake's edge policy: 1e-4; Unity HDRP's own fit: 1e-3)",
        minimum=ALPHA_MIN,
        maximum=0.1,
    ),
    "fit": Key(
        "fit",
        "str",
        "l3",
        "what the fit minimises",
        {
            "l3": "Heitz et al. 2016's L3 distance to the lobe (ltc_code's fit); magnitude and fresnel the exact "
            "integrals",
            "shaded": "the l3 fit refined to the polygon-light integrals the shader computes (lutbake.ltc.shaded): "
            "matrix, magnitude and fresnel fitted to the lobe's integrals over training lights",
        },
    ),
    "fit_f0_weight": Key(
        "fit_f0_weight",
        "float",
        0.7,
        "shaded fit, lobes with Fresnel: weight of the dielectric (f0 = 0.04) shading errors beside F = 1 (0: F = 1 "
        "alone; one matrix serves every f0)",
        minimum=0.0,
        maximum=1.0,
    ),
    "magnitude": Key(
        "magnitude",
        "str",
        "fitted",
        "the magnitude the shaded fit pairs with its matrix",
        {
            "fitted": "fitted with the matrix (ltc_2.x; the shader multiplies by it)",
            "albedo": "the lobe's albedo, fixed (for shaders that take the magnitude from another table, e.g. Unity "
            "HDRP's PreIntegratedFGD)",
        },
    ),
    "nov_mapping": Key(
        "nov_mapping",
        "str",
        "one_minus_t2",
        "how t maps to NoV on the rows (y)",
        {
            "one_minus_t2": MAPPINGS["one_minus_t2"] + "; ltc_code's t = sqrt(1 - cos theta_v) (default)",
            "linear": MAPPINGS["linear"] + " (Zeltner et al.'s sheen tables, Babylon.js's fuzz table)",
        },
    ),
    "texel": Key(
        "texel",
        "str",
        "endpoint",
        "texel convention of both axes (the NoV rows and the roughness columns)",
        {"endpoint": TEXELS["endpoint"] + " (ltc_code; default)", "center": TEXELS["center"] + " (Babylon.js)"},
    ),
    "format": Key("format", "str", "exr", "output file format", FORMATS),
}
RECONSTRUCTION = (  # {uv}: lutbake.layouts.base.uv_of of the table's [NoV, roughness] axes
    "{uv}; t1 = texture(ltc_1, uv); t2 = texture(ltc_2, uv); "
    "Minv = mat3(vec3(t1.x, 0, t1.y), vec3(0, 1, 0), vec3(t1.z, 0, t1.w)); in the frame (T1, T2, N), "
    "T1 = normalize(V - N NoV): polygon integral I = 1/(2 pi) Σ edges acos(v_i.v_j) normalize(v_i x v_j).z of the "
    "clipped, normalised vertices Minv p_i; specular = light * I * (f0 * t2.x + (1 - f0) * t2.y); "
    "sphere/disk: I = len * texture(ltc_2, vec2(z * 0.5 + 0.5, len) * (N - 1)/N + 0.5/N).w for the vector "
    "form factor F (len = |F|, z = F.z / len)"
)
CHANNELS = {
    "x": "slice 0 (ltc_1): M^-1_00 / M^-1_11; slice 1 (ltc_2): magnitude = ∫ f (n.l) dω_l with F = 1 (fit = shaded: "
    "fitted with the matrix)",
    "y": "slice 0: M^-1_20 / M^-1_11 (glm invM[0][2]); slice 1: fresnel = ∫ f (1 - v.h)^5 (n.l) dω_l "
    "(= magnitude for lobes without Fresnel)",
    "z": "slice 0: M^-1_02 / M^-1_11 (glm invM[2][0]); slice 1: fit_error = (E / ∫ f^3 dω)^(1/3), E = Heitz's L3 "
    "metric of the fit (0 in engine layouts)",
    "w": "slice 0: M^-1_22 / M^-1_11; slice 1: sphere = horizon-clipped / unclipped form factor of a spherical cap, "
    "at x = z * 0.5 + 0.5, y = len (own axes, endpoint texels)",
}


def axes_for(o: dict, lb=None) -> list[Axis]:
    """[texture slice, NoV, roughness] axes of an ltc table fitting the Lobe ``lb`` (its roughness names the x axis;
    None: lutbake's lobe named by ``o["lobe"]``, for host helpers and tests)."""
    from ..ltc.lobes import lobe

    n_view, n_rough = o["size"]
    lb = lobe(lb if lb is not None else o["lobe"])
    rname = {"alpha": "alpha", "sigma": "sigma", "diffuse_roughness": "diffuse_roughness"}.get(
        lb.roughness, "perceptual_roughness"
    )
    amap = "sigma" if lb.roughness == "sigma" else None  # Gotanda's sigma: GGX alpha = sigma (docs/diffuse.md)
    texel = o.get("texel", "endpoint")
    return [
        Axis("texture", "z", 2, 1.0, 2.0, texel="endpoint", mapping="listed", listed=(1.0, 2.0)),
        Axis(
            "NoV", "y", n_view, 0.0, 1.0, texel=texel, mapping=o.get("nov_mapping", "one_minus_t2"), clamp=(NOV_LO, 1.0)
        ),
        Axis(rname, "x", n_rough, 0.0, 1.0, texel=texel, alpha_map=amap),
    ]


def plan(spec) -> TexelPlan:
    o = spec.options
    lb = spec.records["lobe"].obj
    axes = axes_for(o, lb)
    state = LtcBake(o, axes, lb, tolerance_of(o))
    n = axes[1].count * axes[2].count
    m_samples = 0 if lb.magnitude in ("lambert", "lobe", "lobe_adaptive") else o["samples"]
    if o["estimator"] == "gauss_legendre" and not m_samples:
        m_samples = MAGNITUDE_SAMPLES.get(o["lobe"])
    terms = {
        "lobe": o["lobe"],
        "description": spec.records["lobe"].description,
        "fresnel": "schlick (1 - v.h)^5 channel"
        if lb.magnitude.startswith("dfg:") and lb.name != "charlie"
        else "none (fresnel channel = magnitude)",
        "layout": "ltc_code (selfshadow/ltc_code fit/fitLTC.cpp packTab)",
    }
    extra = {
        "ltc_fit": fit_record(o, lb, m_samples, THETA_MAX),
        "ltc_texture_slices": "slice_0 = ltc_1 (inverse matrix), slice_1 = ltc_2 (magnitude, fresnel, fit_error, "
        "sphere)",
    }
    return TexelPlan(
        axes=axes,
        channels=CHANNELS,
        reconstruction=RECONSTRUCTION.format(uv=uv_of(axes[1:])),  # uv of the (NoV, roughness) axes
        n_texels=2 * n,
        n_channels=4,
        run_tile=state.run_tile,
        prepare=state.prepare,
        samples=2 * o["fit_samples"] ** 2,
        estimator=f"ltc_fit (magnitude: {o['estimator']})",
        terms=terms,
        cost=float(n) * 300 * 2 * o["fit_samples"] ** 2,
        extra=extra,
        attributes_after=lambda data: {**fit_error_stats(data), **state.magnitude_attributes()},
    )


def check_spec(spec):
    o = spec.options
    lb = spec.records["lobe"].obj
    if o["estimator"] != "gauss_legendre" and lb.magnitude not in ("dfg:ggx", "dfg:beckmann"):
        return (
            "estimator",
            f"estimator {o['estimator']!r} samples the GGX / Beckmann NDF: lobe {o['lobe']!r} needs 'gauss_legendre'",
        )
    if lb.magnitude.startswith("diffuse:") and o["samples"] is not None and o["samples"] > 64:
        return ("samples", f"lobe {o['lobe']!r}: samples is the diffuse kind's Gauss-Legendre order, at most 64")
    if o["format"] in ("ltc_dds", "babylon_fuzz") and o["dtype"] not in ("half", "float32"):
        return ("dtype", f"{o['format']} writes RGBA16F (half) or RGBA32F (float32)")
    if o["format"] == "babylon_fuzz" and not lb.normal_frame:
        normal = ", ".join(r.name for r in LTC_LOBE if r.obj.normal_frame)
        return (
            "format",
            f"babylon_fuzz stores M^-1 = [[A, 0, B], [0, A, 0], [0, 0, 1]] in the normal's frame: lobe {o['lobe']!r} "
            f"is not fitted so (normal-frame lobes: {normal})",
        )
    return None


def texel_count(o: dict) -> int:
    """2 x size (two texture slices)"""
    return 2 * o["size"][0] * o["size"][1]


ESTIMATION = Estimation(
    ESTIMATORS,
    "gauss_legendre",
    "Gauss-Legendre budget of the magnitude / fresnel integrals per texel; "
    "omitted: 432 (ggx, beckmann), 3072 (charlie); gotanda, eon: the diffuse kind's GL order (omitted: its default)",
    samples_min=12,
    samples_max=1 << 20,
)
LTC = declare(
    "ltc",
    "Linearly Transformed Cosine fit (Heitz et al. 2016): ltc_code's two RGBA textures "
    "(inverse matrix; magnitude, fresnel, fit error, sphere integral)",
    KEYS,
    plan,
    ESTIMATION,
    aliases=("ltc_fit",),
    check=check_spec,
    texels=texel_count,
    layout_keys=("format", "dtype"),  # the fit reads neither (no storage-derived tolerance): engine layouts share it
)
