"""Diffuse terms engines pre-integrate beside their specular DFG (Unity HDRP's PreIntegratedFGD).

- ``Fd_disney_hdrp``: Burley's diffuse (Burley 2012, "Physically-Based Shading at Disney", §5.3, Eq. in the
  "diffuse" section) as Unity HDRP writes it without 1/pi (DisneyDiffuseNoPI, com.unity.render-pipelines.core
  ShaderLibrary/BSDF.hlsl):
      fd90 = 0.5 + r + r (l.v)        [= 0.5 + 2 r (l.h)^2, since 2 (l.h)^2 = 1 + l.v]
      f = (1 + (fd90 - 1)(1 - n.l)^5)(1 + (fd90 - 1)(1 - n.v)^5) / 1.03571
  with r the *perceptual* roughness and 1.03571 HDRP's normalisation (the albedo at r = 1, normal view).
  The BRDF is f / pi. Domains: n.l, n.v in [0, 1] (back-facing: 0), r in [0, 1].
- ``Fd_fabric_lambert_hdrp``: HDRP's "FabricLambertNoPI" (BSDF.hlsl, "empirical"): lerp(1, 0.5, alpha) with
  alpha = r^2 as its PreIntegratedFGD_CharlieFabricLambert passes it; the BRDF is that / pi, constant over l.
"""

from __future__ import annotations

import warp as wp

HDRP_DISNEY_NORMALISATION = 1.03571


@wp.func
def F_schlick_f90(f90: float, cos_theta: float):
    """Schlick's interpolation from 1 to f90: 1 + (f90 - 1)(1 - cos)^5 (HDRP F_Schlick(1, f90, cos))."""
    x = wp.clamp(1.0 - cos_theta, 0.0, 1.0)
    x2 = x * x
    return 1.0 + (f90 - 1.0) * x2 * x2 * x


@wp.func
def Fd_disney_hdrp(NoV: float, NoL: float, LoV: float, perceptual_roughness: float):
    """Burley diffuse without 1/pi, HDRP's normalisation (module docstring); 0 when n.l or n.v <= 0."""
    if NoL <= 0.0 or NoV <= 0.0:
        return 0.0
    fd90 = 0.5 + perceptual_roughness + perceptual_roughness * LoV
    return F_schlick_f90(fd90, NoL) * F_schlick_f90(fd90, NoV) / HDRP_DISNEY_NORMALISATION


@wp.func
def Fd_fabric_lambert_hdrp(alpha: float):
    """HDRP's fabric Lambert without 1/pi: lerp(1, 0.5, alpha) (module docstring)."""
    return 1.0 + (0.5 - 1.0) * alpha
