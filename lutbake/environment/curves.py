"""The engines' roughness <-> mip curves: which perceptual roughness r (alpha = r^2) each mip of a prefiltered
specular cube holds, so that the engine's shader, which turns r into a mip (lod), reads the right lobe. Data, one
record per curve; ``roughness(mip, mips)`` inverts the shader's lod(r) at integer mips (0 <= r <= 1).

- ``linear``: lod = r (M - 1), M mips. Bevy ``environment_map.wgsl``: ``radiance_level = perceptual_roughness *
  f32(smallest_specular_mip_level)``, smallest = textureNumLevels - 1 (read this session); glTF Sample Viewer
  ``ibl.glsl``: ``lod = roughness * float(u_MipCount - 1)`` (as the issue quotes it; not re-read this session).
- ``filament``: lod = L1 r (2 - r), L1 = iblRoughnessOneLevel = M - 1 (Filament ``light_indirect.fs``
  ``perceptualRoughnessToLod``, as the issue quotes it).
- ``hdrp``: lod = 6 r (1.7 - 0.7 r) (Unity HDRP ``PerceptualRoughnessToMipmapLevel``, UNITY_SPECCUBE_LOD_STEPS = 6,
  as the issue quotes it).
- ``godot``: lod = sqrt(r) (M - 1) (as the issue quotes it).
- ``babylon``: lod = log2(size alpha) s + o, alpha = r^2, s = lodGenerationScale = 0.8, o = lodGenerationOffset = 0
  (Babylon.js ``pbrBlockReflection`` ``getLodFromAlphaG(vReflectionMicrosurfaceInfos.x, alphaG) *
  vReflectionMicrosurfaceInfos.y + vReflectionMicrosurfaceInfos.z``; its own prefilter ``HDRFiltering`` bakes mip m at
  alphaG = 2^((m - o) / s) / size, mip 0 at 0; @babylonjs/core 9.37.1, read). size = 2^(M - 1) (the full chain); r
  past 1 (alphaG > 1, mips the shader's roughness <= 1 never reaches but by trilinear blending) is clamped to 1.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

BABYLON_LOD_SCALE = 0.8  # Babylon.js BaseTexture.lodGenerationScale's default


@dataclass(frozen=True)
class MipCurve:
    name: str
    lod: str  # the shader's formula
    source: str
    roughness_of: Callable[[float, int], float]  # (mip, mip count) -> perceptual roughness

    def roughness(self, mip: int, mips: int) -> float:
        """The perceptual roughness the shader expects in mip ``mip`` of ``mips``, clamped to [0, 1]."""
        if mips < 2:
            return 0.0
        return min(1.0, max(0.0, self.roughness_of(mip, mips)))


def _filament(mip: int, mips: int) -> float:
    """r with (M - 1) r (2 - r) = mip: r = 1 - sqrt(1 - mip / (M - 1))."""
    return 1.0 - math.sqrt(max(0.0, 1.0 - mip / (mips - 1)))


def _hdrp(mip: int, mips: int) -> float:
    """r with 6 r (1.7 - 0.7 r) = mip: 0.7 r^2 - 1.7 r + mip / 6 = 0, the root in [0, 1] (mips past 6: r = 1)."""
    c = min(1.0, mip / 6.0)
    return (1.7 - math.sqrt(1.7 * 1.7 - 4 * 0.7 * c)) / (2 * 0.7)


CURVES = {
    c.name: c
    for c in (
        MipCurve(
            "linear",
            "lod = r * (M - 1)",
            "glTF Sample Viewer ibl.glsl (u_MipCount); Bevy environment_map.wgsl (textureNumLevels)",
            lambda m, n: m / (n - 1),
        ),
        MipCurve(
            "filament", "lod = (M - 1) * r * (2 - r)", "Filament light_indirect.fs perceptualRoughnessToLod", _filament
        ),
        MipCurve("hdrp", "lod = 6 * r * (1.7 - 0.7 r)", "Unity HDRP ImageBasedLighting.hlsl", _hdrp),
        MipCurve(
            "godot", "lod = sqrt(r) * (M - 1)", "Godot scene_forward_clustered.glsl", lambda m, n: (m / (n - 1)) ** 2
        ),
        MipCurve(
            "babylon",
            "lod = 0.8 * log2(size * r^2), size = 2^(M - 1)",
            "Babylon.js pbrBlockReflection getLodFromAlphaG, HDRFiltering (lodGenerationScale 0.8)",
            lambda m, n: 0.0 if m == 0 else math.sqrt(2.0 ** (m / BABYLON_LOD_SCALE) / 2.0 ** (n - 1)),
        ),
    )
}
