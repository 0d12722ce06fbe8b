"""What a table kind declares: its config keys and how it plans a bake.

A kind is a description (name, aliases, keys with types, defaults, allowed values and docs) plus
``plan(spec) -> Plan``. A plan is everything the executor needs: the axes, the channel meanings,
the texel count and ``run_tile(start, stop, device)``: a pure function of (spec, tile bounds) that
returns the float64 values of texels [start, stop) in row-major order (y slowest), so tiles can be
handed to any worker, thread or cluster, and the result is bit-identical however they are cut.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..axes import Axis


@dataclass(frozen=True)
class Key:
    """One config key: its type, default, allowed values (or a range) and a line of documentation."""

    name: str
    type: str  # "str", "int", "float", "int_pair", "float_range", "float_list", "name"
    default: Any
    doc: str
    choices: dict[str, str] | None = None  # value -> description
    minimum: float | None = None
    maximum: float | None = None
    required: bool = False


@dataclass
class Plan:
    axes: list[Axis]  # slowest first; image dims z, y, x
    channels: dict[str, str]
    reconstruction: str
    n_texels: int
    n_channels: int
    run_tile: Callable[[int, int, str], np.ndarray]
    prepare: Callable[[str], None]  # compile kernels before threads launch them
    samples: int  # integrand evaluations per texel (nominal)
    estimator: str
    terms: dict[str, str]
    cost: float  # integrand evaluations in total, for the progress bar
    extra: dict[str, str] = field(default_factory=dict)
    # (flat float64 data (n_texels, n_channels), device) -> (estimated max abs error, how it was estimated)
    error_estimate: Callable[[np.ndarray, str], tuple[float, str]] | None = None

    @property
    def shape(self) -> tuple[int, ...]:
        """(z,) y, x, C; a 1D table (one x axis) is one image row: (1, x, C). A ``y_block`` axis is
        flattened into the rows: y = y_block count x y count (row = block * y count + y index)."""
        counts = tuple(a.count for a in self.axes if a.dim != "y_block")
        blocks = [a.count for a in self.axes if a.dim == "y_block"]
        if blocks:
            dims = [a.dim for a in self.axes if a.dim != "y_block"]
            counts = tuple(c * blocks[0] if d == "y" else c for c, d in zip(counts, dims))
        if len(counts) == 1:
            counts = (1,) + counts
        return counts + (self.n_channels,)


@dataclass(frozen=True)
class Kind:
    name: str
    description: str
    keys: dict[str, Key]
    plan: Callable[[Any], Plan]
    aliases: tuple[str, ...] = ()
    check: Callable[[Any], str | tuple[str, str] | None] | None = None  # cross-key rules: message or (key, message)
