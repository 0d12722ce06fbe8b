"""Host data and host helpers for the conductor Fresnel terms: complex indices of common metals and
the least-squares fit of F_lazanyi's error term.

Metal table: n + ik at three wavelengths per RGB channel (R ~ 650 nm, G ~ 550 nm, B ~ 450 nm).
Sources, per entry (values are the tabulated rows nearest those wavelengths):
- gold, silver, copper: Johnson & Christy 1972, "Optical constants of the noble metals", Phys. Rev. B 6,
  4370, Table I, rows at 1.88 eV (659 nm), 2.26 eV (549 nm) and 2.75 eV (451 nm) (as listed on
  refractiveindex.info).
- aluminium: R is the seed's example, 1.3 + 7.48i at 610 nm (Gotanda 2014 course notes, Fig. 2);
  G and B are Rakic 1998, "Algorithm for the determination of intrinsic optical constants of metal
  films: application to aluminum", Appl. Opt. 37, 5271, at 550 nm and 450 nm (refractiveindex.info).
The tests check the f0 every entry implies against the lecture's table of linear f0 (003, "Fresnel
reflections at 0° for some materials"); spectrally integrated RGB differs from three wavelengths, so
the tolerance is loose (0.15).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LAZANYI_ALPHA = 6.0  # the fixed exponent of the error term of F_lazanyi


@dataclass(frozen=True)
class Metal:
    name: str
    wavelengths_nm: tuple[float, float, float]  # R, G, B
    n: tuple[float, float, float]
    k: tuple[float, float, float]
    source: str

    def f0(self) -> np.ndarray:
        """Normal-incidence reflectance per channel: ((n-1)^2 + k^2) / ((n+1)^2 + k^2)."""
        n, k = np.asarray(self.n), np.asarray(self.k)
        return ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)


_JC = "Johnson & Christy 1972, Table I (1.88, 2.26, 2.75 eV)"
METALS = {
    "aluminium": Metal(
        "aluminium",
        (610.0, 550.0, 450.0),
        (1.3, 0.958, 0.618),
        (7.48, 6.69, 5.47),
        "R: Gotanda 2014 course notes, Fig. 2 (610 nm); G, B: Rakic 1998",
    ),
    "gold": Metal("gold", (659.0, 549.0, 451.0), (0.14, 0.43, 1.38), (3.697, 2.455, 1.914), _JC),
    "silver": Metal("silver", (659.0, 549.0, 451.0), (0.05, 0.06, 0.04), (4.483, 3.586, 2.657), _JC),
    "copper": Metal("copper", (659.0, 549.0, 451.0), (0.21, 1.02, 1.24), (4.205, 2.577, 2.397), _JC),
}
ALIASES = {"aluminum": "aluminium", "al": "aluminium", "au": "gold", "ag": "silver", "cu": "copper"}


def lookup_metal(name: str) -> Metal:
    """The metal registered under ``name`` (or an alias); KeyError lists the valid names."""
    key = ALIASES.get(name.lower(), name.lower())
    if key not in METALS:
        raise KeyError(f"unknown metal {name!r}; valid: {', '.join(sorted(METALS))}")
    return METALS[key]


# -- host (numpy) forms, used to fit and to average; the @wp.funcs are tested against independent references
def conductor_np(n, k, c):
    """Exact unpolarised reflectance from vacuum into n + ik, by complex arithmetic (Born & Wolf 14.2)."""
    eta = np.asarray(n, dtype=np.complex128) + 1j * np.asarray(k, dtype=np.float64)
    c = np.clip(np.asarray(c, dtype=np.float64), 0.0, 1.0)
    ct = np.sqrt(1.0 - (1.0 - c * c) / (eta * eta))
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return 0.5 * (np.abs(rs) ** 2 + np.abs(rp) ** 2)


def lazanyi_np(n, k, a, c, alpha=LAZANYI_ALPHA):
    c = np.clip(np.asarray(c, dtype=np.float64), 0.0, 1.0)
    m = 1.0 - c
    return ((n - 1) ** 2 + 4 * n * m**5 + k**2) / ((n + 1) ** 2 + k**2) - a * c * m**alpha


def fit_lazanyi_a(n: float, k: float, alpha: float = LAZANYI_ALPHA, samples: int = 1024) -> float:
    """Least-squares ``a`` of F_lazanyi against the exact curve, uniform in theta on [0, pi/2]:
    a = sum(r w) / sum(w^2), r = schlick_nk - exact, w = c (1-c)^alpha (closed form: the error term is
    linear in a)."""
    theta = (np.arange(samples) + 0.5) / samples * (np.pi / 2)
    c = np.cos(theta)
    r = lazanyi_np(n, k, 0.0, c, alpha) - conductor_np(n, k, c)
    w = c * (1 - c) ** alpha
    return float(np.sum(r * w) / np.sum(w * w))
