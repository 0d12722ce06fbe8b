"""Table axes: every grid is declared, never implied.

An axis maps an index i in [0, count) to a parameter in three explicit steps:
1. texel convention -> t in [0, 1]: ``center`` t = (i + 0.5)/count (the default; never hits an
   endpoint, as Filament and glTF sample), ``endpoint`` t = i/(count - 1) (Blender EEVEE).
   ``order = "hi_first"`` reverses the index: index i holds t of index N - 1 - i (image row 0 = t near 1,
   as Filament's DDS/EXR image order); ``lo_first`` (the default) keeps index 0 = t near 0.
2. mapping -> value: ``linear`` value = lo + (hi - lo) t; ``one_minus_t2`` value = lo + (hi - lo)(1 - t^2)
   (Blender EEVEE's NoV rows, t = sqrt(1 - NoV)); ``texel_offset`` value = lo + (hi - lo) min(t + 1/N, 1)
   (Filament cmgen's roughness rows, one texel rougher than their centres). Then ``clamp`` = [a, b]
   (optional) clamps the value (Blender: NoV in [1e-4, 0.9999]).
3. edge policy (lutbake.edge.axis_edge): every cosine axis (NoV, NoL) >= NOV_MIN, every polar-angle axis
   (theta_v, theta_l) <= acos(NOV_MIN). The clamped value is the one integrated and the one listed in the
   metadata (``values``; ``edge`` says the rule). alpha -> 0 is not clamped here: ``alpha`` lists the axis'
   alpha, and the integrand takes the exact mirror limit or clamps (lutbake.edge.effective_alpha).
Index 0 is the first value: image row 0 holds y index 0, column 0 holds x index 0.
``uv(value)`` inverts the chain: the texture coordinate (0 = first texel's outer edge) at which a
bilinear sampler reconstructs the table at a parameter value; ``uv_formula`` says it for shaders.
A roughness axis also carries the NDF alpha at every index: alpha = r^2 for ``perceptual_roughness``,
alpha = value for ``alpha``, and a ``sigma`` axis the GGX alpha of its ``alpha_map`` (SIGMA_TO_ALPHA).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .edge import axis_edge, axis_edge_text

IMAGE_DIMS = {
    "x": "columns",
    "y": "rows",
    "z": "slices",
    "y_block": "row blocks: image row = (y_block index) * (count of the y axis) + (y index)",
}
TEXELS = {"center": "t = (i + 0.5) / N", "endpoint": "t = i / (N - 1)"}
MAPPINGS = {
    "linear": "value = lo + (hi - lo) * t",
    "one_minus_t2": "value = lo + (hi - lo) * (1 - t^2), i.e. t = sqrt(1 - value) on [0, 1] (Blender EEVEE NoV)",
    "square": "value = lo + (hi - lo) * t^2, i.e. t = sqrt(value) on [0, 1] (Unity HDRP PreIntegratedFGD: "
    "x = sqrt(NoV))",
    "texel_offset": "value = lo + (hi - lo) * min(t + 1/N, 1): one texel past the texel centre "
    "(Filament cmgen's roughness rows, r = clamp((H - y + 0.5)/H, 0, 1) in image row y)",
    "listed": "value = values[i], listed in the config (not evenly spaced in general: map a parameter to a "
    "fractional index by searching the values)",
}
ORDERS = {
    "lo_first": "index 0 (first row / column) holds t near 0",
    "hi_first": "index 0 holds t near 1: index i holds t of index N - 1 - i (a vertical flip of lo_first)",
}
SIGMA_TO_ALPHA = {
    "sigma": "GGX alpha = sigma",
    "sigma_squared": "GGX alpha = sigma^2 (sigma as a perceptual roughness)",
}
ROUGHNESS_PARAMS = {
    "perceptual": "the axis holds perceptual roughness r; alpha = r^2",
    "alpha": "the axis holds the NDF alpha directly",
}


def sigma_alpha(sigma, mapping: str) -> np.ndarray:
    """GGX alpha (float64, unclamped) of sigma under ``mapping`` (SIGMA_TO_ALPHA)."""
    s = np.asarray(sigma, dtype=np.float64)
    return s if mapping == "sigma" else s * s


@dataclass(frozen=True)
class Axis:
    name: str  # NoV, perceptual_roughness, alpha, ...
    dim: str  # x = columns, y = rows, z = slices, y_block = blocks of rows (a 4th axis flattened into the rows)
    count: int
    lo: float = 0.0
    hi: float = 1.0
    texel: str = "center"
    mapping: str = "linear"
    order: str = "lo_first"
    clamp: tuple[float, float] | None = None
    listed: tuple[float, ...] = ()  # mapping "listed": the value of every index (count = len(listed))
    alpha_map: str | None = None  # a sigma axis: its SIGMA_TO_ALPHA mapping

    def t(self) -> np.ndarray:
        """The texture-space parameter t in [0, 1] at every index (after ``order``)."""
        i = np.arange(self.count, dtype=np.float64)
        if self.order == "hi_first":
            i = i[::-1]
        if self.texel == "center":
            return (i + 0.5) / self.count
        return i / max(self.count - 1, 1)

    def _map(self, t: np.ndarray, raw: bool = False) -> np.ndarray:
        """The value at t; ``raw``: without ``clamp`` and ``texel_offset``'s min (Axis.regular)."""
        if self.mapping == "one_minus_t2":
            s = 1.0 - t * t
        elif self.mapping == "square":
            s = t * t
        elif self.mapping == "texel_offset":
            s = t + 1.0 / self.count if raw else np.minimum(t + 1.0 / self.count, 1.0)
        else:
            s = t
        v = self.lo + (self.hi - self.lo) * s
        if self.clamp is not None and not raw:
            v = np.clip(v, *self.clamp)
        return v

    def regular(self) -> np.ndarray:
        """Per index: its value is the axis' analytic mapping of t, no clamp, ``texel_offset``'s min or edge policy
        (axis_edge) applied (a ``listed`` axis: nowhere). The indices lutbake.sampling.interpolation may use."""
        if self.mapping == "listed":
            return np.zeros(self.count, bool)
        return self._map(self.t(), raw=True).astype(np.float32) == self.values()

    def values(self) -> np.ndarray:
        """The parameter integrated at every index (float32, after the edge policy)."""
        if self.mapping == "listed":
            v = np.asarray(self.listed, dtype=np.float64)
        else:
            v = self._map(self.t())
        return axis_edge(self.name, v).astype(np.float32)

    def uv(self, value) -> np.ndarray:
        """Texture coordinate (0..1 across the image along this axis, 0 = outer edge of index 0) at
        which bilinear filtering reconstructs the table at ``value`` (float64 array). Values outside
        the tabulated span clamp to the first/last texel centre, as a clamp-to-edge sampler does."""
        x = np.asarray(value, dtype=np.float64)
        if self.mapping == "listed":  # fractional index by searching the (increasing) listed values
            n = self.count
            return (np.interp(x, np.asarray(self.listed, np.float64), np.arange(n)) + 0.5) / n
        s = (x - self.lo) / (self.hi - self.lo) if self.hi > self.lo else np.zeros_like(x)
        if self.mapping == "one_minus_t2":
            t = np.sqrt(np.clip(1.0 - s, 0.0, 1.0))
        elif self.mapping == "square":
            t = np.sqrt(np.clip(s, 0.0, 1.0))
        elif self.mapping == "texel_offset":
            t = s - 1.0 / self.count
        else:
            t = s
        n = self.count
        if self.texel == "center":
            u = t
        else:
            u = (t * (n - 1) + 0.5) / n
        u = np.clip(u, 0.5 / n, 1.0 - 0.5 / n)
        return 1.0 - u if self.order == "hi_first" else u

    def uv_formula(self) -> str:
        """``uv`` as a shader expression in the axis value ``x`` (range [lo, hi] = [0, 1] written out)."""
        n = self.count
        if self.mapping == "listed":
            return f"(fractional index of x among the listed values + 0.5) / {n}"
        s = "x" if (self.lo, self.hi) == (0.0, 1.0) else f"(x - {self.lo:g}) / {self.hi - self.lo:g}"
        t = {"linear": s, "one_minus_t2": f"sqrt(1 - {s})", "square": f"sqrt({s})", "texel_offset": f"{s} - 1/{n}"}[
            self.mapping
        ]
        u = t if self.texel == "center" else f"({t}) * {n - 1}/{n} + 0.5/{n}"
        return f"1 - ({u})" if self.order == "hi_first" else u

    def alpha(self) -> np.ndarray | None:
        """NDF alpha at every index (float32) for a roughness or sigma axis (None otherwise); unclamped: the
        integrands apply the alpha -> 0 policy (lutbake.edge.effective_alpha)."""
        v = self.values().astype(np.float64)
        if self.name == "perceptual_roughness":
            return (v**2).astype(np.float32)
        if self.name == "alpha":
            return v.astype(np.float32)
        if self.name == "sigma" and self.alpha_map is not None:
            return sigma_alpha(v, self.alpha_map).astype(np.float32)
        return None

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
            "order": self.order,
            "order_formula": ORDERS[self.order],
            "clamp": list(self.clamp) if self.clamp is not None else None,
            "uv_formula": f"u = {self.uv_formula()} (x = this axis' value; clamp-to-edge, bilinear)",
            "first": f"index 0 = {float(self.values()[0]):.9g}",
            "values": [float(x) for x in self.values()],
        }
        edge = axis_edge_text(self.name)
        if edge:
            d["edge"] = edge
        a = self.alpha()
        if a is not None:
            d["alpha"] = [float(x) for x in a]
            d["alpha_formula"] = (
                "alpha = value"
                if self.name == "alpha"
                else SIGMA_TO_ALPHA[self.alpha_map]
                if self.name == "sigma"
                else "alpha = r^2"
            )
        return d
