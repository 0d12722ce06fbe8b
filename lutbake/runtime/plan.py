"""The texel plan: everything the executor needs to bake a table's values, and how another process builds it.

A ``TexelPlan`` holds the axes, the channel meanings, the texel count and ``run_tile(start, stop, device)``, a pure
function of (spec, tile bounds) that returns the float64 values of texels [start, stop) in row-major order (slowest
axis first), so tiles can be handed to any worker, thread or cluster, and the result is bit-identical however they
are cut. Every kind builds its plans with lutbake.sampling.plan.per_texel_plan (kind dielectric_avg: its own
lutbake.sampling.dielectric_avg). The runtime is handed plans; it never builds one from a kind's name.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..axes import Axis


@dataclass
class TexelPlan:
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
    # (flat float64 tile data (n_texels, tile_width), device) -> (estimated max error, how it was estimated[, where
    # texels end over the tolerance: lutbake.tolerance.over_tolerance, "" when none])
    error_estimate: Callable[[np.ndarray, str], tuple[float, str]] | None = None
    # (data of plan.shape) -> extra lutbake:* attributes known only after the bake (ltc: fit-error statistics)
    attributes_after: Callable[[np.ndarray], dict[str, str]] | None = None
    # columns run_tile returns after the table's channels (an adaptive estimator's per-texel error estimates):
    # they travel with the tile, so the estimate is a pure function of the tiles wherever they ran, and are
    # handed to error_estimate, never stored in the table
    aux_channels: int = 0
    # texels per CPU tile where the plan wants other than lutbake.runtime.executor.TILE_TEXELS (kind btf: whole
    # (sigma, phi) blocks, so that a tile holds a texel and its reciprocal); any cut still gives the same values
    tile_texels: int | None = None

    @property
    def tile_width(self) -> int:
        """Columns of run_tile's result: n_channels values, then aux_channels."""
        return self.n_channels + self.aux_channels

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
class PlanSource:
    """How another process builds the plan of one table (a lutbake.runtime.cluster worker): ``build()`` returns it.
    Picklable where ``build`` is: the table's kind's ``plan`` function (module-level, pickled by reference) bound to
    its spec (``functools.partial(kind.plan, spec)``, made once on the client by lutbake.pipeline), so a worker runs
    a tile without looking a kind up by its name. ``name`` labels the tasks; ``key`` (the spec's canonical TOML) is
    what the worker caches the built plan under."""

    name: str
    key: str
    build: Callable[[], TexelPlan]
