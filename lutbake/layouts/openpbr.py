"""OpenPBR (adobe/openpbr-bsdf, impl/data/openpbr_energy_arrays.h): the energy-complement tables of the reference
implementation, UNORM16 arrays in its layout array[ior][alpha][cos] (32^3) and array[ior][alpha] (32^2).

    z = IOR (indices 0-15: 1/eta = 1 + 1.5 (15 - i)/15, 16-31: eta = 1 + 1.5 (i - 16)/15), y = sqrt(alpha) = i/31,
    x = cos theta = i/31 (0 clamped to NOV_MIN)
    R = 1 - (E_R + E_T) (IdealDielectricEnergyComplement), G = 1 - E_R (OpaqueDielectricEnergyComplement),
    B = 1 - E(F = 1) (IdealMetalEnergyComplement, the same in every IOR slice)
kind dielectric_avg: the three averages and A = OpenPBR's IdealDielectricReflectionRatio (lutbake.integrands.
dielectric_ratio, from the averages of both sides of the interface: row z and its mirror row 31 - z, eta -> 1/eta).
Both fix GGX with separable Smith (G_V G_L) and the grid.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..axes import Axis
from ..integrands import dielectric_ratio
from .base import EngineTable, Layout, Storage, Terms, ior_axis, ior_values, nov_alpha_grid

OPENPBR_SIZE = 32  # OpenPBR_EnergyTableSize
OPENPBR_IOR_MAX = 2.5  # OpenPBR_IorMax
OPENPBR_MS_ALPHA_MIN = (
    0.0016  # below it OpenPBR's multiple-scattering lobe is off (lutbake.integrands.dielectric_ratio)
)
SYMMETRIC = (
    "OpenPBR's: the first N/2 indices hold 1/eta = hi - (hi - 1) i/(N/2 - 1) (eta from 1/hi up to 1), the "
    "last N/2 hold eta = 1 + (hi - 1) i/(N/2 - 1) (1 up to hi); N even, lo ignored"
)
SOURCE = "adobe/openpbr-bsdf impl/data/openpbr_energy_arrays.h, impl/openpbr_energy_tables.h"


def etas() -> np.ndarray:
    """eta at OpenPBR's 32 IOR indices (symmetric mapping, hi = 2.5)."""
    return ior_values(OPENPBR_SIZE, 1.0 / OPENPBR_IOR_MAX, OPENPBR_IOR_MAX, "endpoint", "symmetric")


def grid_3d(o: dict):
    """[ior, sqrt(alpha), cos] 32^3, endpoint texels."""
    n = OPENPBR_SIZE
    e = etas()
    rough = Axis("perceptual_roughness", "y", n, 0.0, 1.0, texel="endpoint")
    nov = Axis("NoV", "x", n, 0.0, 1.0, texel="endpoint")
    grid = nov_alpha_grid([rough, nov])
    extra = {"ior_axis": SYMMETRIC + f", hi = {OPENPBR_IOR_MAX}"}
    return [ior_axis(e, "z"), rough, nov], np.tile(grid[0], n), np.tile(grid[1], n), np.repeat(e, n * n), extra


def grid_avg(o: dict):
    """[ior, sqrt(alpha)] 32^2: (axes, alpha, eta per texel)."""
    e = etas()
    rough = Axis("perceptual_roughness", "x", OPENPBR_SIZE, 0.0, 1.0, texel="endpoint")
    return [ior_axis(e, "y"), rough], np.tile(rough.alpha(), len(e)), np.repeat(e, rough.count)


def complements(e: np.ndarray) -> np.ndarray:
    """(E_R, E_T, E(F = 1)) -> (1 - (E_R + E_T), 1 - E_R, 1 - E(F = 1))."""
    return np.stack([1.0 - (e[:, 0] + e[:, 1]), 1.0 - e[:, 0], 1.0 - e[:, 2]], axis=1)


def complement_errors(err: np.ndarray) -> np.ndarray:
    """Error bounds of complements from those of (E_R, E_T, E(F = 1))."""
    return np.stack([err[:, 0] + err[:, 1], err[:, 0], err[:, 2]], axis=1)


def kernel_tolerance(tol) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """1 - (E_R + E_T) adds two channels' errors (half the absolute tolerance each); a complement's relative
    tolerance does not carry over (0)."""
    a = tol.absolute
    return (a / 2, a / 2, a), (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class MirrorRatio:
    """OpenPBR's reflection ratio (channel A of the average table): x at (eta, alpha) needs E_c,avg at (1/eta, alpha)
    too, the mirror row N - 1 - z (lutbake.integrands.dielectric_ratio)."""

    size: int = OPENPBR_SIZE
    alpha_min: float = OPENPBR_MS_ALPHA_MIN
    metadata: str = dielectric_ratio.METADATA

    def mirror(self, t: np.ndarray) -> np.ndarray:
        """The texels of the mirror rows of texels t (row-major [ior][alpha])."""
        return (self.size - 1 - t // self.size) * self.size + t % self.size

    def ratio(self, ec, ec_m, eta) -> np.ndarray:
        return dielectric_ratio.reflection_ratio(ec, ec_m, eta)

    def ratio_error(self, ec, ec_m, err, err_m, eta) -> np.ndarray:
        """A bound on the ratio's error from its two averages' (|x(corner) - x| over the four corners ec +- err,
        ec_m +- err_m: x is monotone in each average on each branch)."""
        x = self.ratio(ec, ec_m, eta)
        corners = [self.ratio(ec + a * err, ec_m + b * err_m, eta) for a in (-1, 1) for b in (-1, 1)]
        return np.max(np.abs(np.array(corners) - x), axis=0)


FIXED = {
    "terms": Terms(ndf="ggx", masking="smith_separable"),
    "split_sum": None,
    "integrand": "exact_metal",
    "audit": ("openpbr_arrays",),  # lutbake.commands.audit_tables.audit_openpbr: the header's arrays, not a 2D LUT
}
STORAGE = Storage(formats=("openpbr_h",), exclusive=("openpbr_h",))
OPENPBR = Layout(
    name="openpbr",
    kind="dielectric",
    engine="OpenPBR reference implementation (adobe/openpbr-bsdf)",
    summary="OpenPBR reference [ior][alpha][cos] 32^3: 1 - (E_R + E_T), 1 - E_R, 1 - E(F = 1) (grid fixed)",
    channels={
        "ideal_dielectric_energy_complement": "1 - (E_R + E_T)",
        "opaque_dielectric_energy_complement": "1 - E_R",
        "ideal_metal_energy_complement": "1 - E with F = 1 (reflection only; independent of the IOR)",
    },
    shader="openpbr_look_up_*_energy_complement(ior, alpha, cos): exact indices ior -> "
    "(ior < 1 ? 15 - 15 (1/ior - 1)"
    "/1.5 : 16 + 15 (ior - 1)/1.5), sqrt(alpha) * 31, cos * 31, clamped to [0, 31], trilinear over "
    "array[ior][alpha][cos] (cos fastest); values UNORM16 / 65535",
    source=SOURCE,
    grid=grid_3d,
    texels=lambda o: OPENPBR_SIZE**3,
    to_stored=complements,
    error_to_stored=complement_errors,
    kernel_tolerance=kernel_tolerance,
    storage=STORAGE,
    **FIXED,
)
OPENPBR_AVG = replace(
    OPENPBR,
    kind="dielectric_avg",
    channels={
        "ideal_dielectric_average_energy_complement": "1 - 2 ∫ (E_R + E_T) mu dmu",
        "opaque_dielectric_average_energy_complement": "1 - 2 ∫ E_R mu dmu",
        "ideal_metal_average_energy_complement": "1 - 2 ∫ E(F = 1) mu dmu",
        "ideal_dielectric_reflection_ratio": "x: the multiple-scattering lobe's reflected share, Kulla-Conty split of "
        "the two sides' E_c,avg (lutbake.integrands.dielectric_ratio), symmetric transmission",
    },
    shader="openpbr_look_up_*_average_energy_complement(ior, alpha) and "
    "openpbr_look_up_ideal_dielectric_reflection_ratio(ior, alpha): bilinear over array[ior][alpha] (alpha "
    "fastest), indices as the 3D tables",
    grid=grid_avg,
    texels=lambda o: OPENPBR_SIZE**2,
    kernel_tolerance=None,
    mirror_ratio=MirrorRatio(),
    extra={"reflection_ratio": dielectric_ratio.METADATA},
)

LAYOUTS = (OPENPBR, OPENPBR_AVG)
TABLES = (
    EngineTable(
        "OpenPBR",
        "openpbr",
        "openpbr_energy_3d",
        "dielectric",
        "openpbr",
        {"layout": "openpbr", "format": "openpbr_h"},
        SOURCE,
        "openpbr_energy_arrays.h (UNORM16 uint16_t arrays)",
        shipped="openpbr_energy_tables.npz",
        shader="openpbr_look_up_*_energy_complement(ior, alpha, cos)",
    ),
    EngineTable(
        "OpenPBR",
        "openpbr",
        "openpbr_energy_avg",
        "dielectric_avg",
        "openpbr",
        {"layout": "openpbr", "format": "openpbr_h"},
        SOURCE,
        "openpbr_energy_arrays.h (UNORM16 uint16_t arrays)",
    ),
)
