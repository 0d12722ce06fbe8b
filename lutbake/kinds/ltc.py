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

import json
import os
import threading

import numpy as np

from ..axes import MAPPINGS, TEXELS, Axis
from ..edge import ALPHA_MIN
from ..layouts.base import uv_of
from ..limits import LTC_FIT_GRID
from ..records import LTC_LOBE
from ..registry import choices
from ..sampling.plan import TexelPlan
from .base import Estimation, Key, declare

THETA_MAX = 1.57  # ltc_code fitTab: theta = min(1.57, acos(1 - x^2))
NOV_LO = float(np.cos(np.float32(THETA_MAX)))
MAGNITUDE_SAMPLES = {"ggx": 432, "beckmann": 432, "charlie": 3072, "lambert": 0}  # diffuse lobes: the diffuse kind's
FORMATS = {
    "exr": "OpenEXR, two parts (slice_0 = ltc_1, slice_1 = ltc_2), lutbake:* attributes (default)",
    "npy": "NumPy (2, N, N, 4) + .json sidecar",
    "ltc_dds": "ltc_code's two files <name>_1.dds, <name>_2.dds: RGBA16F (dtype half, as ltc_code) or RGBA32F",
    "js": "three.js ES module: LTC_MAT_1 / LTC_MAT_2 Float32Arrays as RectAreaLightTexturesLib's, .z of LTC_MAT_2 = 0",
    "c": "Blender EEVEE C arrays ltc_mat_<lobe>[N][N][4], ltc_mag_<lobe>[N][N][2], ltc_disk_integral[N][N][1]",
    "cs": "Unity HDRP C# table s_LtcMatrixData_BRDF_<LOBE> (ushort FP16 bits, one RGBA16F slice of _LtcData): "
    "(M^-1_00, M^-1_20, M^-1_11, M^-1_02) / M^-1_22",
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


def axes_for(o: dict) -> list[Axis]:
    from ..ltc.lobes import LOBES

    n_view, n_rough = o["size"]
    lb = LOBES[o["lobe"]]
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


def uses_shaded_fit(o: dict) -> bool:
    """Whether the table's texels are the shaded fit's (lutbake.ltc.shaded) or the L3 fit's."""
    return o["fit"] == "shaded" and o["lobe"] != "lambert"  # lambert: the L3 fit is exact


def lobe_parameter(rough: Axis) -> np.ndarray:
    """The lobe's parameter per roughness index: the NDF alpha of the axis, or (EON) the axis value itself."""
    a = rough.alpha()
    return rough.values() if a is None else a


def texel_params(axes: list[Axis], alpha_min: float = ALPHA_MIN) -> tuple[np.ndarray, np.ndarray]:
    """Per texel of one slice, row-major (y = view slowest): (NoV, alpha) as float32, alpha >= alpha_min (the
    alpha fitted: an LTC of a Dirac lobe is not defined)."""
    _, view, rough = axes
    alpha = np.maximum(lobe_parameter(rough), np.float32(alpha_min))
    return np.repeat(view.values(), rough.count), np.tile(alpha, view.count)


def magnitude_alpha(axes: list[Axis], alpha_min: float = ALPHA_MIN) -> np.ndarray:
    """The alpha at which magnitude and fresnel are integrated: the axis alpha itself under lutbake's edge policy
    (alpha -> 0: the exact mirror limit, as the ``albedo`` table), or alpha_min where a larger one is set."""
    _, view, rough = axes
    a = lobe_parameter(rough)
    if alpha_min > ALPHA_MIN:
        a = np.maximum(a, np.float32(alpha_min))
    return np.tile(a, view.count)


def magnitude_fresnel(
    lobe_name: str,
    nov: np.ndarray,
    alpha: np.ndarray,
    samples: int | None,
    device: str = "cpu",
    estimator: str = "gauss_legendre",
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """(magnitude, fresnel) per texel from lutbake's integrators (``estimator``, default Gauss-Legendre).
    GGX / Beckmann: magnitude is the ``albedo`` kind's integrand (so it equals that table at the same texels),
    fresnel the ``dfg`` multiscatter integrand's Fc channel; charlie: the ``dfg`` charlie layout's B channel (the
    gltf-charlie table), fresnel = magnitude; lambert: 1; gotanda, eon: the ``diffuse`` kind's integrator and
    integrand (its default GL order unless ``samples``; ``alpha`` = sigma resp. EON's r), fresnel = magnitude.
    ``alpha`` goes through the integrands' edge policy (mirror limit at alpha -> 0)."""
    from ..integrands.specular import specular_integrand
    from ..ltc.lobes import LOBES
    from ..sampling.hemisphere import estimator_for

    lb = LOBES[lobe_name]
    if lb.magnitude == "lambert":
        one = np.ones(len(nov))
        return one, one.copy()
    if lb.magnitude == "lobe":  # no other integrator has the lobe: lutbake.ltc.fit's quadrature of f_cos
        from ..ltc import fit

        m = fit.lobe_albedo(fit.Problem(lobe_name, nov, alpha, np.zeros(len(nov)), device=device))
        return m, m.copy()
    if lb.magnitude.startswith("diffuse:"):
        m = diffuse_magnitude(lb.magnitude.split(":")[1], nov, alpha, samples, device)
        return m, m.copy()
    if estimator == "gauss_legendre":
        samples = samples or MAGNITUDE_SAMPLES[lobe_name]
    est = estimator_for(estimator, samples, seed)
    nov = np.asarray(nov, np.float32)
    zero = np.zeros(len(nov), np.float32)

    def integrate(integrand):
        inputs = {"nov": nov, "alpha": integrand.alpha_input(alpha), "param": zero}
        est.prepare(integrand, device)  # compiled once, whichever table asks first (tables prepare in parallel)
        return est.evaluate(integrand, inputs, device)

    _, which = lb.magnitude.split(":")
    if which == "charlie":
        m = integrate(specular_integrand("ggx", "smith_height_correlated", "charlie"))[:, 2]
        return m, m.copy()
    mag = integrate(specular_integrand(which, "smith_height_correlated", "albedo", "microfacet", 1))[:, 0]
    fres = integrate(specular_integrand(which, "smith_height_correlated", "multiscatter"))[:, 0]
    return mag, fres


def diffuse_magnitude(model: str, nov, sigma, samples: int | None, device: str = "cpu") -> np.ndarray:
    """E(n.v) = ∫ f (n.l) dω_l (rho = 1, f0 = 0) exactly as the ``diffuse`` kind integrates ``model`` at these
    texels (its grid inputs, its Gauss-Legendre estimator and default order), so the magnitude equals that table."""
    from ..integrands.diffuse import diffuse_integrand
    from . import diffuse as kind_diffuse  # the diffuse kind declares its estimator; imported where needed

    o = {"estimator": "gauss_legendre", "samples": samples, "model": model, "seed": 0}
    nov = np.asarray(nov, np.float32)
    grid = kind_diffuse.diffuse_grid([], nov, np.asarray(sigma, np.float32), np.zeros(len(nov)), "sigma")
    est = kind_diffuse.estimator_of(o)
    integrand = diffuse_integrand(model)
    est.prepare(integrand, device)
    return est.evaluate(integrand, grid.inputs, device)[:, 0]


class LtcBake:
    """The state one bake shares between its tiles: the problem (magnitudes, frames) and the coarse pass,
    built once under a lock; fits are memoised per texel range (both slices' tiles of one range use one fit) and
    per texel across tables (lutbake.ltc.fit.MEMO: a texel with the same inputs and seeds as one another table
    of the process fitted, e.g. ltc-hdrp's beside ltc-ggx's, is that fit)."""

    def __init__(self, o: dict, axes: list[Axis]):
        self.o = o
        self.axes = axes
        self.nov, self.alpha = texel_params(axes, o["alpha_min"])
        self.n_view, self.n_rough = axes[1].count, axes[2].count
        from ..ltc import sphere

        self._lock = threading.Lock()
        self._fits: dict[tuple[int, int], tuple[threading.Lock, list]] = {}
        self.problem = None
        self.coarse = None
        self.shaded = uses_shaded_fit(o)
        self.device = "cpu"
        self.sphere = sphere.sphere_table(self.n_rough) if self.n_view == self.n_rough else None

    def prepare(self, device: str) -> None:
        from ..ltc import fit

        with self._lock:
            if self.problem is None:
                o = self.o
                alpha = magnitude_alpha(self.axes, o["alpha_min"])
                mag, fres = magnitude_fresnel(
                    o["lobe"], self.nov, alpha, o["samples"], device, o["estimator"], o["seed"]
                )
                self.fresnel = fres
                self.device = device
                self.has_fresnel = not np.array_equal(mag, fres)  # lobes without Fresnel store fresnel = magnitude
                # a tabulated lobe's table is built here on every available core (the executor's default; values do
                # not depend on the thread count)
                threads = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
                p = fit.Problem(self.o["lobe"], self.nov, self.alpha, mag, self.o["fit_samples"], device, threads)
                nodes = self.unclamped_nodes(device, threads)
                self.coarse = fit.coarse_pass(p, self.n_view, self.n_rough, fit.MEMO, nodes)
                self.problem = p

    def unclamped_nodes(self, device: str, threads: int):
        """The coarse pass's own problem where ``alpha_min`` clamps a coarse texel's alpha: the coarse texels at the
        lobe's alpha (>= lutbake's ALPHA_MIN) and magnitude, as a table without the clamp fits them; None where no
        coarse texel is clamped. The coarse fits only seed the texels, so the table's seeds are then the unclamped
        table's, and through the fit memo so is every texel the clamp leaves alone (ltc-hdrp, alpha_min 1e-3, fits
        its two clamped columns of 64 beside ltc-ggx instead of the nine of the first coarse cell)."""
        from ..ltc import fit

        idx = fit.coarse_texels(self.n_view, self.n_rough)
        nov, alpha = texel_params(self.axes)
        if np.array_equal(alpha[idx], self.alpha[idx]):
            return None
        o = self.o
        mag, _ = magnitude_fresnel(
            o["lobe"], nov[idx], magnitude_alpha(self.axes)[idx], o["samples"], device, o["estimator"], o["seed"]
        )
        return fit.Problem(o["lobe"], nov[idx], alpha[idx], mag, o["fit_samples"], device, threads)

    def fitted(self, start: int, stop: int) -> list:
        """[packed ltc_1 (k, 4), relative error (k,)] of texels [start, stop) of a slice (fitted once)."""
        from ..ltc import fit

        with self._lock:
            lock, box = self._fits.setdefault((start, stop), (threading.Lock(), []))
        with lock:
            if not box:
                texel = np.arange(start, stop)
                p = self.problem
                m, err = fit.fit_texels(p, texel, self.n_rough, self.coarse, fit.MEMO)
                packed, mag, fres = fit.pack_inverse(m), p.magnitude[texel], self.fresnel[texel]
                if self.shaded:
                    from ..ltc import shaded

                    # texels the L3 fit represents exactly (EON at r = 0: Lambert) keep it: the training lights'
                    # sampled targets would only add their noise
                    sel = np.flatnonzero(p.relative(texel, err) >= shaded.EXACT_L3)
                    free = self.o["magnitude"] == "fitted"
                    exact_fres = fres[sel] if self.has_fresnel else None
                    w = self.o["fit_f0_weight"]
                    packed, mag, fres, err = packed.copy(), mag.copy(), fres.copy(), err.copy()
                    packed[sel], mag[sel], fres[sel] = shaded.refine(
                        p, texel[sel], packed[sel], exact_fres, free, self.device, f0_weight=w
                    )
                    err[sel] = p.error(texel[sel], np.linalg.inv(fit.unpack_inverse(packed[sel])))
                box += [packed, p.relative(texel, err), mag, fres]
        return box

    def run_tile(self, start: int, stop: int, device: str) -> np.ndarray:
        self.prepare(device)
        n = self.n_view * self.n_rough
        out = np.empty((stop - start, 4))
        pos = start
        while pos < stop:  # a tile may straddle the two slices
            z, s = divmod(pos, n)
            e = min(stop - z * n, n)
            packed, rel, mag, fres = self.fitted(s, e)
            rows = slice(pos - start, pos - start + e - s)
            if z == 0:
                out[rows] = packed
            else:
                sph = self.sphere.ravel()[s:e] if self.sphere is not None else np.zeros(e - s)
                out[rows] = np.stack([mag, fres, rel, sph], axis=1)
            pos += e - s
        return out


NORMAL_FRAME = (
    "M^-1 = [[a, 0, b], [0, a, 0], [0, 0, 1]] in the normal's frame (Zeltner, Burley & Chiang 2022; tizian/ltc-sheen), "
    "2 parameters (log(1 / a), b)"
)
FREE_FRAME = " turned about y by a fitted angle d (4 parameters: every LTC of a lobe symmetric about the xz-plane)"
ROUGHNESS_AXES = {
    "perceptual": "x = perceptual roughness r, NDF alpha = r^2 (ltc_code)",
    "alpha": "x = alpha (the lobe's own parameter: charlie's sheenRoughness)",
    "sigma": "x = Gotanda's sigma, GGX alpha = sigma (the diffuse kind's default sigma_to_alpha, docs/diffuse.md)",
    "diffuse_roughness": "x = EON's roughness r (OpenPBR base_diffuse_roughness), linear in [0, 1]",
    "none": "x unused (lambert)",
}


def magnitude_record(lb, estimator: str, samples) -> str:
    if lb.magnitude == "lobe":
        from ..ltc import fit

        return (
            f"lutbake.ltc.fit.lobe_albedo: Gauss-Legendre {fit.ALBEDO_ORDER} x {fit.ALBEDO_ORDER // 2} (theta graded "
            "to the horizon, phi)"
        )
    if lb.magnitude.startswith("diffuse:"):
        model = lb.magnitude.split(":")[1]
        return (
            f"the diffuse kind's gauss_legendre estimator, model {model!r}, order {samples or 'default'} (rho = 1, "
            "f0 = 0): equal to that table at the same texels; fresnel channel = magnitude"
        )
    return f"{estimator}, {samples or 'default'} samples (lutbake albedo / dfg integrands)"


def shaded_record(o: dict) -> dict:
    if not uses_shaded_fit(o):
        return {"fit": "l3: the matrices minimise the L3 distance; magnitude and fresnel are the exact integrals"}
    from ..ltc import shaded

    mag = (
        "magnitude fitted with the matrix, fresnel the least-squares Schlick scale"
        if o["magnitude"] == "fitted"
        else "magnitude = the exact albedo (fixed), fresnel the least-squares Schlick scale"
    )
    return {
        "fit": f"shaded: the l3 fit refined by Levenberg-Marquardt ({shaded.ITERATIONS} steps) to minimise the soft-L1 "
        f"(scale {shaded.ROBUST_SCALE:g}) of (value_j - G_j) / (G_j + {shaded.ABS_WEIGHT:g} albedo) over "
        f"{shaded.LIGHTS} training lights per texel (lutbake.ltc.lights, seed {shaded.SEED}), G_j from the lobe's "
        f"{shaded.SAMPLES}^2 importance samples, for F = 1 and (weight {o['fit_f0_weight']:g}) f0 = "
        f"{shaded.F0_TRAIN:g}; " + mag
    }


def tabulation_record(lb) -> dict:
    if lb.tabulate is None:
        return {}
    from ..ltc import tabulated

    return {
        "tabulated_lobe": f"f (n.l) = G2 J, J tabulated per texel on {tabulated.TAB_THETA} theta_l (cell centres) x "
        f"{tabulated.TAB_PHI} phi_l (endpoints, [0, pi]) by Eq. 4's GL quadrature at order {tabulated.TAB_ORDER}, "
        "Catmull-Rom interpolated (lutbake.ltc.tabulated)"
    }


def fit_error_stats(data: np.ndarray) -> dict[str, str]:
    """The lutbake:fit_error_* attributes: statistics of slice 1's z channel (relative L3 error per texel)."""
    e = np.asarray(data)[1, ..., 2].ravel()
    return {
        "fit_error_max": f"{e.max():.4g}",
        "fit_error_median": f"{np.median(e):.4g}",
        "fit_error_p95": f"{np.quantile(e, 0.95):.4g}",
        "fit_error": json.dumps(
            {
                "metric": "(E / ∫ f^3 dω)^(1/3), E = ∫ |f (n.l) - magnitude D_ltc|^3 dω by MIS "
                "over the lobe's and the LTC's N x N stratified samples (Heitz et al. 2016, "
                "ltc_code computeError)",
                "max": float(e.max()),
                "median": float(np.median(e)),
                "p95": float(np.quantile(e, 0.95)),
                "mean": float(e.mean()),
            }
        ),
    }


def plan(spec) -> TexelPlan:
    from ..ltc import fit
    from ..ltc.lobes import LOBES

    o = spec.options
    axes = axes_for(o)
    state = LtcBake(o, axes)
    n = axes[1].count * axes[2].count
    lb = LOBES[o["lobe"]]
    m_samples = 0 if lb.magnitude in ("lambert", "lobe") else o["samples"]
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
    q_text = "log(1 / a), b" if lb.normal_frame else "log m11, log m22, m13/m11" + (", d" if lb.free_frame else "")
    extra = {
        "ltc_fit": json.dumps(
            {
                "parametrisation": NORMAL_FRAME
                if lb.normal_frame
                else "M = [X Y Z] [[m11, 0, m13], [0, m22, 0], [0, 0, 1]], Z = lobe's average direction"
                + (FREE_FRAME if lb.free_frame else " (ltc_code's 3 parameters)"),
                "metric": "Heitz et al. 2016 L3 distance, MIS over lobe and LTC samples (ltc_code computeError)",
                "fit_samples": f"{o['fit_samples']} x {o['fit_samples']} per technique",
                "optimiser": f"Nelder-Mead (ltc_code nelder_mead.h), tol {fit.NELDER_MEAD_TOL}, "
                f"<= {fit.NELDER_MEAD_ITERS} iterations per restart, simplex sizes {list(fit.COARSE_STEPS)} "
                f"(coarse pass), {list(fit.FINE_STEPS)} (texels) in ({q_text})",
                "seeding": f"coarse pass on {fit.COARSE_NODES}^2 texels from analytic guesses, at the lobe's alpha "
                f"(>= {ALPHA_MIN:g}, unclamped by alpha_min); each texel starts "
                "from the best of the analytic guesses and the surrounding coarse fits (no chaining)",
                "alpha_min": o["alpha_min"],
                "theta_max": THETA_MAX,
                "magnitude": magnitude_record(lb, o["estimator"], m_samples),
                **shaded_record(o),
                "roughness_axis": ROUGHNESS_AXES[lb.roughness],
                **tabulation_record(lb),
            }
        ),
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
        attributes_after=fit_error_stats,
    )


def check_spec(spec):
    from ..ltc.lobes import LOBES

    o = spec.options
    if o["estimator"] != "gauss_legendre" and LOBES[o["lobe"]].magnitude not in ("dfg:ggx", "dfg:beckmann"):
        return (
            "estimator",
            f"estimator {o['estimator']!r} samples the GGX / Beckmann NDF: lobe {o['lobe']!r} needs 'gauss_legendre'",
        )
    if LOBES[o["lobe"]].magnitude.startswith("diffuse:") and o["samples"] is not None and o["samples"] > 64:
        return ("samples", f"lobe {o['lobe']!r}: samples is the diffuse kind's Gauss-Legendre order, at most 64")
    if o["format"] in ("ltc_dds", "babylon_fuzz") and o["dtype"] not in ("half", "float32"):
        return ("dtype", f"{o['format']} writes RGBA16F (half) or RGBA32F (float32)")
    if o["format"] == "babylon_fuzz" and not LOBES[o["lobe"]].normal_frame:
        normal = ", ".join(n for n, lb in LOBES.items() if lb.normal_frame)
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
