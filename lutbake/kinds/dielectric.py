"""Kinds ``dielectric`` and ``dielectric_avg``: energy tables of the rough dielectric BSDF (Walter, Marschner, Li &
Torrance 2007, "Microfacet models for refraction through rough surfaces") over the relative index of refraction.

    E_R(mu, r, eta) = ∫ f_r |n.o| dω_o over the incident side,   E_T(mu, r, eta) = ∫ f_t |n.o| dω_o over the other side
    E_avg(r, eta)   = 2 ∫_0^1 E(mu) mu dmu   (kind dielectric_avg; panels split at
                                             mu = 0.2 and at cos theta_c for eta < 1)
eta = eta_o / eta_i is the relative IOR seen from the view's side: eta > 1 outside a denser medium, eta < 1 inside it
(total internal reflection past the critical angle). The integrands are lutbake.integrands.dielectric, the default
quadrature lutbake.sampling.dielectric (panelled Gauss-Legendre split at every kink; kind dielectric to the
tolerance, kind dielectric_avg at a fixed order); docs/transmission.md has the
derivation and the measured accuracy, docs/glass-layouts.md every engine's conventions.

Layouts (key ``layout``) fix the channels, and for the engine layouts the whole grid:
    energy      z = IOR slices (ior_size, ior_range, ior_mapping), y/x = roughness / NoV as the dfg kind;
                R = E_R, G = E_T, B = E_R + E_T (exact Fresnel)
    eevee_btdf  Blender EEVEE's btdf_ggx[16][64][64][1] (eevee_lut_comp.glsl ggx_btdf_gt_one): z = perceptual roughness
                k/15, y = sqrt(1 - NoV) (NoV clamped to [1e-4, 0.9999]), x = sqrt((eta - 1)/(eta + 1))
                (its square clamped
                to [1e-4, 0.9999]); all endpoint texels; R = transmission_factor with Schlick s = (1 - v.h)^5
    eevee_bsdf  Blender EEVEE's bsdf_ggx[16][64][64][3] (ggx_bsdf_split_sum, eta < 1): z = roughness k/15,
                x = eta^2 (eta clamped to [1e-4, 0.9999]), y centred on the critical angle: with c = sqrt(1 - eta^2),
                y' = 2y - 1, NoV = clamp(c + y' (y' > 0 ? 1 - c : c), 1e-4, 0.9999); R = scale, G = bias,
                B = transmission_factor with s = (1 - |t.h|)^5 (t refracted; s = 1 under TIR)
    openpbr     adobe/openpbr-bsdf's [ior][alpha][cos] 32^3 tables: z = IOR (indices 0-15: 1/eta = 1 + 1.5 (15 - i)/15,
                16-31: eta = 1 + 1.5 (i - 16)/15), y = sqrt(alpha) = i/31, x = cos theta = i/31 (0 clamped to NOV_MIN);
                R = 1 - (E_R + E_T) (IdealDielectricEnergyComplement), G = 1 - E_R (OpaqueDielectricEnergyComplement),
                B = 1 - E(F = 1) (IdealMetalEnergyComplement, the same in every IOR slice); kind dielectric_avg:
                the three averages and A = OpenPBR's IdealDielectricReflectionRatio (lutbake.kinds.dielectric_ratio,
                from the averages of both sides of the interface: row z and its mirror row 31 - z, eta -> 1/eta)
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, replace

import numpy as np

from ..axes import Axis
from ..catalog import DIELECTRIC_MASKINGS, HEMISPHERE_ESTIMATORS, MASKINGS, NDF_DESCRIPTIONS, SMITH_NDFS, VNDF_NDFS
from ..edge import ALPHA_MIN, alpha_policy
from ..runtime.memo import RowMemo
from ..sampling import points
from ..sampling.mu_average import mu_averages, mu_target
from ..sampling.plan import Grid, TexelPlan, per_texel_plan, probe_indices
from ..tolerance import tolerance_of
from . import dfg, dielectric_ratio
from .base import Estimation, Key, declare

DEFAULT_SAMPLES = {"gauss_legendre": 3 * 12**2, "sobol_vndf": 1 << 14, "sobol_ndf": 1 << 16, "hammersley_ndf": 1 << 16}
EEVEE_SIZE = (16, 64, 64)  # UTIL_BTDF_LAYER_COUNT roughness layers x UTIL_TEX_SIZE^2
EEVEE_CLAMP = (1.0e-4, 0.9999)  # eevee_lut_comp.glsl: NoV, f0-like x^2 (btdf) and eta (bsdf) clamps
OPENPBR_SIZE = 32  # OpenPBR_EnergyTableSize
OPENPBR_IOR_MAX = 2.5  # OpenPBR_IorMax
OPENPBR_MS_ALPHA_MIN = 0.0016  # below it OpenPBR's multiple-scattering lobe is off (lutbake.kinds.dielectric_ratio)
# both kinds reach the tolerance that format / dtype set (lutbake.tolerance; kind dielectric_avg through its mu rule):
# no layout keys
AVG_LAYOUT_KEYS = ()
# kind dielectric_avg: while a texel's mu estimate (its panels' differences between the Kronrod and the Gauss rule of
# the mu_order pair) exceeds a quarter of its target, its worst panel is bisected, up to MU_MAX_PANELS panels. Inside
# the glass at small roughness E(mu) crosses the total-internal-reflection transition, ~alpha wide at cos theta_c, and
# E_T is not analytic at further points inside the glass (mu = eta among them: mu_starts): the fixed 16 nodes per panel
# of before were off by up to 2.0e-4 on OpenPBR's eta < 1 rows (alpha = 0.004)
MU_MAX_PANELS = 40
# inside the glass the first mu panels are also graded towards cos theta_c (mu_starts): Turquin's average 0.84x the mu
# evaluations, OpenPBR's 0.88x (docs/decisions.md)
MU_GRADE_MAX, MU_GRADE_RATIO = 0.25, 4.0
# kind dielectric_avg's inner rule (fixed-order Gauss-Legendre at the mu nodes, its error the probe's): without
# ``samples``, its order climbs from the default 12 by 4 (each order's refined rule, order + 4, is the next order) up
# to INNER_ORDER_MAX until the probe's share is within INNER_SHARE of the target at every probe texel (the mu rule's is
# within the other half: a quarter per kernel channel, at most two of them summed). Order 12 was the fixed default:
# Turquin's float32 average needs it (order 10: 1.53e-6 against 5e-7), OpenPBR's UNORM16 one would take 10 (1.47e-6
# against 1.9e-6) but the try costs as much as it saves, so the climb starts at 12 and tolerances tighter than order
# 12 reaches now climb instead of recording an estimate above them (tolerance 1e-7: 2.99e-7 at order 12 before)
INNER_ORDER_MAX = 32
INNER_SHARE = 0.5
NO_TARGET = 1.0e300  # the tolerance of a kernel channel a layout drops (it never refines)

LAYOUTS = {
    "energy": "R = E_R, G = E_T, B = E_R + E_T over NoV x roughness x IOR (exact Fresnel)",
    "eevee_btdf": "Blender EEVEE btdf_ggx[16][64][64][1]: Schlick transmission factor for eta > 1 (grid fixed)",
    "eevee_bsdf": "Blender EEVEE bsdf_ggx[16][64][64][3]: Schlick scale, bias, transmission factor for eta < 1 "
    "(grid fixed)",
    "openpbr": "OpenPBR reference [ior][alpha][cos] 32^3: 1 - (E_R + E_T), 1 - E_R, 1 - E(F = 1) (grid fixed)",
}
MODE = {"energy": "exact", "eevee_btdf": "eevee", "eevee_bsdf": "eevee", "openpbr": "exact_metal"}
CHANNELS = {
    "energy": {
        "e_r": "E_R = ∫ f_r |n.o| dω_o: directional reflectance of the rough interface",
        "e_t": "E_T = ∫ f_t |n.o| dω_o: directional transmittance",
        "e_sum": "E_R + E_T: single-scattering energy kept (1 - it is lost to multiple scattering)",
    },
    "eevee_btdf": {
        "transmission_factor": "∫ (1 - (1 - v.h)^5) f_t/(1 - F) |n.o| dω_o: transmittance = (1 - F0) * this"
    },
    "eevee_bsdf": {
        "scale": "∫ (1 - s) f_r/F |n.o| dω_o, s = (1 - |t.h|)^5 (1 under TIR): multiplies F0",
        "bias": "∫ s f_r/F |n.o| dω_o: multiplies F90",
        "transmission_factor": "∫ (1 - s) f_t/(1 - F) |n.o| dω_o: transmittance = (1 - F0) * this",
    },
    "openpbr": {
        "ideal_dielectric_energy_complement": "1 - (E_R + E_T)",
        "opaque_dielectric_energy_complement": "1 - E_R",
        "ideal_metal_energy_complement": "1 - E with F = 1 (reflection only; independent of the IOR)",
    },
}
AVG_CHANNELS = {
    "energy": {"e_r_avg": "2 ∫ E_R mu dmu", "e_t_avg": "2 ∫ E_T mu dmu", "e_sum_avg": "2 ∫ (E_R + E_T) mu dmu"},
    "openpbr": {
        "ideal_dielectric_average_energy_complement": "1 - 2 ∫ (E_R + E_T) mu dmu",
        "opaque_dielectric_average_energy_complement": "1 - 2 ∫ E_R mu dmu",
        "ideal_metal_average_energy_complement": "1 - 2 ∫ E(F = 1) mu dmu",
        "ideal_dielectric_reflection_ratio": "x: the multiple-scattering lobe's reflected share, Kulla-Conty split of "
        "the two sides' E_c,avg (lutbake.kinds.dielectric_ratio), symmetric transmission",
    },
}
RECONSTRUCTION = {
    "energy": "E = texture(lut3d, vec3(u(NoV), u(roughness), u(eta))).rgb (texel conventions per lutbake:axes); "
    "Turquin 2019 compensation of the dielectric lobe: f_ms-scaled = f * (1 + (1 - E_sum) / E_sum) = f / E_sum; "
    "glass split sum: reflected = prefiltered_R * E_R, transmitted = prefiltered_T * E_T",
    "eevee_btdf": "EEVEE bsdf_lut(): eta >= 1, coords = vec3(sqrt((eta - 1)/(eta + 1)), sqrt(1 - NoV), roughness); "
    "xy = xy * 63/64 + 0.5/64; layer = roughness * 15, two layers mixed by fract (manual trilinear); "
    "transmittance = (1 - F0) * t.r, reflectance = F0 * brdf.r + F90 * brdf.g (brdf_ggx split sum)",
    "eevee_bsdf": "EEVEE bsdf_lut(): eta < 1, c = sqrt(1 - eta^2), y = (NoV - c) / (NoV > c ? 1 - c : c) * 0.5 + 0.5, "
    "coords = saturate(vec3(eta^2, y, roughness)); xy = xy * 63/64 + 0.5/64; layer = roughness * 15 "
    "(manual trilinear); reflectance = F0 * t.r + F90 * t.g, transmittance = (1 - F0) * t.b",
    "openpbr": "openpbr_look_up_*_energy_complement(ior, alpha, cos): exact indices ior -> "
    "(ior < 1 ? 15 - 15 (1/ior - 1)"
    "/1.5 : 16 + 15 (ior - 1)/1.5), sqrt(alpha) * 31, cos * 31, clamped to [0, 31], trilinear over "
    "array[ior][alpha][cos] (cos fastest); values UNORM16 / 65535",
}
AVG_RECONSTRUCTION = {
    "energy": "E_avg = texture(lut2d, vec2(u(roughness), u(eta))).rgb: rows = IOR, columns = roughness",
    "openpbr": "openpbr_look_up_*_average_energy_complement(ior, alpha) and "
    "openpbr_look_up_ideal_dielectric_reflection_ratio(ior, alpha): bilinear over array[ior][alpha] (alpha "
    "fastest), indices as the 3D tables",
}
IOR_MAPPINGS = {
    "linear": "eta = lo + (hi - lo) t (t per the texel convention)",
    "symmetric": "OpenPBR's: the first N/2 indices hold 1/eta = hi - (hi - 1) i/(N/2 - 1) (eta from 1/hi up to 1), the "
    "last N/2 hold eta = 1 + (hi - 1) i/(N/2 - 1) (1 up to hi); N even, lo ignored",
}
GEOMETRY_KEYS = {
    k: dfg.KEYS[k]
    for k in (
        "roughness",
        "texel",
        "roughness_range",
        "nov_range",
        "axis_order",
        "row_order",
        "nov_mapping",
        "roughness_mapping",
        "nov_clamp",
    )
}
KEYS = {
    "layout": Key("layout", "str", "energy", "channels (and, for the engine layouts, the whole grid)", LAYOUTS),
    "size": Key("size", "int_pair", [32, 32], "[NoV, roughness] texel counts (layout energy)", minimum=1),
    "ior_size": Key("ior_size", "int", 32, "IOR slice count (z; layout energy)", minimum=1, maximum=1024),
    "ior_range": Key(
        "ior_range",
        "float_range",
        [1.0, 2.5],
        "relative IOR eta = eta_o / eta_i at t = 0 and t = 1 (eta < 1: seen from inside)",
        minimum=0.05,
        maximum=20.0,
    ),
    "ior_mapping": Key("ior_mapping", "str", "linear", "how the IOR index maps to eta", IOR_MAPPINGS),
    "ndf": Key(
        "ndf",
        "str",
        "ggx",
        "normal distribution function",
        {k: NDF_DESCRIPTIONS[k] for k in SMITH_NDFS},
    ),
    "masking": Key(
        "masking",
        "str",
        "smith_separable",
        "Smith G2, evaluated with |n.o| on both sides",
        {k: MASKINGS[k] for k in DIELECTRIC_MASKINGS},
    ),
    **GEOMETRY_KEYS,
}
AVG_KEYS = {
    **{
        k: v
        for k, v in KEYS.items()
        if k not in ("size", "nov_range", "axis_order", "row_order", "nov_mapping", "nov_clamp", "layout")
    },
    "layout": Key("layout", "str", "energy", "channels (openpbr: the grid too)", {k: LAYOUTS[k] for k in AVG_CHANNELS}),
    "roughness_size": Key("roughness_size", "int", 32, "roughness texel count (x; layout energy)", minimum=1),
    "mu_order": Key(
        "mu_order",
        "int",
        7,
        "Gauss points n in mu per panel of the (n, 2n + 1) Gauss-Kronrod pair (panels from 0.2, eta and cos theta_c, "
        "bisected to the tolerance)",
        minimum=2,
        maximum=64,
    ),
}


def ior_values(n: int, lo: float, hi: float, texel: str, mapping: str) -> np.ndarray:
    """eta at every index of an IOR axis (IOR_MAPPINGS)."""
    if mapping == "symmetric":
        half = n // 2
        t = np.arange(half) / max(half - 1, 1)
        return np.concatenate([1.0 / (hi - (hi - 1.0) * t), 1.0 + (hi - 1.0) * t])
    t = Axis("t", "z", n, texel=texel).t()
    return lo + (hi - lo) * t


def eevee_btdf_ior(x: np.ndarray) -> np.ndarray:
    """ggx_btdf_gt_one: f0 = clamp(x^2, 1e-4, 0.9999), ior = (1 + f0)/(1 - f0), i.e. x = sqrt((ior - 1)/(ior + 1))."""
    f = np.clip(x * x, *EEVEE_CLAMP)
    return (1.0 + f) / (1.0 - f)


def eevee_bsdf_ior_nov(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ggx_bsdf_split_sum: ior = clamp(sqrt(x), 1e-4, 0.9999) (the sine of the critical angle); with
    c = sqrt(1 - saturate(ior^2)), y' = 2y - 1 scaled by (1 - c) above 0 and by c below,
    NoV = clamp(y' + c, 1e-4, 0.9999)."""
    ior = np.clip(np.sqrt(x), *EEVEE_CLAMP)
    c = np.sqrt(1.0 - np.clip(ior * ior, 0.0, 1.0))
    yp = 2.0 * y - 1.0
    yp = yp * np.where(yp > 0.0, 1.0 - c, c)
    return ior, np.clip(yp + c, *EEVEE_CLAMP)


def texel_grid(o: dict) -> tuple[list[Axis], np.ndarray, np.ndarray, np.ndarray, dict]:
    """(axes slowest first, per-texel NoV, alpha, eta in row-major order, extra metadata) of a layout."""
    layout = o["layout"]
    if layout in ("eevee_btdf", "eevee_bsdf"):
        nz, ny, nx = EEVEE_SIZE
        rough = Axis("perceptual_roughness", "z", nz, 0.0, 1.0, texel="endpoint")
        t_x = np.arange(nx) / (nx - 1.0)
        t_y = np.arange(ny) / (ny - 1.0)
        X, Y = np.meshgrid(t_x, t_y)  # [y][x]
        if layout == "eevee_btdf":
            eta2 = eevee_btdf_ior(X)
            nov2 = np.clip(1.0 - Y * Y, *EEVEE_CLAMP)
            y_axis = Axis("NoV", "y", ny, 0.0, 1.0, texel="endpoint", mapping="one_minus_t2", clamp=EEVEE_CLAMP)
            extra = {
                "ior_axis": "x: t = i/63, eta = (1 + f)/(1 - f), f = clamp(t^2, 1e-4, 0.9999) "
                "(t = sqrt((eta - 1)/(eta + 1)))"
            }
        else:
            eta2, nov2 = eevee_bsdf_ior_nov(X, Y)
            y_axis = Axis("nov_coordinate", "y", ny, 0.0, 1.0, texel="endpoint")
            extra = {
                "ior_axis": "x: t = i/63, eta = clamp(sqrt(t), 1e-4, 0.9999) (t = eta^2)",
                "nov_axis": "y: t = j/63, c = sqrt(1 - eta^2), y' = 2t - 1, y' *= (y' > 0 ? 1 - c : c), "
                "NoV = clamp(y' + c, 1e-4, 0.9999) (centred on the critical angle, per IOR column)",
            }
        x_axis = Axis("ior", "x", nx, listed=tuple(float(e) for e in eta2[0]), mapping="listed")
        axes = [rough, y_axis, x_axis]
        alpha = np.repeat(rough.alpha(), ny * nx)
        return axes, np.tile(nov2.ravel(), nz), alpha, np.tile(eta2.ravel(), nz), extra
    if layout == "openpbr":
        n = OPENPBR_SIZE
        etas = ior_values(n, 1.0 / OPENPBR_IOR_MAX, OPENPBR_IOR_MAX, "endpoint", "symmetric")
        ior = Axis("ior", "z", n, listed=tuple(float(e) for e in etas), mapping="listed")
        rough = Axis("perceptual_roughness", "y", n, 0.0, 1.0, texel="endpoint")
        nov = Axis("NoV", "x", n, 0.0, 1.0, texel="endpoint")
        grid = dfg.texel_grid([rough, nov])
        return (
            [ior, rough, nov],
            np.tile(grid[0], n),
            np.tile(grid[1], n),
            np.repeat(etas, n * n),
            {"ior_axis": IOR_MAPPINGS["symmetric"] + f", hi = {OPENPBR_IOR_MAX}"},
        )
    etas = ior_values(o["ior_size"], *o["ior_range"], o["texel"], o["ior_mapping"])
    ior = Axis("ior", "z", len(etas), listed=tuple(float(e) for e in etas), mapping="listed")
    yx = dfg.axes_for(o)
    nov, alpha = dfg.texel_grid(yx)
    return (
        [ior] + yx,
        np.tile(nov, len(etas)),
        np.tile(alpha, len(etas)),
        np.repeat(etas, len(nov)),
        {"ior_axis": f"{IOR_MAPPINGS[o['ior_mapping']]}, range {list(o['ior_range'])}"},
    )


def terms_of(o: dict) -> tuple[str, str]:
    """(ndf, masking) integrated: EEVEE's and OpenPBR's layouts fix GGX with separable Smith (their G_V G_L)."""
    if o["layout"] in ("eevee_btdf", "eevee_bsdf", "openpbr"):
        return "ggx", "smith_separable"
    return o["ndf"], o["masking"]


def estimator_for(name: str, samples: int | None = None, seed: int = 0, merged: bool = False, members: bool = True):
    """The dielectric kinds' estimator ``name``: the panelled Gauss-Legendre of lutbake.sampling.dielectric
    (``merged``: its NDF-peak breakpoints merged; ``members``: texels that differ only in eta >= 1 in groups), or a
    QMC estimator of lutbake.sampling.hemisphere (the same half-vector measure)."""
    from ..sampling.dielectric import DielectricGaussLegendre
    from ..sampling.hemisphere import QuasiMonteCarlo

    if name == "gauss_legendre":
        return DielectricGaussLegendre(samples or DEFAULT_SAMPLES[name], merged=merged, members=members)
    return QuasiMonteCarlo(name, samples or DEFAULT_SAMPLES[name], seed)


def integrate(key: tuple, nov, alpha, eta, samples: int | None = None, seed: int = 0, device: str = "cpu"):
    """Host helper (checks, tests, benchmarks): float64 (len, 3) integrals of the (ndf, masking, Fresnel mode)
    integrand by ``estimator`` at texels (nov, alpha, eta); alpha through the edge policy as in a table."""
    from ..integrands.dielectric import dielectric_integrand

    ndf_name, masking_name, mode, estimator = key
    integrand = dielectric_integrand(ndf_name, masking_name, mode)
    inputs = {
        "nov": np.asarray(nov, np.float32),
        "alpha": integrand.alpha_input(np.asarray(alpha, np.float32)),
        "param": np.asarray(eta, np.float32),
    }
    return estimator_for(estimator, samples, seed).evaluate(integrand, inputs, device)


def kernel_tolerance(layout: str, tol) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """(absolute, relative) per kernel channel such that every channel of ``layout`` meets ``tol``
    (lutbake.tolerance.Tolerance) through post_process: openpbr's 1 - (E_R + E_T) adds two channels' errors
    (half the absolute tolerance each; a complement's relative tolerance does not carry over: 0), eevee_btdf keeps
    channel 2 only."""
    a, r = tol.absolute, tol.relative
    if layout == "openpbr":
        return (a / 2, a / 2, a), (0.0, 0.0, 0.0)
    if layout == "eevee_btdf":
        return (NO_TARGET, NO_TARGET, a), (0.0, 0.0, r)
    return (a, a, a), (r, r, r)


def error_post_process(layout: str, err: np.ndarray) -> np.ndarray:
    """Per-texel error bounds of post_process(layout, e) from those of e (the triangle inequality)."""
    if layout == "openpbr":
        return np.stack([err[:, 0] + err[:, 1], err[:, 0], err[:, 2]], axis=1)
    return err[:, 2:] if layout == "eevee_btdf" else err


def post_process(layout: str, e: np.ndarray) -> np.ndarray:
    """The integrals (n, 3) -> the layout's channels: complements for openpbr, the transmission factor (channel 2)
    for eevee_btdf."""
    if layout == "openpbr":
        return np.stack([1.0 - (e[:, 0] + e[:, 1]), 1.0 - e[:, 0], 1.0 - e[:, 2]], axis=1)
    return e[:, 2:] if layout == "eevee_btdf" else e


@dataclass(frozen=True)
class LayoutChannels:
    """An estimator whose values pass through ``post_process(layout)`` (its refinement too)."""

    inner: object
    layout: str

    @property
    def name(self) -> str:
        return self.inner.name

    def samples(self, inputs: dict) -> np.ndarray:
        return self.inner.samples(inputs)

    def prepare(self, integrand, device: str) -> None:
        self.inner.prepare(integrand, device)

    def evaluate(self, integrand, inputs: dict, device: str) -> np.ndarray:
        return post_process(self.layout, self.inner.evaluate(integrand, inputs, device))

    def refined(self):
        inner, how = self.inner.refined()
        return LayoutChannels(inner, self.layout), how


@dataclass(frozen=True)
class LayoutChannelsAdaptive(LayoutChannels):
    """LayoutChannels of lutbake.sampling.dielectric.DielectricAdaptive: ``absolute`` / ``relative``, the table's
    tolerance (its channels); the inner estimator holds kernel_tolerance's per kernel channel."""

    absolute: float = 0.0
    relative: float = 0.0

    def evaluate_with_error(self, integrand, inputs: dict, device: str) -> tuple[np.ndarray, np.ndarray]:
        values, err = self.inner.evaluate_with_error(integrand, inputs, device)
        return post_process(self.layout, values), error_post_process(self.layout, err)

    def refined(self):
        inner, how = self.inner.refined()
        return replace(self, inner=inner, absolute=self.absolute / 100, relative=self.relative / 100), how


def layout_estimator(o: dict, members: bool = True):
    """The estimator of a ``dielectric`` spec: to its tolerance (lutbake.tolerance) when ``samples`` is unset and the
    estimator is gauss_legendre, else estimator_for at ``samples``, through the layout's channels (``members``: the
    grid has texels that differ only in eta >= 1, which the gauss_legendre kernels take in groups)."""
    layout = o["layout"]
    if o["estimator"] == "gauss_legendre" and o["samples"] is None:
        from ..sampling.dielectric import DielectricAdaptive

        tol = tolerance_of(o)
        inner = DielectricAdaptive(*kernel_tolerance(layout, tol), members=members)
        return LayoutChannelsAdaptive(inner, layout, tol.absolute, tol.relative)
    return LayoutChannels(estimator_for(o["estimator"], o["samples"], o["seed"], members=members), layout)


def terms_record(key: tuple, layout: str) -> dict:
    return {
        "model": "rough dielectric BSDF (Walter et al. 2007)",
        "ndf": key[0],
        "masking": key[1],
        "fresnel": key[2],
        "layout": layout,
    }


def plan(spec) -> TexelPlan:
    from ..integrands.dielectric import dielectric_integrand
    from ..sampling.dielectric import sibling_tiles

    o = spec.options
    layout = o["layout"]
    axes, nov, alpha, eta, extra = texel_grid(o)
    nd, mk = terms_of(o)
    channels = CHANNELS[layout]
    integrand = dielectric_integrand(nd, mk, MODE[layout], len(channels))
    inputs = {
        "nov": np.asarray(nov, np.float32),
        "alpha": integrand.alpha_input(alpha),
        "param": np.asarray(eta, np.float32),
    }
    grid = Grid(axes, inputs, grazing=inputs["nov"], alpha=np.asarray(alpha, np.float64))
    est = layout_estimator(o, members=bool(np.any(np.asarray(eta) >= 1.0)))
    return per_texel_plan(
        integrand,
        est,
        grid,
        channels=channels,
        reconstruction=RECONSTRUCTION[layout],
        terms=terms_record((nd, mk, MODE[layout]), layout),
        extra={**extra, "alpha_policy": alpha_policy(True)},
        siblings=sibling_tiles(inputs),
    )


def mu_starts(eta: float, alpha: float = 0.0) -> np.ndarray:
    """The first mu panel ends of kind dielectric_avg: 0, 0.2, 1 and, for eta < 1, cos theta_c = sqrt(1 - eta^2)
    (where E(mu) has its total-internal-reflection kink in the smooth limit) and mu = eta = sin theta_c, where
    theta_v + theta_c = pi/2: the outer cut theta_h = theta_v + theta_c of the dielectric estimator (phi_c,
    lutbake.sampling.dielectric) enters the hemisphere there and E(mu) is not analytic (rough texels bisected
    around it: 11 % of turquin_dielectric_e_avg's mu nodes). For eta < 1 off the mirror limit (alpha >= ALPHA_MIN,
    lutbake.edge: the mirror's kink is the cos theta_c end itself) the panels are also graded towards cos theta_c,
    ends at cos theta_c +- alpha MU_GRADE_RATIO^k below MU_GRADE_MAX: the transition there is ~alpha wide, which
    bisection from the first panels reached only after up to 16 halvings of 30 evaluations each."""
    cuts = [0.0, 0.2, 1.0]
    if eta < 1.0:
        c = float(np.sqrt(1.0 - eta * eta))
        cuts += [c, float(eta)]
        w = float(alpha)
        while ALPHA_MIN <= w < MU_GRADE_MAX:
            cuts += [c - w, c + w]
            w *= MU_GRADE_RATIO
    return np.unique(np.clip(cuts, 0.0, 1.0))


def ratio_error(ec, ec_m, err, err_m, eta) -> np.ndarray:
    """A bound on OpenPBR's reflection ratio's error from its two averages' (|x(corner) - x| over the four corners
    ec +- err, ec_m +- err_m: x is monotone in each average on each branch)."""
    x = dielectric_ratio.reflection_ratio(ec, ec_m, eta)
    corners = [dielectric_ratio.reflection_ratio(ec + a * err, ec_m + b * err_m, eta) for a in (-1, 1) for b in (-1, 1)]
    return np.max(np.abs(np.array(corners) - x), axis=0)


def avg_grid(o: dict) -> tuple[list[Axis], np.ndarray, np.ndarray]:
    """(axes [ior (y), roughness (x)], alpha and eta per texel, row-major)."""
    if o["layout"] == "openpbr":
        n = OPENPBR_SIZE
        etas = ior_values(n, 1.0 / OPENPBR_IOR_MAX, OPENPBR_IOR_MAX, "endpoint", "symmetric")
        rough = Axis("perceptual_roughness", "x", n, 0.0, 1.0, texel="endpoint")
    else:
        etas = ior_values(o["ior_size"], *o["ior_range"], o["texel"], o["ior_mapping"])
        rname = "perceptual_roughness" if o["roughness"] == "perceptual" else "alpha"
        rough = Axis(
            rname, "x", o["roughness_size"], *o["roughness_range"], texel=o["texel"], mapping=o["roughness_mapping"]
        )
    ior = Axis("ior", "y", len(etas), listed=tuple(float(e) for e in etas), mapping="listed")
    return [ior, rough], np.tile(rough.alpha(), len(etas)), np.repeat(etas, rough.count)


def plan_avg(spec) -> TexelPlan:
    """E_avg per (eta, roughness) texel: the kernel at the nodes of its mu panels, reduced 2 sum w mu E per texel (the
    node set depends on eta, so the reduction is here rather than in lutbake.sampling.plan.Grid)."""
    from ..integrands.dielectric import dielectric_integrand

    o = spec.options
    layout = o["layout"]
    axes, alpha, eta = avg_grid(o)
    nd, mk = terms_of(o)
    integrand = dielectric_integrand(nd, mk, "exact_metal")
    # the inner rule's panels merged as the adaptive kernel's (its error is the probe's: inner_rule); ``samples``
    # unset: its order climbs (INNER_ORDER_MAX) until the probe fits the tolerance
    estimator = estimator_for(o["estimator"], o["samples"], o["seed"], merged=True)
    climb = o["samples"] is None and o["estimator"] == "gauss_legendre"
    order = o["mu_order"]
    x_mu, w_kronrod, _ = points.gauss_kronrod(order)
    tol = tolerance_of(o)
    starts = [mu_starts(float(e), float(a)) for e, a in zip(eta, alpha)]
    grid = Grid(axes, {"alpha": alpha}, alpha=np.asarray(alpha, np.float64))
    n_channels = len(AVG_CHANNELS[layout])

    def e_at(t, mu, est, device):
        """E(mu) (len(mu), 3) of texels t (one per mu), one launch."""
        inputs = {
            "nov": mu.astype(np.float32),
            "alpha": integrand.alpha_input(alpha[t]),
            "param": eta[t].astype(np.float32),
        }
        return est.evaluate(integrand, inputs, device)

    def first_panels(t):
        """(owner, lo, hi): the mu_starts panels of texels t, owner = the texel's position in t."""
        ends = [starts[i] for i in t]
        owner = np.concatenate([[j] * (len(e) - 1) for j, e in enumerate(ends)]).astype(int)
        return owner, np.concatenate([e[:-1] for e in ends]), np.concatenate([e[1:] for e in ends])

    # the inner rule (chosen once per plan, by one thread: inner_rule) and E at the probe texels' first-panel nodes at
    # its order, which the table's first pass takes instead of computing them again (the same inputs, the same bits)
    chosen: dict = {}
    known: dict[tuple[int, float], np.ndarray] = {}
    lock = threading.Lock()

    def inner_rule(device):
        """(estimator, inner estimate, text): the inner rule's share, 2 Σ W mu |E - E_refined| over the Kronrod nodes
        of the first panels (mu_starts) of the probe texels, per texel through the layout's channels (energy_errors).
        It bounds |2 ∫ mu (E - E_refined) dmu| whatever nodes the mu rule ends on (2 ∫ mu dmu = 1: an error of E at
        every mu moves the average by at most its mu-weighted mean), so it needs neither the bisection nor the
        refined rule's own panels. With ``climb``, the first order of 12, 16, ... INNER_ORDER_MAX (each order's
        refined rule the next) whose share is within INNER_SHARE of every probe texel's target (max(tolerance,
        relative_tolerance |v|), v its first-pass average, the worst channel, as the mu rule's)."""
        with lock:
            if chosen:
                return chosen["est"], chosen["inner"], chosen["how"]
            idx = probe_indices(grid)
            owner, lo, hi = first_panels(idx)
            mu = (lo[:, None] + (hi - lo)[:, None] * x_mu).ravel()
            tt = np.repeat(idx[owner], len(x_mu))
            w = (2.0 * np.repeat(hi - lo, len(x_mu)) * mu * np.tile(w_kronrod, len(lo)))[:, None]
            rows = np.repeat(owner, len(x_mu))
            est = estimator
            e = e_at(tt, mu, est, device)
            total = np.zeros((len(idx), e.shape[1]))
            np.add.at(total, rows, e * w)
            target = INNER_SHARE * np.maximum(tol.absolute, tol.relative * np.min(np.abs(total), axis=1))
            while True:
                refined, how = est.refined()
                e_ref = e_at(tt, mu, refined, device)
                per_texel = np.zeros((len(idx), e.shape[1]))
                np.add.at(per_texel, rows, np.abs(e - e_ref) * w)
                err = energy_errors(per_texel)
                if not climb or np.all(err <= target[:, None]) or est.order >= INNER_ORDER_MAX:
                    break
                est, e = refined, e_ref
            known.update({(int(k), float(m)): v for k, m, v in zip(tt, mu, e)})
            chosen.update(est=est, inner=float(np.max(err)), how=how)
            return est, chosen["inner"], how

    def e_known(t, mu, est, device):
        """e_at, the rows the probe computed (the table's order) taken from it."""
        out = np.empty((len(t), 3))
        got = np.array([(int(k), float(m)) in known for k, m in zip(t, mu)], bool)
        if np.any(got):
            out[got] = [known[(int(k), float(m))] for k, m in zip(t[got], mu[got])]
        if not np.all(got):
            out[~got] = e_at(t[~got], mu[~got], est, device)
        return out

    def averages(t, device):
        """(values, mu-rule estimates), (len(t), 3) float64 each: 2 ∫ E mu dmu of (E_R, E_T, E(F = 1)) at texels t by
        lutbake.sampling.mu_average from the panels of mu_starts, the mu rule to a quarter of the target
        (max(tolerance, relative_tolerance |v|) at the first pass's v, the worst channel: a layout's sum of two
        channels gets half); the inner rule's share is the probe's (inner_rule)."""
        est = inner_rule(device)[0]
        r = mu_averages(
            lambda tt, mu: (e_known(tt, mu, est, device), None),
            t,
            [starts[i] for i in t],
            order,
            mu_target(tol, 0.25),
            MU_MAX_PANELS,
        )
        return r.values, r.mu_error

    memo = RowMemo(capacity=len(alpha))

    def averages_once(t, device):
        """averages(t), each texel computed once per plan, by one thread (a texel another thread is computing is
        waited for): OpenPBR's tiles also need their mirror rows, another tile's texels (a texel's values do not
        depend on who computes them)."""
        return memo.run([int(k).to_bytes(8, "little") for k in t], lambda i: averages(t[i], device))

    def run(idx, device):
        """The channels of texels idx, then their mu-rule estimates (aux columns; OpenPBR's ratio: the bound of
        ratio_error)."""
        t = np.arange(len(alpha))[idx]
        if layout == "openpbr":
            # the reflection ratio at (eta, alpha) needs E_c,avg at (1/eta, alpha) too: row z mirrors row N - 1 - z
            mirror = (OPENPBR_SIZE - 1 - t // OPENPBR_SIZE) * OPENPBR_SIZE + t % OPENPBR_SIZE
            avg, err = averages_once(t, device)  # its own texels first: another tile may need them
            avg_m, err_m = averages_once(mirror, device)
            ch, ch_m = post_process("openpbr", avg), post_process("openpbr", avg_m)
            ce, ce_m = energy_errors(err), energy_errors(err_m)
            ratio = dielectric_ratio.reflection_ratio(ch[:, 0], ch_m[:, 0], eta[t])
            r_err = ratio_error(ch[:, 0], ch_m[:, 0], ce[:, 0], ce_m[:, 0], eta[t])
            return np.concatenate([ch, ratio[:, None], ce, r_err[:, None]], axis=1)
        avg, err = averages(t, device)
        energy = np.stack([avg[:, 0], avg[:, 1], avg[:, 0] + avg[:, 1]], axis=1)
        return np.concatenate([energy, energy_errors(err)], axis=1)

    def energy_errors(err):
        """Bounds on the layout's energy channels from those on (E_R, E_T, E(F = 1)) (the triangle inequality)."""
        if layout == "openpbr":
            return error_post_process("openpbr", err)
        return np.stack([err[:, 0], err[:, 1], err[:, 0] + err[:, 1]], axis=1)

    def error_estimate(data: np.ndarray, device: str) -> tuple[float, str]:
        """The inner rule's share at the probe texels (inner_rule) plus the largest per-texel mu-rule estimate (the
        aux columns); OpenPBR's ratio (channel A) is reported apart (0/0-like where E_c,avg -> 0)."""
        full = data.reshape(len(alpha), -1)
        energy = 3
        idx = probe_indices(grid)
        _, inner, how = inner_rule(device)
        mu = float(np.max(full[:, n_channels : n_channels + energy]))
        text = (
            f"2 sum W mu |{how}| at the Kronrod nodes of the first mu panels of {len(idx)} strided probe texels "
            f"({inner:.3g}) + the largest per-texel mu-rule estimate, sum over bisected panels of "
            f"|Q(Kronrod {2 * order + 1}) - Q(Gauss {order})| ({mu:.3g})"
        )
        if layout == "openpbr":
            used = alpha >= OPENPBR_MS_ALPHA_MIN
            text += (
                f"; reflection ratio (A): mu-rule bound {float(np.max(full[used, n_channels + energy])):.3g} where "
                f"alpha >= {OPENPBR_MS_ALPHA_MIN:g} (OpenPBR's multiple-scattering lobe)"
            )
        return inner + mu, text

    per = int(estimator.samples({"nov": [0.0]})[0]) * 5 * (2 * order + 1)  # nominal: 5 panels
    return TexelPlan(
        axes=axes,
        channels=AVG_CHANNELS[layout],
        reconstruction=AVG_RECONSTRUCTION[layout],
        n_texels=len(alpha),
        n_channels=n_channels,
        run_tile=lambda s, e, d: run(slice(s, e), d),
        prepare=lambda d: (estimator.prepare(integrand, d), inner_rule(d)),
        samples=per,
        aux_channels=n_channels,
        estimator=estimator.name,
        terms=terms_record((nd, mk, "exact_metal"), layout),
        cost=float(len(alpha)) * per,
        extra={
            "mu_quadrature": f"Gauss-Kronrod ({order}, {2 * order + 1}) per panel from mu = 0, 0.2, 1 and, for "
            f"eta < 1, eta and cos theta_c; the worst panel bisected until the sum of |Kronrod - Gauss| is within "
            f"tol / 4 (at most {MU_MAX_PANELS} panels)",
            "tolerance": tol.text(),
            "alpha_policy": alpha_policy(True),
            **({"reflection_ratio": dielectric_ratio.METADATA} if layout == "openpbr" else {}),
        },
        error_estimate=error_estimate,
    )


def check_spec(spec) -> tuple[str, str] | None:
    o = spec.options
    nd, _ = terms_of(o)
    if o["estimator"] == "sobol_vndf" and nd not in VNDF_NDFS:
        return ("estimator", f"'sobol_vndf' needs ndf = 'ggx' (a visible-normal sampler), not {nd!r}")
    if o.get("ior_mapping") == "symmetric" and (o["ior_range"][1] <= 1.0 or o["ior_size"] % 2):
        return ("ior_mapping", "'symmetric' needs ior_range[1] > 1 (the largest eta) and an even ior_size")
    if o["layout"] in ("eevee_btdf", "eevee_bsdf", "openpbr") and (o["ndf"], o["masking"]) != (
        "ggx",
        "smith_separable",
    ):
        return ("layout", f"layout {o['layout']!r} fixes ndf = 'ggx' and masking = 'smith_separable' (the engine's)")
    if o.get("format") == "openpbr_h" and o["layout"] != "openpbr":
        return ("format", f"'openpbr_h' writes OpenPBR's arrays: it needs layout = 'openpbr', not {o['layout']!r}")
    return None


def texel_count(o: dict) -> int:
    """size x ior_size (the engine layouts: their fixed grids)"""
    if o["layout"] in ("eevee_btdf", "eevee_bsdf"):
        return int(np.prod(EEVEE_SIZE))
    if o["layout"] == "openpbr":
        return OPENPBR_SIZE**3
    return o["size"][0] * o["size"][1] * o["ior_size"]


def avg_texel_count(o: dict) -> int:
    """roughness_size x ior_size"""
    return OPENPBR_SIZE**2 if o["layout"] == "openpbr" else o["roughness_size"] * o["ior_size"]


SAMPLES_DOC = (
    "integrand evaluations per texel; omitted: gauss_legendre adapts to the tolerance (kind dielectric; "
    "dielectric_avg: 432 = order 12 per panel), sobol_vndf 16384"
)
ESTIMATION = Estimation(HEMISPHERE_ESTIMATORS, "gauss_legendre", SAMPLES_DOC)


DIELECTRIC = declare(
    "dielectric",
    "rough dielectric BSDF energies E_R, E_T, E_R + E_T: NoV x roughness x IOR slices "
    "(eta < 1: seen from inside), or an engine's layout (EEVEE btdf/bsdf, OpenPBR)",
    KEYS,
    plan,
    ESTIMATION,
    aliases=("glass", "btdf"),
    check=check_spec,
    texels=texel_count,
)
DIELECTRIC_AVG = declare(
    "dielectric_avg",
    "hemispherical averages 2 ∫ E mu dmu of the dielectric energies: IOR (rows) x roughness (columns)",
    AVG_KEYS,
    plan_avg,
    ESTIMATION,
    aliases=("glass_avg",),
    check=check_spec,
    texels=avg_texel_count,
    layout_keys=AVG_LAYOUT_KEYS,
)
