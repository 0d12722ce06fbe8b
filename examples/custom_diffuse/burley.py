"""A diffuse lobe of one's own: Burley's diffuse (the Disney principled BRDF's base diffuse), for rho = 1,

    Fd = (1/pi) (1 + (F_D90 - 1)(1 - n.l)^5) (1 + (F_D90 - 1)(1 - n.v)^5),   F_D90 = 0.5 + 2 r (l.h)^2,

with (l.h)^2 = (1 + l.v) / 2 and r its roughness (the table's sigma axis). Burley 2012, "Physically-Based Shading at
Disney", Sec. 5.3, Eq. 3. Its albedo under uniform light is not 1 (it gains energy at grazing for rough surfaces and
loses it for smooth ones), which is what the diffuse table records.
"""

import warp as wp

import lutbake


@wp.func
def Fd_burley(rho: float, NoL: float, NoV: float, LoV: float, r: float):
    """Burley 2012, Eq. 3, for NoL, NoV > 0 (the diffuse kinds integrate over the upper hemisphere only)."""
    LoH2 = 0.5 * (1.0 + LoV)
    fd90 = 0.5 + 2.0 * r * LoH2
    ml = 1.0 - NoL
    mv = 1.0 - NoV
    fl = 1.0 + (fd90 - 1.0) * ml * ml * ml * ml * ml
    fv = 1.0 + (fd90 - 1.0) * mv * mv * mv * mv * mv
    return rho / wp.pi * fl * fv


lutbake.register_diffuse(
    "burley",
    Fd_burley,
    description="Burley's diffuse, (1/pi)(1 + (F_D90 - 1)(1 - n.l)^5)(1 + (F_D90 - 1)(1 - n.v)^5), sigma = its r",
    citation="Burley 2012, Eq. 3",
)
