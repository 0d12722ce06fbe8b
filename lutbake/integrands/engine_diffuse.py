"""dfg layouts that add an engine's pre-integrated diffuse term as channel B (Unity HDRP PreIntegratedFGD).

``charlie_fabric`` (HDRP PreIntegratedFGD_CharlieFabricLambert): the sheen lobe's multiscatter pair stored divided
by 2 pi, B the Fabric Lambert term:
    R = (1/2pi) ∫ D_charlie V_charlie (1 - v.h)^5 (n.l) dω_l,  G = (1/2pi) ∫ D_charlie V_charlie (n.l) dω_l,
    B = FabricLambertNoPI(alpha) = lerp(1, 0.5, alpha)   (constant in l: its cosine-weighted mean is itself)
HDRP's shader averages D V (n.l) over uniform hemisphere samples (pdf 1/(2 pi)) and leaves out the 2 pi "to keep the
values in [0, 1]"; the runtime multiplies it back: specularFGD = lerp(R, G, F0) * 2 pi (PreIntegratedFGD.hlsl).
D_charlie, V_charlie and the Lambda fit take alpha = r^2 (PerceptualRoughnessToRoughness), as lutbake's terms.

``multiscatter_disney``: R = ∫ f/F Fc (n.l), G = ∫ f/F (n.l) (the multiscatter layout, lutbake.kinds.dfg), and
    B = (1/pi) ∫ Fd_disney_hdrp(n.v, n.l, l.v, r) (n.l) dω_l - 0.5
the Disney diffuse FGD that HDRP stores shifted by -0.5 (its shader adds 0.5 back: diffuseFGD = preFGD.z + 0.5;
preIntegratedFGD_GGXDisneyDiffuse.shader, PreIntegratedFGD.hlsl). r is the perceptual roughness, alpha = r^2.

The diffuse integral is smooth over the hemisphere (no lobe), so it has its own quadrature: product Gauss-Legendre
in mu = n.l in (0, 1) and phi in (0, pi) (the integrand is even in phi), with the cosine folded in:
    (1/pi) ∫ g (n.l) dω = (2/pi) ∫_0^pi ∫_0^1 g(mu, phi) mu dmu dphi.
The integrand is a polynomial in mu and cos(phi) times sqrt(1 - mu^2) (through l.v): DIFFUSE_ORDER nodes per
dimension reach 1e-9 (tested against scipy's adaptive quadrature).
The layouts' names, channels and reconstruction text are declared in lutbake.layouts.hdrp.
"""

from __future__ import annotations

import functools

import numpy as np
import warp as wp

from ..layouts.hdrp import HDRP_UNIFORM_SCALE
from ..runtime.warp_runtime import MODULE_OPTIONS, load_module
from ..sampling.plan import TexelPlan
from ..terms.engine_diffuse import Fd_disney_hdrp, Fd_fabric_lambert_hdrp

wp.set_module_options(MODULE_OPTIONS)

DIFFUSE_ORDER = 24  # Gauss-Legendre nodes per dimension (mu, phi)
HDRP_DIFFUSE_OFFSET = 0.5  # HDRP stores the Disney FGD minus 0.5 (range [0.5, 1.5] -> [0, 1] for its UNORM target)


@functools.lru_cache(maxsize=None)
def diffuse_kernel():
    @wp.kernel(enable_backward=False)
    def disney_fgd(
        nov: wp.array(dtype=float),
        r: wp.array(dtype=float),
        x: wp.array(dtype=wp.float64),
        w: wp.array(dtype=wp.float64),
        out: wp.array(dtype=wp.float64),
    ):
        i = wp.tid()
        NoV = nov[i]
        v = wp.vec3(wp.sqrt(wp.max(1.0 - NoV * NoV, 0.0)), 0.0, NoV)
        acc = wp.float64(0.0)
        n = x.shape[0]
        for a in range(n):
            mu = float(wp.float64(0.5) * (x[a] + wp.float64(1.0)))
            sin_l = wp.sqrt(wp.max(1.0 - mu * mu, 0.0))
            for b in range(n):
                phi = float(wp.float64(0.5) * (x[b] + wp.float64(1.0))) * wp.pi
                l = wp.vec3(sin_l * wp.cos(phi), sin_l * wp.sin(phi), mu)
                g = Fd_disney_hdrp(NoV, mu, wp.dot(l, v), r[i]) * mu
                acc += w[a] * w[b] * wp.float64(g)
        # (2/pi) * (1/2 for mu in (0, 1)) * (pi/2 for phi in (0, pi)) = 1/2
        out[i] = acc * wp.float64(0.5)

    return disney_fgd


def disney_fgd(nov: np.ndarray, perceptual_roughness: np.ndarray, device: str = "cpu") -> np.ndarray:
    """(1/pi) ∫ Fd_disney_hdrp (n.l) dω_l at every (NoV, r), float64 (no -0.5 offset)."""
    x, w = np.polynomial.legendre.leggauss(DIFFUSE_ORDER)
    out = wp.zeros(len(nov), dtype=wp.float64, device=device)
    wp.launch(
        diffuse_kernel(),
        dim=len(nov),
        device=device,
        inputs=[
            wp.array(np.ascontiguousarray(nov, np.float32), dtype=float, device=device),
            wp.array(np.ascontiguousarray(perceptual_roughness, np.float32), dtype=float, device=device),
            wp.array(x, dtype=wp.float64, device=device),
            wp.array(w, dtype=wp.float64, device=device),
            out,
        ],
    )
    return out.numpy()


@functools.lru_cache(maxsize=None)
def fabric_kernel():
    @wp.kernel(enable_backward=False)
    def fabric_lambert(r: wp.array(dtype=float), out: wp.array(dtype=wp.float64)):
        i = wp.tid()
        out[i] = wp.float64(Fd_fabric_lambert_hdrp(r[i] * r[i]))

    return fabric_lambert


def fabric_lambert(perceptual_roughness: np.ndarray, device: str = "cpu") -> np.ndarray:
    """HDRP's FabricLambertNoPI(alpha = r^2) at every texel: its cosine-weighted hemisphere mean (a constant)."""
    out = wp.zeros(len(perceptual_roughness), dtype=wp.float64, device=device)
    r = wp.array(np.ascontiguousarray(perceptual_roughness, np.float32), dtype=float, device=device)
    wp.launch(fabric_kernel(), dim=len(out), device=device, inputs=[r, out])
    return out.numpy()


def fabric_channel(base: np.ndarray, nov: np.ndarray, rough: np.ndarray, device: str = "cpu") -> np.ndarray:
    """charlie_fabric's table from the sheen pair (n, 2) at texels (nov, perceptual roughness): R, G / 2 pi and
    B = FabricLambertNoPI."""
    b = fabric_lambert(rough, device)
    return np.concatenate([base / HDRP_UNIFORM_SCALE, b[:, None]], axis=1)


def disney_channel(base: np.ndarray, nov: np.ndarray, rough: np.ndarray, device: str = "cpu") -> np.ndarray:
    """multiscatter_disney's table from the multiscatter pair (n, 2): B = the Disney FGD - 0.5."""
    b = disney_fgd(nov, rough, device) - HDRP_DIFFUSE_OFFSET
    return np.concatenate([base, b[:, None]], axis=1)


# lutbake.layouts.base.EngineChannel.name -> (the layout's table from the base channels, the Warp kernel it launches)
CHANNELS = {"disney": (disney_channel, diffuse_kernel), "fabric": (fabric_channel, fabric_kernel)}


def with_diffuse_channel(plan: TexelPlan, nov: np.ndarray, perceptual_roughness: np.ndarray, channel) -> TexelPlan:
    """The plan of the base layout turned into the engine layout's (``channel``, lutbake.layouts.base.EngineChannel:
    channel B appended by its CHANNELS function, same tiles)."""
    base_tile = plan.run_tile
    nch = plan.n_channels
    compute, kernel = CHANNELS[channel.name]

    def run_tile(start: int, stop: int, device: str) -> np.ndarray:
        """The layout's channels from the base tile's, then the base tile's aux columns (TexelPlan.aux_channels)."""
        s = slice(start, stop)
        base = base_tile(start, stop, device)
        table = compute(base[:, :nch], nov[s], perceptual_roughness[s], device)
        return np.concatenate([table, base[:, nch:]], axis=1)

    base_prepare = plan.prepare

    def prepare(device: str) -> None:
        base_prepare(device)
        load_module(kernel().module, device=device)

    base_estimate = plan.error_estimate

    def base_data(data: np.ndarray) -> np.ndarray:
        """The base layout's tile data: its channels (rescaled) and aux columns, without channel B."""
        return np.concatenate([data[:, :nch] * channel.scale, data[:, nch + 1 :]], axis=1)

    if base_estimate is not None:  # the specular channels' estimate, on the base layout's values; B: the tests
        plan.error_estimate = lambda data, device: base_estimate(base_data(data), device)
    plan.run_tile, plan.prepare, plan.n_channels = run_tile, prepare, nch + 1
    return plan


def perceptual_roughness_grid(axes) -> np.ndarray:
    """Per-texel perceptual roughness of a [y, x] dfg grid (row-major), from the roughness axis' values."""
    y_axis, x_axis = axes
    rough, other = (y_axis, x_axis) if x_axis.name == "NoV" else (x_axis, y_axis)
    r = rough.values().astype(np.float64)
    if rough.name == "alpha":
        r = np.sqrt(r)
    return np.repeat(r, other.count) if rough is y_axis else np.tile(r, other.count)
