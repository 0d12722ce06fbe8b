"""One table through the pipeline: spec -> kind's texel plan -> executor -> Table (with its provenance).

    spec (lutbake.config) -> lutbake.kinds.<kind>.plan = per_texel_plan(integrand, estimator, grid)
         -> lutbake.runtime.executor.execute -> finite check -> lutbake.table.Table (lutbake.provenance.attributes)
``plan_of`` builds a spec's plan (the batch builds it once per table, lutbake.batch.Job.plan, and hands it on);
``compute`` runs everything up to the values (tiles, finite check, error estimate); ``compute_at`` the same
integrand and estimator at arbitrary texels (audit and size); ``assemble`` makes the Table of one spec from them
(name, config, content hash). ``bake_table`` is both. The batch (lutbake.batch) computes once per distinct values
key (lutbake.sharing) and assembles per table; the batch and the Python API (lutbake.api) write.

A kind baked whole (the environment cubes: Kind.bake) goes through ``bake_cube_table``: its kind's bake (no texel
plan), the finite check, then ``assemble_cube`` (the engine's shader line first, the provenance and content hash).
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import numpy as np

from .config import TableSpec, kind_of
from .errors import TableError
from .layouts import reconstruction_with_engine_line
from .provenance import attributes, cube_attributes
from .runtime.executor import Cancelled, Progress, Timer, estimate_error, execute_tiles
from .runtime.plan import PlanSource, TexelPlan
from .runtime.warp_runtime import defining
from .table import CubeTable, Table

OVER_TOLERANCE = "over_tolerance"  # the lutbake:* attribute of a table whose texels end over their tolerance


@dataclass
class Computed:
    """What ``compute`` made of a spec: its plan, the float64 values (plan.shape), the attributes known only after
    the bake (error estimate, plan.attributes_after), the tiles' wall seconds, and the CPU seconds of the whole
    computation in this process, every thread's share (in a lutbake.runtime.cluster session the workers' are not
    counted)."""

    plan: TexelPlan
    data: np.ndarray
    extra: dict[str, str]
    seconds: float
    cpu_seconds: float


def plan_of(spec: TableSpec) -> TexelPlan:
    """The plan of ``spec``'s table, built by its kind (lutbake.config.kind_of)."""
    with defining():  # a plan builds Warp functions (kernel factories): one table thread at a time
        return kind_of(spec).plan(spec)


def plan_source(spec: TableSpec) -> PlanSource:
    """How a cluster worker builds ``spec``'s plan: its kind's plan function bound to it (picklable by reference)."""
    return PlanSource(spec.name, f"{spec.kind}\n{spec.toml()}", functools.partial(kind_of(spec).plan, spec))


def compute(
    spec: TableSpec,
    workers: int | None = None,
    device: str = "cpu",
    progress: Progress | None = None,
    cancel=None,
    runner=None,
    plan: TexelPlan | None = None,
) -> Computed:
    """The values of ``spec``'s table (nothing written). Raises TableError if a value is not finite;
    executor.Cancelled if the ``cancel`` event (a threading.Event) is set while it runs. ``runner``: where the
    tiles run (lutbake.runtime.cluster.DaskRunner, handed plan_source(spec)); None: this process' threads.
    ``plan``: ``spec``'s plan where the caller built it already (plan_of); None: built here."""
    cpu: list[float] = []  # CPU seconds of each part, measured in the thread that ran it (time.thread_time)
    t0 = time.thread_time()
    plan = plan if plan is not None else plan_of(spec)
    source = plan_source(spec) if runner is not None else None
    cpu.append(time.thread_time() - t0)
    with Timer() as t:
        full = execute_tiles(
            plan,
            workers=workers,
            device=device,
            progress=progress,
            label=spec.name,
            cancel=cancel,
            source=source,
            cpu=cpu,
            runner=runner,
        )
    t0 = time.thread_time()
    data = full[:, : plan.n_channels].reshape(plan.shape)
    if not np.all(np.isfinite(data)):
        bad = int(np.size(data) - np.count_nonzero(np.isfinite(data)))
        raise TableError(f"{spec.source}: table '{spec.name}': {bad} non-finite values; nothing written")
    extra = {}
    estimate = estimate_error(plan, full, device, source, runner)
    if estimate is not None:
        err, how, *over = estimate
        extra.update(error_estimate=f"{err:.3e}", error_estimate_method=how)
        if over and over[0]:  # texels that ended over the tolerance (lutbake.tolerance.over_tolerance)
            extra[OVER_TOLERANCE] = over[0]
    if plan.attributes_after is not None:
        extra.update(plan.attributes_after(data))
    cpu.append(time.thread_time() - t0)
    return Computed(plan, data, extra, t.seconds, sum(cpu))


def compute_at(spec: TableSpec, points: dict[str, np.ndarray], workers: int | None = None, device: str = "cpu"):
    """``spec``'s integrand and estimator at arbitrary texels instead of its grid: float64 (n, channels), nothing
    written. ``points``: flat per-texel arrays the kind's plan reads ({"nov", "alpha", "rough"} for dfg, whose
    ``plan(spec, points=...)`` takes them). The reference of ``lutbake audit`` and ``lutbake size``
    (lutbake.commands.reference): the bake's own plan and tile executor, at the points those commands need."""
    with defining():
        plan = kind_of(spec).plan(spec, points=points)
    full = execute_tiles(plan, workers=workers, device=device)
    return full[:, : plan.n_channels]


def assemble(spec: TableSpec, computed: Computed) -> Table:
    """The Table of ``spec`` from ``computed`` (``spec``'s own values, or those of a spec with the same
    lutbake.sharing.values_key): the values with ``spec``'s name and provenance."""
    plan = computed.plan
    return Table(
        spec.name,
        spec.kind,
        computed.data.astype(np.float32),
        plan.axes,
        plan.channels,
        reconstruction_with_engine_line(spec.kind, spec.name, spec.options, plan.reconstruction),
        attributes(spec, plan, computed.extra),
    )


def bake_table(spec: TableSpec, *args, **options) -> tuple[Table, float, int]:
    """Bake one spec into a Table (nothing written): (table, seconds, samples per texel): ``compute`` (same
    arguments: workers, device, progress, cancel, runner) then ``assemble``. Raises TableError if a value is not
    finite; executor.Cancelled if the ``cancel`` event (a threading.Event) is set while it runs."""
    c = compute(spec, *args, **options)
    return assemble(spec, c), c.seconds, c.plan.samples


def baked_whole(spec: TableSpec) -> bool:
    """Whether ``spec``'s kind is baked whole (Kind.bake: an environment cube), not through a texel plan."""
    return kind_of(spec).bake is not None


def bake_cube_table(
    spec: TableSpec, workers: int | None = None, device: str = "cpu", progress: Progress | None = None, cancel=None
) -> tuple[CubeTable, float]:
    """Bake one spec of a kind baked whole into its CubeTable (nothing written): (table, seconds). ``progress`` is told
    the table's texels when it starts and when it ends (its kind's bake reports no tiles); ``cancel`` is checked
    before it starts (executor.Cancelled). Raises TableError if a value is not finite."""
    if cancel is not None and cancel.is_set():
        raise Cancelled(spec.name)
    kind = kind_of(spec)
    texels = kind.texels(spec.options)
    update = progress(spec.name, texels, float(texels)) if progress is not None else None
    with Timer() as t:
        baked = kind.bake(spec, workers, device)
    bad = sum(int(np.size(m) - np.count_nonzero(np.isfinite(m))) for m in baked.mips)
    if bad:
        raise TableError(f"{spec.source}: table '{spec.name}': {bad} non-finite values; nothing written")
    if update is not None:
        update(texels)
    return assemble_cube(spec, baked), t.seconds


def assemble_cube(spec: TableSpec, baked: CubeTable) -> CubeTable:
    """``baked`` (its kind's bake of ``spec``) with the engine's shader line first in its reconstruction and its
    provenance: the config, versions, the engine's ibl conventions and the content hash of the inputs it read."""
    baked.reconstruction = reconstruction_with_engine_line(spec.kind, spec.name, spec.options, baked.reconstruction)
    baked.attributes = cube_attributes(spec, baked.inputs)
    return baked
