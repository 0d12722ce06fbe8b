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

import numpy as np
import warp as wp

from ..runtime.warp_runtime import MODULE_OPTIONS, kernel_factory, load_module
from ..sampling.plan import StoredMap
from ..terms.engine_diffuse import Fd_disney_hdrp, Fd_fabric_lambert_hdrp

wp.set_module_options(MODULE_OPTIONS)

DIFFUSE_ORDER = 24  # Gauss-Legendre nodes per dimension (mu, phi)
HDRP_DIFFUSE_OFFSET = 0.5  # HDRP stores the Disney FGD minus 0.5 (range [0.5, 1.5] -> [0, 1] for its UNORM target)


@kernel_factory
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


@kernel_factory
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


def disney_b(nov: np.ndarray, perceptual_roughness: np.ndarray, device: str = "cpu") -> np.ndarray:
    """multiscatter_disney's channel B at texels (nov, perceptual roughness): the Disney FGD - 0.5."""
    return disney_fgd(nov, perceptual_roughness, device) - HDRP_DIFFUSE_OFFSET


def fabric_b(nov: np.ndarray, perceptual_roughness: np.ndarray, device: str = "cpu") -> np.ndarray:
    """charlie_fabric's channel B at texels (nov, perceptual roughness): FabricLambertNoPI (constant in NoV)."""
    return fabric_lambert(perceptual_roughness, device)


# lutbake.layouts.base.EngineChannel.name -> (its channel B at texels (nov, perceptual roughness), the Warp kernel it
# launches)
CHANNELS = {"disney": (disney_b, diffuse_kernel), "fabric": (fabric_b, fabric_kernel)}


def diffuse_channel(channel, nov: np.ndarray, perceptual_roughness: np.ndarray) -> StoredMap:
    """What the engine layout ``channel`` (lutbake.layouts.base.EngineChannel) stores of the base layout's channels,
    texel i at (nov[i], perceptual_roughness[i]): the base channels / channel.scale (HDRP's Charlie pair / 2 pi), then
    channel B (CHANNELS). Back, for the specular channels' error estimate: B dropped, the base channels times the scale
    (B itself: the tests)."""
    b_of, kernel = CHANNELS[channel.name]

    def to_stored(values: np.ndarray, texels: slice, device: str) -> np.ndarray:
        b = b_of(nov[texels], perceptual_roughness[texels], device)
        return np.concatenate([values / channel.scale, b[:, None]], axis=1)

    return StoredMap(
        to_stored,
        lambda stored: stored[:, :-1] * channel.scale,
        added=1,
        prepare=lambda device: load_module(kernel().module, device=device),
    )


def perceptual_roughness_grid(axes) -> np.ndarray:
    """Per-texel perceptual roughness of a [y, x] dfg grid (row-major), from the roughness axis' values."""
    y_axis, x_axis = axes
    rough, other = (y_axis, x_axis) if x_axis.name == "NoV" else (x_axis, y_axis)
    r = rough.values().astype(np.float64)
    if rough.name == "alpha":
        r = np.sqrt(r)
    return np.repeat(r, other.count) if rough is y_axis else np.tile(r, other.count)
