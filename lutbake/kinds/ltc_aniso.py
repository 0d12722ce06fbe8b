"""Kind ``ltc_aniso``: LTC tables of anisotropic GGX for area lights (Kt, Heitz, Dupuy & Narayanan 2022, "Bringing
Linearly Transformed Cosines to Anisotropic GGX", I3D; github AakashKT/LTC-Anisotropic), over the paper's 4D domain.

Texels: the paper's (a, b, theta_v, phi_v), N per axis (the paper: 8), endpoint texels: theta_v = k/(N-1) 0.9999
pi/2, phi_v = l/(N-1) pi/2 (the view azimuth from the tangent T; the other quadrants by reflections), and
- ``alphax_alphay``: alpha_x = max(i/(N-1), 1e-4), alpha_y = max(j/(N-1), 1e-4) (the paper's Sec. 4 table);
- ``alpha_anisotropy``: the paper's alpha x lambda table, alpha_x = max(a, 1e-4), alpha_y = max(a lambda, 1e-4),
  a = i/(N-1), lambda = j/(N-1) (alpha_y <= alpha_x; a shader swaps x and y where alpha_y > alpha_x).
Per texel the LTC matrix M (clamped cosine -> lobe) in the tangent frame (T = +x, B = +y, n = +z), |M e_z| = 1, fitted
to Heitz et al. 2016's L3 distance with a general matrix (lutbake.ltc.aniso: the lobe, the symmetries, the fit);
magnitude = ∫ f (n.l) dω with F = 1 and fresnel = ∫ f (1 - v.h)^5 (n.l) dω.

Stored as lutbake.ltc.aniso.texture_layout's three RGBA 3D textures of width N (phi), height N (theta) and depth N^2
(layer = b + N a: the 4th axis packed into the depth, as the paper's Tex3D path): the table's z axis is the texture
(t0, t1, t2), its rows the layers' theta rows stacked (y_block = layer, y = theta), its columns phi. So each z slice
(an EXR part; npy [k]) is one 3D texture's bytes in glTexImage3D order. ``format = "ktx2"`` / ``"dds"`` write the
three textures as 3D texture files <name>_t0, _t1, _t2 (lutbake.io.ltc_aniso_textures), the same bytes;
``format = "ltc_aniso_npy"`` the paper's own layout instead: M as (N, N, N, N, 3, 3) float32 (its LUT/*.npy; no
magnitude, as the paper's; lutbake.io.ltc.write_ltc_aniso_npy). The shader: docs/shaders/ltc_aniso.glsl.
``lobes = 2`` or ``3`` (fit shaded only; not ltc_aniso_npy): K LTCs per texel, value = Σ_k w_k I(M_k), fitted per
texel and between the texels (three split from two; lutbake.ltc.aniso_lobes), as 3 K textures: (t0, t1, t2) lobe 1's,
(t3, t4, t5) lobe 2's, (t6, t7, t8) lobe 3's, each set a one-lobe table's layout with t2 = (M22, w_k,
w_k fresnel / magnitude, sum_error).
"""

from __future__ import annotations

import json

import numpy as np

from ..axes import Axis
from ..io.file_sets import MAX_LOBES
from ..io.ltc_aniso_textures import texture_names
from ..limits import LTC_FIT_GRID
from ..ltc import aniso_grid as aniso
from ..ltc.aniso_grid import ALPHA_FLOOR
from ..ltc.metadata import L3_METRIC, fit_error_stats
from ..runtime.plan import TexelPlan
from .base import Estimation, Key, declare

PARAMETRISATIONS = {  # key value -> (lutbake.ltc.aniso.Grid4's name, what it means)
    "alphax_alphay": ("alphax_alphay", aniso.PARAMETRISATIONS["alphax_alphay"]),
    "alpha_anisotropy": ("alpha_lambda", aniso.PARAMETRISATIONS["alpha_lambda"] + " (the paper's alpha x lambda)"),
}
FORMATS = {
    "exr": "OpenEXR, three parts (t0, t1, t2), each one 3D texture with its N^2 layers' N theta rows stacked "
    "(row = layer N + theta index), lutbake:* attributes (default)",
    "npy": "NumPy (3, N^3, N, 4) = (texture, layer x theta, phi, RGBA) + .json sidecar: [k].reshape(N^2, N, N, 4) "
    "is texture k's (depth, height, width, RGBA)",
    "ltc_aniso_npy": "the paper's layout (AakashKT/LTC-Anisotropic LUT/*.npy): M[a, b, theta, phi] (N, N, N, N, 3, 3) "
    "float32 + .json sidecar; no magnitude (the paper's renderer reads it from another table: use exr / npy)",
    "ktx2": "three KTX 2.0 3D textures <name>_t0.ktx2, _t1.ktx2, _t2.ktx2 (pixelDepth N^2, "
    "VK_FORMAT_R16G16B16A16_SFLOAT / R32G32B32A32_SFLOAT, each file's record in its key/value data) + the sidecar "
    "<name>_t0.ktx2.json naming the sha256 of all three (lutbake.io.ltc_aniso_textures)",
    "dds": "three DDS volume textures <name>_t0.dds, _t1.dds, _t2.dds (DX10, TEXTURE3D, depth N^2, "
    "DXGI_FORMAT_R16G16B16A16_FLOAT / R32G32B32A32_FLOAT) + the sidecar <name>_t0.dds.json naming the sha256 of all "
    "three",
}
ESTIMATORS = {
    "sobol": "magnitude and fresnel of anisotropic texels by scrambled Sobol' points at the texel's view azimuth "
    "(the specular_aniso kind's integrand and QMC estimator: anisotropic VNDF sampling, weight G2 / G1 <= 1); "
    "isotropic texels (alpha_x = alpha_y) by the ltc kind's Gauss-Legendre rule (exact)",
    "sobol_cosine": "the same with the anisotropic texels by scrambled Sobol' points of cosine-weighted l (the "
    "specular_aniso kind's sobol_cosine: independent of the lobe's sampler, a cross-check; noisy for sharp lobes)",
}
KEYS = {
    "parametrisation": Key(
        "parametrisation",
        "str",
        "alphax_alphay",
        "the (a, b) axes of the 4D table (the paper's two tables)",
        {k: v[1] for k, v in PARAMETRISATIONS.items()},
    ),
    "size": Key(
        "size",
        "int",
        8,
        "N: texels per axis (a, b, theta_v, phi_v), endpoint texels (the paper: 8)",
        minimum=2,
    ),
    "alpha_min": Key(
        "alpha_min",
        "float",
        ALPHA_FLOOR,
        "alpha_x, alpha_y = max(axis value, alpha_min) (the paper: 1e-4)",
        minimum=ALPHA_FLOOR,
        maximum=0.5,
    ),
    "fit_frame": Key("fit_frame", "str", "free", "the LTC's frame in the fit (lutbake.ltc.aniso)", aniso.FRAMES),
    "fit_samples": Key(
        "fit_samples",
        "int",
        LTC_FIT_GRID,
        "N: the L3 metric's N x N stratified grid per sampling technique (ltc_code Nsample = 32)",
        minimum=4,
        maximum=256,
    ),
    "fit": Key(
        "fit",
        "str",
        "l3",
        "what the fit minimises",
        {
            "l3": "Heitz et al. 2016's L3 distance to the lobe (at alpha_x = alpha_y: lutbake's isotropic L3 fit)",
            "shaded": "the l3 fit refined to the polygon-light integrals the shader computes, the magnitude kept "
            "exact (lutbake.ltc.aniso_shaded: Levenberg-Marquardt in the 9 coefficients of M^-1 over 128 training "
            "lights per texel)",
        },
    ),
    "lobes": Key(
        "lobes",
        "int",
        1,
        "LTCs per texel: 1, 2 or 3 (a sum Σ_k w_k I(M_k), 3 K textures, K polygon integrals in the shader; "
        "fit = 'shaded' only, not format ltc_aniso_npy; three: the two-lobe table's narrow lobe split in two and "
        "refitted; lutbake.ltc.aniso_lobes)",
        minimum=1,
        maximum=MAX_LOBES,
    ),
    "between_configs": Key(
        "between_configs",
        "int",
        aniso.BETWEEN_CONFIGS,
        "lobes >= 2: training configurations (uniform in table coordinates) of the fit between the texels",
        minimum=16,
        maximum=100000,
    ),
    "between_iterations": Key(
        "between_iterations",
        "int",
        aniso.BETWEEN_ITERATIONS,
        "lobes >= 2: Levenberg-Marquardt steps of the fit between the texels (0: each texel fitted at itself only; "
        "three lobes: as many again after the split)",
        minimum=0,
        maximum=200,
    ),
    "format": Key("format", "str", "exr", "output file format", FORMATS),
}
SHADED = (
    "each fitted texel's M^-1 (9 coefficients, view frame) refined by Levenberg-Marquardt to the soft-L1 of (magnitude "
    "I_j - G_j) / (G_j + 0.4 albedo) over 128 training lights (lutbake.ltc.shaded's lights, cost and lobe-sampled "
    "targets; lutbake.ltc.aniso_shaded), the magnitude the exact albedo; fit_error = the refined M's L3 error"
)
CHANNELS = {
    "x": "t0: M00; t1: M11; t2: M22 (M row-major, tangent frame, |M e_z| = 1)",
    "y": "t0: M01; t1: M12; t2: magnitude = ∫ f (n.l) dω_l with F = 1",
    "z": "t0: M02; t1: M20; t2: fresnel = ∫ f (1 - v.h)^5 (n.l) dω_l",
    "w": "t0: M10; t1: M21; t2: fit_error = (E / ∫ f^3 dω)^(1/3), E = Heitz's L3 metric of the texel's fit",
}


def lobes_channels(lobes: int) -> dict[str, str]:
    """The channels of a table of ``lobes`` > 1: lobe k's set t(3k-3), t(3k-2), t(3k-1) (lutbake.ltc.aniso_lobes)."""
    t0, t1, t2 = ("/".join(f"t{3 * k + i}" for k in range(lobes)) for i in range(3))
    return {
        "x": f"{t0}: M00; {t1}: M11; {t2}: M22 (lobe k's M row-major, tangent frame, as the between fit leaves it: not "
        "scaled to |M e_z| = 1)",
        "y": f"{t0}: M01; {t1}: M12; {t2}: weight w_k (value = Σ_k w_k I(M_k) with F = 1)",
        "z": f"{t0}: M02; {t1}: M20; {t2}: weight_fresnel = w_k fresnel / magnitude (the lobe's Schlick part)",
        "w": f"{t0}: M10; {t1}: M21; {t2}: sum_error = the sum's relative RMS shaded residual at the texel over its "
        "137 lights (lutbake.ltc.aniso_lobes.sum_error; the same in every set)",
    }


SUM_ERROR_METRIC = (
    "sqrt(mean_j z_j^2), z_j = (Σ_k w_k I_j(M_k) - G_j) / (G_j + 0.4 magnitude) over the texel's 128 training lights "
    "and 9 hemisphere lights, G_j from 48^2 lobe samples, at the texel itself (lutbake.ltc.aniso_lobes.sum_error)"
)
LOBES_FIT = (
    "two lobes (lutbake.ltc.aniso_lobes): each fitted texel's sum w_1 I(M_1) + w_2 I(M_2) by Levenberg-Marquardt "
    "(40 steps) to the shaded cost over 128 training lights + 9 hemisphere lights, targets from 128^2 lobe samples, "
    "from the shaded M (lobe 2 broadened twice, weights 0.8 / 0.2 albedo), the other texels by the symmetries; then "
    "every texel's 2 x (M, w) fitted between the texels: the interpolated sum's shaded cost at {configs} "
    "configurations uniform in table coordinates x (32 lights + 9 hemisphere lights), + 0.001 mean(diag J^T J) "
    "|x - x0|^2 towards the per-texel table, {iterations} Levenberg-Marquardt steps"
)
SPLIT_FIT = (
    "; three lobes: the narrow lobe split into M_1 diag({0:g}, {0:g}, 1) (lobe 1) and M_1 diag({1:g}, {1:g}, 1) (lobe "
    "3), half its weight each, then the three lobes fitted between the texels as above ({iterations} steps)"
)
RECONSTRUCTION = (
    "docs/shaders/ltc_aniso.glsl lutbake_ltc_aniso_specular(t0, t1, t2, N, T, V, alpha_x, alpha_y, f0, p, Li, "
    "two_sided): slice k = a sampler3D of width N (phi_v / (pi/2)), height N (theta_v / (0.9999 pi/2)), depth N^2 "
    "(layer = b + N a), linear filtering, clamp to edge; the hardware interpolates phi, theta and b, a between two "
    "fetches (quadrilinear M, as the paper's); phi_v folded into [0, pi/2] by the reflections diag(-1, 1, 1), "
    "diag(-1, -1, 1), diag(1, -1, 1) of M, the polygon's orientation from sign(det M); specular = Li I (f0 t2.y + "
    "(1 - f0) t2.z)"
)


LOBES_RECONSTRUCTION = (
    "docs/shaders/ltc_aniso.glsl lutbake_ltc_aniso_specular_two_lobes(t0, t1, t2, t3, t4, t5, N, T, V, alpha_x, "
    "alpha_y, f0, p, Li, two_sided) = lutbake_ltc_aniso_specular on (t0, t1, t2) + on (t3, t4, t5) (three lobes: "
    "lutbake_ltc_aniso_specular_three_lobes, + on (t6, t7, t8)): each set as the one-lobe table's (its M, t2.y = w_k, "
    "t2.z = w_k fresnel / magnitude: specular = Σ_k Li I_k (f0 t2.y + (1 - f0) t2.z))"
)


def grid_of(o: dict) -> aniso.Grid4:
    n = o["size"]
    return aniso.Grid4(PARAMETRISATIONS[o["parametrisation"]][0], (n, n, n, n), o["alpha_min"])


def axes_for(o: dict) -> list[Axis]:
    """[texture (z), layer (y_block), theta_v (y), phi_v (x)]: the textures' texel order."""
    n, count = o["size"], 3 * o.get("lobes", 1)
    return [
        Axis(
            "texture",
            "z",
            count,
            0.0,
            float(count - 1),
            texel="endpoint",
            mapping="listed",
            listed=tuple(float(k) for k in range(count)),
        ),
        Axis("layer", "y_block", n * n, 0.0, float(n * n - 1), texel="endpoint"),
        Axis("theta_v", "y", n, 0.0, aniso.THETA_SCALE * np.pi / 2, texel="endpoint"),
        Axis("phi_v", "x", n, 0.0, np.pi / 2, texel="endpoint"),
    ]


def plan(spec) -> TexelPlan:
    from ..ltc.aniso_table import AnisoBake

    o = spec.options
    g = grid_of(o)
    samples = o["samples"] or aniso.MAGNITUDE_SAMPLES
    state = AnisoBake(
        g,
        o["fit_frame"],
        o["fit_samples"],
        samples,
        o["seed"],
        o["fit"] == "shaded",
        o["estimator"],
        o["lobes"],
        (o["between_configs"], o["between_iterations"]),
    )
    several = o["lobes"] > 1
    a, b, _, _ = g.axes()
    n = o["size"]
    n_fit = len(aniso.fitted_texels(g))
    extra = {
        "ltc_aniso_parametrisation": f"{o['parametrisation']}: {PARAMETRISATIONS[o['parametrisation']][1]}",
        "ltc_aniso_layer": f"layer = b + {n} a (a, b the parametrisation's first two indices; the y_block axis): "
        f"a = b = i / {n - 1}, a in {[round(float(x), 6) for x in a]}",
        "ltc_aniso_textures": ", ".join(
            f"slice {k} = {t} ({', '.join(ch)})" for k, (t, ch) in enumerate(texture_names(3 * o["lobes"]).items())
        )
        + "; each a 3D texture (width phi, height theta, depth layer)",
        "ltc_aniso_conventions": "M maps the clamped cosine to the lobe (w = M w_o / |M w_o|), tangent frame T = +x, "
        "B = +y, n = +z, |M e_z| = 1, M R_z chosen closest to the identity (lutbake.ltc.aniso.canonical); "
        "v = (sin theta cos phi, sin theta sin phi, cos theta); phi in the other quadrants: M(pi - phi) = "
        "diag(-1, 1, 1) M(phi), M(phi + pi) = diag(-1, -1, 1) M(phi), M(-phi) = diag(1, -1, 1) M(phi)",
        "ltc_aniso_symmetries": f"{n_fit} of {n**4} texels fitted: alpha_x >= alpha_y (the others S M S at "
        "(alpha_y, alpha_x, pi/2 - phi), S = swap(x, y)), phi = 0 alone at theta = 0 (the tangent-frame M) and "
        "at alpha_x = alpha_y (the view-frame M, turned by R_z(phi))",
        "ltc_aniso_fit": f"L3 (Heitz et al. 2016) by Nelder-Mead per texel, frame {o['fit_frame']!r}: "
        f"{aniso.FRAMES[o['fit_frame']]}; metric grid {o['fit_samples']}^2 per technique; lutbake.ltc.aniso.fit_tile"
        + ("" if o["fit"] == "l3" else f"; then shaded: {SHADED}")
        + (
            f"; then {LOBES_FIT.format(configs=o['between_configs'], iterations=o['between_iterations'])}"
            + (SPLIT_FIT.format(*aniso.SPLIT, iterations=o["between_iterations"]) if o["lobes"] == 3 else "")
            if several
            else ""
        ),
        "ltc_aniso_magnitude": f"{o['estimator']}: {ESTIMATORS[o['estimator']]}; {samples} points per anisotropic "
        f"texel, seed {o['seed']} (the spread between two scramblings: lutbake:ltc_aniso_magnitude_spread, an "
        "estimate, not a bound, ~1e-5 at 2^16 with sobol). Not Gauss-Legendre: the specular_aniso kind's rule is "
        "azimuth-averaged only (at a fixed view azimuth the lobe's ridge at alpha_y << alpha_x falls between the "
        "panels' nodes)",
        "ltc_aniso_shader": LOBES_RECONSTRUCTION if several else RECONSTRUCTION,
    }
    if several:
        sets = ", ".join(f"t{3 * k}, t{3 * k + 1}, t{3 * k + 2} lobe {k + 1}'s" for k in range(o["lobes"]))
        extra["ltc_aniso_lobes"] = (
            f"{o['lobes']}: value = Σ_k w_k I(M_k); textures {sets}, each set laid out as a one-lobe table's with its "
            "third texture = (M22, w_k, w_k fresnel / magnitude, sum_error)"
        )
    return TexelPlan(
        axes=axes_for(o),
        channels=lobes_channels(o["lobes"]) if several else CHANNELS,
        reconstruction=LOBES_RECONSTRUCTION if several else RECONSTRUCTION,
        n_texels=texel_count(o),
        n_channels=4,
        run_tile=state.run_tile,
        prepare=state.prepare,
        samples=1 << int(np.ceil(np.log2(samples))),  # the magnitude's Sobol' points (a power of two)
        estimator=f"ltc_aniso_fit (magnitude: {o['estimator']})",
        terms={
            "lobe": "ggx_aniso: D_ggx_aniso (Heitz 2014 Eq. 85) G2 height-correlated Smith, anisotropic Lambda "
            "(Eqs. 86, 99), F = 1 (Schlick: the fresnel channel)",
            "layout": "lutbake 3D textures (docs/shaders/ltc_aniso.glsl); the paper's: format ltc_aniso_npy",
            "parametrisation": o["parametrisation"],
        },
        cost=float(n_fit) * 300 * 2 * o["fit_samples"] ** 2
        + float(n**4) * samples
        # two lobes: 40 steps x 137 lights x 20 unknowns per fitted texel; per between step ~30 integrals per light
        # (three lobes: the between fit again, ~45 integrals per light)
        + several * (float(n_fit) * 40 * 137 * 20 + o["between_configs"] * o["between_iterations"] * 41 * 30)
        + (o["lobes"] == 3) * o["between_configs"] * o["between_iterations"] * 41 * 45,
        extra=extra,
        attributes_after=lambda data: {
            **fit_error_stats(data, (2, 3), SUM_ERROR_METRIC if several else L3_METRIC),
            "ltc_aniso_magnitude_spread": json.dumps(state.spread),
        },
    )


def check_spec(spec):
    o = spec.options
    k = o["lobes"]
    if k > 1 and o["fit"] != "shaded":
        return (
            "fit",
            f"lobes = {k} starts from the shaded one-lobe fit: fit 'shaded' (allowed with lobes = {k}: shaded)",
        )
    if k > 1 and o["format"] == "ltc_aniso_npy":
        return (
            "format",
            f"ltc_aniso_npy is the paper's layout of one M per texel, no room for lobes = {k}: format exr, npy, ktx2 "
            f"or dds (lobes = {k} writes {3 * k} textures)",
        )
    if spec.options["format"] == "ltc_aniso_npy" and spec.options["dtype"] != "float32":
        return ("dtype", "ltc_aniso_npy is the paper's float32 array: dtype 'float32'")
    return None


def texel_count(o: dict) -> int:
    """3 x lobes x size^4 (three textures per lobe)"""
    return 3 * o.get("lobes", 1) * o["size"] ** 4


ESTIMATION = Estimation(
    ESTIMATORS,
    "sobol",
    "Sobol' points per anisotropic texel for magnitude and fresnel (omitted: 2^16 = 65536); isotropic texels: exact",
    samples_min=256,
    samples_max=1 << 20,
)
LTC_ANISO = declare(
    "ltc_aniso",
    "Linearly Transformed Cosines of anisotropic GGX (Kt et al. 2022): 4D table (a, b, theta, phi) as three RGBA "
    "3D textures (M; magnitude, fresnel, fit error)",
    KEYS,
    plan,
    ESTIMATION,
    check=check_spec,
    texels=texel_count,
    layout_keys=("format", "dtype"),
)
