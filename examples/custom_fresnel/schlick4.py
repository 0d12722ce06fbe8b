"""A Fresnel term of one's own: Schlick's form with a fourth power, F = f0 + (1 - f0)(1 - v.h)^4.

Some engines ship this cheaper variant; the split-sum table must then integrate the same F, or every specular
highlight is off by the difference. It is linear in f0, so the dfg kind factors f0 out as for Schlick's:
E = f0 * scale + bias with scale = ∫ f/F (1 - Fc) (n.l) dω, bias = ∫ f/F Fc (n.l) dω, Fc = (1 - v.h)^4.
"""

import warp as wp

import lutbake


@wp.func
def Fc_schlick4(c: float):
    """(1 - c)^4, clamped to [0, 1] (c = v.h)."""
    m = wp.clamp(1.0 - c, 0.0, 1.0)
    m2 = m * m
    return m2 * m2


@wp.func
def F_schlick4(f0: float, c: float):
    """f0 + (1 - f0)(1 - c)^4."""
    return f0 + (1.0 - f0) * Fc_schlick4(c)


lutbake.register_fresnel(
    "schlick4",
    F_schlick4,
    Fc=Fc_schlick4,
    linear_in_f0=True,
    description="f0 + (1 - f0)(1 - v.h)^4: Schlick's form with a fourth power",
    citation="Schlick 1994, Eq. 24, exponent 4",
)
