"""Kind ``specular_aniso``: split-sum tables of anisotropic lobes, NoV x roughness x anisotropy.

    E(NoV, r, a) = ∫ f(l, v) (n.l) dω_l,  f anisotropic: tangent T = +x, bitangent B = +y, n = +z,
stored as z slices over the anisotropy a (a multi-part EXR, one part per a, as specular_3d stores f0), with the
split-sum channels of ``dfg`` (Schlick F: scale/bias or multiscatter).

Anisotropy -> (alpha_x, alpha_y): Burley 2012 ("Physically based shading at Disney", SIGGRAPH course notes,
Addenda B.2): aspect = sqrt(1 - 0.9 |a|), alpha_x = alpha / aspect, alpha_y = alpha * aspect for a >= 0
(a < 0 swaps the two: the lobe stretches along B), alpha = r^2 (or the axis value with roughness = "alpha"),
both clamped to >= ALPHA_MIN. a = 0 is the isotropic lobe.

Models (key ``model``):
- ``microfacet``: anisotropic GGX (Heitz 2014, Eq. 85) with height-correlated Smith G2 and the anisotropic
  Lambda (Heitz 2014, Eq. 86); f = D G2 F / (4 (n.l)(n.v)).
- ``ashikhmin_shirley``: Ashikhmin & Shirley 2000 with exponents nu = 2 / alpha_x^2 - 2 along T and
  nv = 2 / alpha_y^2 - 2 along B (the lecture's shin_T and shin_B; the Blinn-Phong roughness mapping per axis,
  clamped to >= 0, so alpha_x > 1 gives nu = 0), f = F sqrt((nu+1)(nv+1))/(8 pi) (n.h)^e / ((v.h) max(n.l, n.v)),
  e = (nu (T.h)^2 + nv (B.h)^2) / (1 - (n.h)^2).

The view azimuth phi_v (of v about n, from T) is a fourth parameter of an anisotropic lobe; the table does not
have it. Key ``view_azimuth``: ``average`` (default) integrates it out, E = (1/2 pi) ∫ E(phi_v) dphi_v, which is
what a shader looking up a 3D table without the azimuth should use (at a = 0 it is the isotropic table);
``tangent`` fixes phi_v = 0 (v in the T-n plane), ``bitangent`` phi_v = pi/2. Recorded in lutbake:view_azimuth.

Estimator (``sobol``): scrambled 3D Sobol' points (u1, u2, u3): phi_v = 2 pi u3 (average), and h from
- microfacet: the anisotropic GGX visible-normal distribution (Heitz 2018, JCGT 7(4); spherical caps, Dupuy &
  Benyoub 2023), pdf = G1(v) max(0, v.h) D(h) / (n.v), so the weight g / p = F G2 / G1(v) = F (1 + Lambda_v) /
  (1 + Lambda_v + Lambda_l), bounded by F;
- ashikhmin_shirley: the paper's own half-vector sampling (Eq. 9), pdf = p_h(h), weight = F (n.l) / max(n.l, n.v).
Both weights are bounded by 1, so the QMC error is that of a bounded integrand with a kink at the horizon
(measured in tests/test_aniso.py against the isotropic gauss_legendre tables).
"""

from __future__ import annotations

import functools

import numpy as np
import warp as wp

from ..axes import Axis
from ..edge import ALPHA_MIN, COS_EPS
from ..sampling import points
from ..terms import masking, ndf
from ..terms.frame import reflect
from . import dfg, specular
from .base import Key, Kind, Plan

MODELS = {
    "microfacet": "anisotropic GGX, height-correlated Smith G2 with the anisotropic Lambda, Schlick F (Heitz 2014)",
    "ashikhmin_shirley": "Ashikhmin & Shirley 2000, nu = 2/alpha_x^2 - 2 (tangent), nv = 2/alpha_y^2 - 2 (bitangent)",
}
VIEW_AZIMUTHS = {
    "average": "E averaged over the view azimuth phi_v in [0, 2 pi) (default)",
    "tangent": "phi_v = 0: v in the plane of the tangent and the normal",
    "bitangent": "phi_v = pi/2: v in the plane of the bitangent and the normal",
}
PHI_V = {"average": -1.0, "tangent": 0.0, "bitangent": 0.5 * np.pi}
ESTIMATORS = {
    "sobol": "scrambled 3D Sobol' points: h by anisotropic GGX VNDF sampling (microfacet) or the "
    "Ashikhmin-Shirley h sampling; phi_v = 2 pi u3 when averaged"
}
DEFAULT_SAMPLES = 16384

KEYS = {
    **{k: v for k, v in dfg.COMMON_KEYS.items() if k != "estimator"},
    "estimator": Key("estimator", "str", "sobol", "how the integral is estimated", ESTIMATORS),
    "model": Key("model", "str", "microfacet", "the anisotropic lobe", MODELS),
    "layout": dfg.KEYS["layout"],
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
AXES_FORMULA = (
    "aspect = sqrt(1 - 0.9 |a|); alpha_x = alpha / aspect, alpha_y = alpha * aspect (a >= 0; swapped for a < 0)"
)


def alpha_xy(alpha: np.ndarray, aniso: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Burley 2012 (Addenda B.2): (alpha_x, alpha_y) for NDF alpha and anisotropy a in [-1, 1], >= ALPHA_MIN."""
    alpha = np.asarray(alpha, np.float64)
    aniso = np.asarray(aniso, np.float64)
    aspect = np.sqrt(1.0 - 0.9 * np.abs(aniso))
    ax, ay = alpha / aspect, alpha * aspect
    ax, ay = np.where(aniso >= 0, ax, ay), np.where(aniso >= 0, ay, ax)
    return (np.maximum(ax, ALPHA_MIN).astype(np.float32), np.maximum(ay, ALPHA_MIN).astype(np.float32))


@wp.func
def view_at(nov: float, phi_v: float):
    s = wp.sqrt(wp.max(1.0 - nov * nov, 0.0))
    return wp.vec3(s * wp.cos(phi_v), s * wp.sin(phi_v), nov)


@functools.lru_cache(maxsize=None)
def kernel_for(model: str, layout: str):
    """QMC kernel over texels (nov, alpha_x, alpha_y, phi_v; phi_v < 0: averaged) with 3D points (module docstring)."""
    ch, vec = specular.channels_for(layout)
    acc_type = wp.vec2d
    nch = 2
    micro = model == "microfacet"

    @wp.kernel(enable_backward=False, module="unique")
    def aniso_kernel(
        nov: wp.array(dtype=float),
        alpha_x: wp.array(dtype=float),
        alpha_y: wp.array(dtype=float),
        phi_v: wp.array(dtype=float),
        pts: wp.array2d(dtype=float),
        out: wp.array2d(dtype=wp.float64),
    ):
        i = wp.tid()
        ax = alpha_x[i]
        ay = alpha_y[i]
        nu = ndf.as_exponent(wp.min(ax, 1.0))
        nv = ndf.as_exponent(wp.min(ay, 1.0))
        acc = acc_type()
        n = pts.shape[0]
        for k in range(n):
            phi = phi_v[i]
            if phi < 0.0:
                phi = 2.0 * wp.pi * pts[k, 2]
            v = view_at(nov[i], phi)
            w = 0.0
            h = wp.vec3()
            if wp.static(micro):
                h = ndf.sample_vndf_ggx_aniso(v, ax, ay, pts[k, 0], pts[k, 1])
            else:
                h = ndf.sample_ashikhmin_shirley(nu, nv, pts[k, 0], pts[k, 1])
            VoH = wp.dot(v, h)
            l = reflect(v, h)
            if l[2] > COS_EPS and VoH > COS_EPS and v[2] > COS_EPS:
                if wp.static(micro):
                    lam_v = masking.Lambda_ggx_aniso(v, ax, ay)
                    w = (1.0 + lam_v) / (1.0 + lam_v + masking.Lambda_ggx_aniso(l, ax, ay))
                else:
                    w = l[2] / wp.max(l[2], v[2])
                g = ch(VoH, 0.0) * w
                for c in range(wp.static(nch)):
                    acc[c] = acc[c] + wp.float64(g[c])
        for c in range(wp.static(nch)):
            out[i, c] = acc[c] / wp.float64(n)

    return aniso_kernel


def integrate(kernel, nov, alpha_x, alpha_y, phi_v, samples: int, seed: int, device: str = "cpu") -> np.ndarray:
    """One launch over texels -> float64 (len, 2)."""
    n = len(nov)
    pts = np.clip(points.sobol3(samples, seed), 0.0, np.nextafter(np.float32(1.0), np.float32(0.0))).astype(np.float32)
    out = wp.zeros((n, 2), dtype=wp.float64, device=device)
    inputs = [
        wp.array(np.ascontiguousarray(a, dtype=np.float32), dtype=float, device=device)
        for a in (nov, alpha_x, alpha_y, phi_v)
    ]
    wp.launch(kernel, dim=n, inputs=inputs + [wp.array(pts, dtype=float, device=device), out], device=device)
    return out.numpy()


def axes_for(o: dict) -> list[Axis]:
    return [Axis("anisotropy", "z", o["anisotropy_size"], *o["anisotropy_range"], texel=o["texel"])] + dfg.axes_for(o)


def plan(spec) -> Plan:
    o = spec.options
    axes = axes_for(o)
    an_axis, rough, nov_axis = axes
    nx, ny, nz = nov_axis.count, rough.count, an_axis.count
    samples = o["samples"] or DEFAULT_SAMPLES
    eff = 1 << int(np.ceil(np.log2(max(samples, 1))))
    # texel t = (iz * ny + iy) * nx + ix: anisotropy slowest, then roughness, then NoV
    nov = np.tile(nov_axis.values(), ny * nz)
    alpha = np.tile(np.repeat(rough.alpha(), nx), nz)
    aniso = np.repeat(an_axis.values(), ny * nx)
    ax, ay = alpha_xy(alpha, aniso)
    phi = np.full(len(nov), PHI_V[o["view_azimuth"]], np.float32)
    key = (o["model"], o["layout"])

    def run_tile(start: int, stop: int, device: str) -> np.ndarray:
        k = kernel_for(*key)
        return integrate(
            k, nov[start:stop], ax[start:stop], ay[start:stop], phi[start:stop], samples, o["seed"], device
        )

    terms = {
        "model": o["model"],
        "ndf": "ggx_aniso" if o["model"] == "microfacet" else "ashikhmin_shirley",
        "masking": "smith_height_correlated (anisotropic Lambda)"
        if o["model"] == "microfacet"
        else "none (implicit in the lobe)",
        "fresnel": "schlick",
        "layout": o["layout"],
    }
    return Plan(
        axes=axes,
        channels=dfg.CHANNELS[o["layout"]],
        reconstruction=RECONSTRUCTION[o["layout"]],
        n_texels=len(nov),
        n_channels=2,
        run_tile=run_tile,
        prepare=lambda d: specular.load(kernel_for(*key), d),
        samples=eff,
        estimator=o["estimator"],
        terms=terms,
        cost=float(len(nov)) * eff,
        extra={
            "view_azimuth": f"{o['view_azimuth']}: {VIEW_AZIMUTHS[o['view_azimuth']]}",
            "anisotropy_mapping": f"Burley 2012, Addenda B.2: {AXES_FORMULA}",
            "tangent_frame": "T = +x (phi = 0), B = +y, n = +z",
        },
    )


def check_spec(spec) -> tuple[str, str] | None:
    o = spec.options
    n = o["size"][0] * o["size"][1] * o["anisotropy_size"]
    if n > 1 << 26:
        return ("size", f"size x anisotropy_size = {n} texels: at most {1 << 26}")
    return None


SPECULAR_ANISO = Kind(
    "specular_aniso",
    "anisotropic split-sum: NoV x roughness x anisotropy slices (anisotropic "
    "GGX or Ashikhmin-Shirley), scale/bias or multiscatter",
    KEYS,
    plan,
    aliases=("aniso",),
    check=check_spec,
)
