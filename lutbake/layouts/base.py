"""The ``Layout`` record: everything lutbake knows about one engine table's layout, as data.

A layout is what an engine fixes on top of a kind (lutbake.kinds): the terms (NDF, masking, Fresnel form), the grid
(axes, texel convention, mapping, row order; or the config's keys), the channels (names, meanings, the map from the
kind's integrals to the stored values, their value bounds), the shader's reconstruction with its uv rendered from
the axes, the storage (formats, dtype and the tolerance its precision implies) and the mistakes ``audit`` tries.
Kinds, value_bounds, the writers, ``inspect``, ``preview``, ``audit``, ``size`` and the presets read the record;
one module per engine in lutbake.layouts declares them (``EngineTable``: a preset's grid and storage, its shipped
table).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..axes import Axis


@dataclass(frozen=True)
class Terms:
    """The terms an engine fixes; None: the config's key (ndf, masking)."""

    ndf: str | None = None
    masking: str | None = None
    fresnel: str = "schlick"


@dataclass(frozen=True)
class EngineChannel:
    """A channel an engine adds to a base layout's (Unity HDRP's pre-integrated diffuse as channel B): ``name``
    its entry in lutbake.integrands.engine_diffuse.CHANNELS (the function that computes channel B at each texel
    and the Warp kernel it loads; named, so that reading the records imports no Warp), ``scale`` the base channels'
    divisor as stored, ``description`` the lutbake:terms ``diffuse`` entry."""

    name: str
    scale: float
    description: str


@dataclass(frozen=True)
class Storage:
    """How an engine stores the table: ``formats`` (lutbake.io), ``dtype`` and the tolerance its precision implies
    (absolute, relative; None: the dtype's default, lutbake.tolerance), ``exclusive``: formats only this layout
    writes."""

    formats: tuple[str, ...] = ()
    dtype: str | None = None
    tolerance: tuple[float, float] | None = None
    exclusive: tuple[str, ...] = ()


@dataclass(frozen=True)
class Layout:
    """One layout of one kind (the config's ``layout`` key). Fields by concern:

    - what: ``name``, ``kind``, ``engine`` (who loads it), ``summary`` (the key's documentation), ``source``;
    - terms: ``integrand`` (the kind's integrand channel set or Fresnel mode it derives from), ``terms`` (what the
      engine fixes), ``terms_record`` (the lutbake:terms record when the layout replaces the kind's), ``terms_extra``;
      ``gauss_legendre_only``: why the QMC estimators cannot integrate it (None: any estimator);
    - grid: ``grid`` (a fixed grid: options -> the kind's texel grid; None: the config's keys), ``texels``;
    - channels: ``channels`` (name -> meaning), ``to_stored`` / ``error_to_stored`` (the kind's integrals and their
      error bounds -> the stored channels; ``from_stored`` the inverse), ``kernel_tolerance``, ``engine_channel``,
      ``mirror_ratio``, ``extra`` (metadata), ``unit_range`` (every value within [0, 1]; else ``above_one`` says why);
    - shader: ``shader`` (the reconstruction text, ``{uv}`` rendered from the axes: ``reconstruction``),
      ``split_sum`` (``scale_bias`` / ``multiscatter``: the R, G pair a shader reads as E = f0 R + G or
      mix(R, G, f0); ``sheen``: B = the sheen DFG; None: no sphere preview);
    - storage: ``storage``; audit: ``audit`` (the hypotheses ``lutbake audit`` adds to the positional ones)."""

    name: str
    kind: str
    engine: str
    summary: str
    channels: dict[str, str]
    shader: str
    integrand: str = ""
    source: str = ""
    terms: Terms = field(default_factory=Terms)
    terms_record: dict | None = None
    terms_extra: dict = field(default_factory=dict)
    gauss_legendre_only: str | None = None
    grid: Callable | None = None
    texels: Callable | None = None
    to_stored: Callable | None = None
    from_stored: Callable | None = None
    error_to_stored: Callable | None = None
    kernel_tolerance: Callable | None = None
    engine_channel: EngineChannel | None = None
    mirror_ratio: object | None = None
    extra: dict = field(default_factory=dict)
    unit_range: bool = True
    above_one: str = ""
    split_sum: str | None = None
    storage: Storage = field(default_factory=Storage)
    audit: tuple[str, ...] = ("positions", "values", "other_split_sum")

    def stored(self, e: np.ndarray) -> np.ndarray:
        """The kind's integrals (n, k) -> this layout's stored channels (the identity when none is declared)."""
        return e if self.to_stored is None else self.to_stored(e)

    def stored_error(self, err: np.ndarray) -> np.ndarray:
        """Error bounds of ``stored(e)`` from those of e (the triangle inequality)."""
        return err if self.error_to_stored is None else self.error_to_stored(err)

    def reconstruction(self, axes: list[Axis] | None = None) -> str:
        """The shader text, its ``{uv}`` rendered from a [y, x] table's axes (uv_of)."""
        return self.shader.format(uv=uv_of(axes) if axes is not None else "")


@dataclass(frozen=True)
class IBL:
    """The conventions one engine's image-based lighting shares between its DFG table and its environment cubes: the
    NDF, masking and roughness definition the DFG table is integrated with, the mip curve by which the shader turns
    that roughness into the specular cube's mip, and the lobe the cube is prefiltered with. Recorded as
    ``lutbake:ibl`` in every file of each of the engine's tables (lutbake.provenance.ibl_attributes), so the files
    of one ``<engine>-ibl`` run say they belong together; tests/test_layouts.py checks the tables' keys against it."""

    engine: str
    ndf: str
    masking: str
    roughness: str
    curve: str
    lobe: str
    source: str

    def record(self) -> dict[str, str]:
        return {
            "engine": self.engine,
            "ndf": self.ndf,
            "masking": self.masking,
            "roughness": self.roughness,
            "mip_curve": self.curve,
            "lobe": self.lobe,
            "source": self.source,
        }

    def keys(self, kind: str) -> dict[str, str]:
        """The keys a table of ``kind`` holds under these conventions (dfg: ndf, masking, roughness; the specular
        cube: curve, lobe; the irradiance cube: none)."""
        return {
            "dfg": {"ndf": self.ndf, "masking": self.masking, "roughness": self.roughness},
            "environment_specular": {"curve": self.curve, "lobe": self.lobe},
        }.get(kind, {})


@dataclass(frozen=True)
class EngineTable:
    """One table an engine loads, baked by a preset: the layout it is written in, the grid and storage keys the engine
    fixes (the preset's options must hold them: tests/test_layouts.py), the engine's source, what the engine loads
    and, where tests/data holds the shipped table, its name there. ``shader``: the engine's own line that samples
    the table and rebuilds its value, in the engine's names and uv (the first line of the file's reconstruction,
    ``lutbake inspect``, and the README's engine table; "" where the engine reads the table through its own array
    code, as the LTC arrays). ``encoding``: how the engine's shipped file stores a value (a name of
    lutbake.commands.audit_search.ENCODINGS: ``plain`` UNORM codes or floats as read, ``rgbd`` Babylon's RGBD,
    ``rgbm``, ``srgb_encoded``, ``half_bits``); ``audit --preset`` decodes a file so when its storage can hold that
    encoding (an 8-bit RGBA PNG for RGBD), and tries every other encoding as a hypothesis. ``ibl``: the engine's
    image-based-lighting conventions where the table is part of them (its DFG table, its environment cubes)."""

    engine: str
    preset: str
    table: str
    kind: str
    layout: str | None
    keys: dict
    source: str
    loads: str
    shipped: str | None = None
    shader: str = ""
    encoding: str = "plain"
    ibl: IBL | None = None

    def holds(self, kind: str, name: str, options: dict) -> bool:
        """Whether a table ``name`` of ``kind`` with ``options`` is this engine table: its name, and every key the
        engine fixes except the storage ones (``dtype``, ``format``: they change no shader line)."""
        if (kind, name) != (self.kind, self.table):
            return False
        given = {**options, "kind": kind}
        return all(_plain(given.get(k)) == v for k, v in self.keys.items() if k not in STORAGE_KEYS)


STORAGE_KEYS = ("dtype", "format")


def _plain(value):
    """A config value as the records write it (tuples as lists)."""
    return [_plain(v) for v in value] if isinstance(value, (list, tuple)) else value


def uv_of(axes: list[Axis]) -> str:
    """``uv = vec2(u(x axis), u(y axis))`` of a [y, x] table (lutbake.axes.Axis.uv_formula, its x named after the
    axis: NoV, alpha, roughness)."""
    y_axis, x_axis = axes

    def u(a: Axis) -> str:
        return re.sub(r"\bx\b", {"NoV": "NoV", "alpha": "alpha"}.get(a.name, "roughness"), a.uv_formula())

    return f"uv = vec2({u(x_axis)}, {u(y_axis)})"


def nov_alpha_grid(axes: list[Axis]) -> tuple[np.ndarray, np.ndarray]:
    """Per-texel (NoV, alpha) of a [y, x] grid (either axis order), row-major: texel t = iy * nx + ix."""
    y_axis, x_axis = axes
    if x_axis.name == "NoV":
        return np.tile(x_axis.values(), y_axis.count), np.repeat(y_axis.alpha(), x_axis.count)
    return np.repeat(y_axis.values(), x_axis.count), np.tile(x_axis.alpha(), y_axis.count)


IOR_MAPPINGS = {
    "linear": "eta = lo + (hi - lo) t (t per the texel convention)",
    "symmetric": "OpenPBR's: the first N/2 indices hold 1/eta = hi - (hi - 1) i/(N/2 - 1) (eta from 1/hi up to 1), the "
    "last N/2 hold eta = 1 + (hi - 1) i/(N/2 - 1) (1 up to hi); N even, lo ignored",
}


def ior_values(n: int, lo: float, hi: float, texel: str, mapping: str) -> np.ndarray:
    """eta at every index of an IOR axis (IOR_MAPPINGS)."""
    if mapping == "symmetric":
        half = n // 2
        t = np.arange(half) / max(half - 1, 1)
        return np.concatenate([1.0 / (hi - (hi - 1.0) * t), 1.0 + (hi - 1.0) * t])
    t = Axis("t", "z", n, texel=texel).t()
    return lo + (hi - lo) * t


def ior_axis(etas: np.ndarray, dim: str) -> Axis:
    """A listed IOR axis."""
    return Axis("ior", dim, len(etas), listed=tuple(float(e) for e in etas), mapping="listed")
