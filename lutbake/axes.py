"""Table axes: every grid is declared, never implied.

An axis maps an index i in [0, count) to a parameter in three explicit steps:
1. texel convention -> t in [0, 1]: ``center`` t = (i + 0.5)/count (the default; never hits an
   endpoint, as Filament and glTF sample), ``endpoint`` t = i/(count - 1) (Blender EEVEE).
2. mapping -> value: ``linear`` value = lo + (hi - lo) t.
3. edge policy (lutbake.edge): n.v >= NOV_MIN, alpha >= ALPHA_MIN. The clamped value is the one
   integrated and the one listed in the EXR metadata (``values`` / ``alpha``).
Index 0 is the first value: image row 0 holds y index 0, column 0 holds x index 0.
A roughness axis also carries the NDF alpha at every index: alpha = r^2 for ``perceptual_roughness``,
alpha = value for ``alpha``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .edge import ALPHA_MIN, NOV_MIN

IMAGE_DIMS = {"x": "columns", "y": "rows", "z": "slices",
              "y_block": "row blocks: image row = (y_block index) * (count of the y axis) + (y index)"}
TEXELS = {"center": "t = (i + 0.5) / N", "endpoint": "t = i / (N - 1)"}
MAPPINGS = {"linear": "value = lo + (hi - lo) * t",
            "listed": "value = values[i], listed in the config (not evenly spaced in general: map a parameter to a "
                      "fractional index by searching the values)"}
ROUGHNESS_PARAMS = {
    "perceptual": "the axis holds perceptual roughness r; alpha = r^2",
    "alpha": "the axis holds the NDF alpha directly",
}


@dataclass(frozen=True)
class Axis:
    name: str  # NoV, perceptual_roughness, alpha, ...
    dim: str  # x = columns, y = rows, z = slices, y_block = blocks of rows (a 4th axis flattened into the rows)
    count: int
    lo: float = 0.0
    hi: float = 1.0
    texel: str = "center"
    mapping: str = "linear"
    listed: tuple[float, ...] = ()  # mapping "listed": the value of every index (count = len(listed))

    def t(self) -> np.ndarray:
        i = np.arange(self.count, dtype=np.float64)
        if self.texel == "center":
            return (i + 0.5) / self.count
        return i / max(self.count - 1, 1)

    def values(self) -> np.ndarray:
        """The parameter integrated at every index (float32, after the edge policy)."""
        if self.mapping == "listed":
            v = np.asarray(self.listed, dtype=np.float64)
        else:
            v = self.lo + (self.hi - self.lo) * self.t()
        if self.name == "NoV":
            v = np.maximum(v, NOV_MIN)
        return v.astype(np.float32)

    def alpha(self) -> np.ndarray | None:
        """NDF alpha at every index for a roughness axis (None otherwise)."""
        if self.name == "perceptual_roughness":
            a = self.values().astype(np.float64) ** 2
        elif self.name == "alpha":
            a = self.values().astype(np.float64)
        else:
            return None
        return np.maximum(a, ALPHA_MIN).astype(np.float32)

    def describe(self) -> dict:
        d = {
            "name": self.name,
            "dim": self.dim,
            "image": IMAGE_DIMS[self.dim],
            "count": self.count,
            "range": [self.lo, self.hi],
            "texel": self.texel,
            "texel_formula": TEXELS[self.texel],
            "mapping": self.mapping,
            "mapping_formula": MAPPINGS[self.mapping],
            "first": f"index 0 = {float(self.values()[0]):.9g}",
            "values": [float(x) for x in self.values()],
        }
        a = self.alpha()
        if a is not None:
            d["alpha"] = [float(x) for x in a]
            d["alpha_formula"] = "alpha = r^2" if self.name == "perceptual_roughness" else "alpha = value"
        return d
