"""The one edge-case policy of lutbake: every guard against grazing angles, alpha -> 0 and
back-facing samples uses a constant from here, so the behaviour is written down in one place.

- ``ALPHA_MIN``: below it a lobe is *effectively smooth* (pbrt-v4's ``EffectivelySmooth``). Where the
  integrand has a closed-form limit at alpha = 0 (the microfacet specular form: the mirror, E = channels(n.v),
  so E = 1 for F = 1 at any n.v > 0), texels with alpha < ALPHA_MIN take that limit exactly: their kernel
  input is alpha = 0 and the estimator evaluates the integrand's ``mirror`` instead of a quadrature
  (``effective_alpha``). Where no closed form exists (the Charlie sheen lobe, Blinn-Phong and
  Ashikhmin-Shirley lobes, the microfacet diffuse model) alpha is clamped to ALPHA_MIN (mitsuba3 uses the
  same 1e-4); the change to such a table is O(ALPHA_MIN^2) ~ 1e-8 away from grazing. The axis metadata lists
  the alpha of the axis (r^2, unclamped) and ``lutbake:alpha_policy`` says which branch the table took.
- ``NOV_MIN``: the smallest cosine (n.v, n.l) an axis integrates; at a cosine of 0 the direction lies in the
  surface, every term is continuous there but per-sample weights divide by it. Every cosine axis (NoV, NoL)
  is clamped to it, and every polar-angle axis (theta_v, theta_l) to acos(NOV_MIN); the clamped value is the
  one integrated and the one the axis lists (``axis_edge``).
- ``COS_EPS``: below this, a cosine is treated as zero (the sample is back-facing or on the horizon):
  the masking functions return 0 and integrands contribute nothing. No term ever divides by a cosine
  that has not passed this test, so no NaN or Inf can reach a table.
"""

from __future__ import annotations

import math

import numpy as np

ALPHA_MIN = 1.0e-4
NOV_MIN = 1.0e-4
COS_EPS = 1.0e-7
COSINE_AXES = ("NoV", "NoL")
ANGLE_AXES = ("theta_v", "theta_l")
THETA_MAX = math.acos(NOV_MIN)

ALPHA_POLICY_MIRROR = f"alpha < {ALPHA_MIN:g}: the exact mirror limit (alpha = 0); otherwise integrated"
ALPHA_POLICY_CLAMP = f"alpha clamped to >= {ALPHA_MIN:g} (no closed-form alpha -> 0 limit for this integrand)"


def effective_alpha(alpha, mirror: bool) -> np.ndarray:
    """The alpha a kernel integrates (float32): 0 (the mirror branch) below ALPHA_MIN if the integrand has a
    closed-form mirror limit, else max(alpha, ALPHA_MIN)."""
    a = np.asarray(alpha, dtype=np.float64)
    if mirror:  # compared in float32, so an alpha of float32(ALPHA_MIN) is integrated, not mirrored
        return np.where(a.astype(np.float32) < np.float32(ALPHA_MIN), 0.0, a).astype(np.float32)
    return np.maximum(a, ALPHA_MIN).astype(np.float32)


def alpha_policy(mirror: bool) -> str:
    return ALPHA_POLICY_MIRROR if mirror else ALPHA_POLICY_CLAMP


def axis_edge(name: str, values: np.ndarray) -> np.ndarray:
    """An axis' values after the edge policy: cosines >= NOV_MIN, polar angles <= acos(NOV_MIN)."""
    if name in COSINE_AXES:
        return np.maximum(values, NOV_MIN)
    if name in ANGLE_AXES:
        return np.minimum(values, THETA_MAX)
    return values


def axis_edge_text(name: str) -> str | None:
    if name in COSINE_AXES:
        return f"{name} >= {NOV_MIN:g} (lutbake.edge.NOV_MIN)"
    if name in ANGLE_AXES:
        return f"{name} <= acos({NOV_MIN:g}) = {THETA_MAX:.9g} (lutbake.edge.NOV_MIN)"
    return None
