"""One table through the pipeline: spec -> kind's texel plan -> executor -> Table (with its provenance).

    spec (lutbake.config) -> lutbake.kinds.<kind>.plan = per_texel_plan(integrand, estimator, grid)
         -> lutbake.executor.execute -> finite check -> lutbake.table.Table (lutbake.provenance.attributes)
The batch (lutbake.batch) and the Python API (lutbake.api) both bake through ``bake_table``; writing is theirs.
"""

from __future__ import annotations

import numpy as np

from .config import TableSpec
from .errors import TableError
from .executor import Progress, Timer, estimate_error, execute_tiles
from .kinds import lookup_kind
from .provenance import attributes
from .table import Table


def bake_table(
    spec: TableSpec, workers: int | None = None, device: str = "cpu", progress: Progress | None = None, cancel=None
) -> tuple[Table, float, int]:
    """Bake one spec into a Table (nothing written): (table, seconds, samples per texel). Raises TableError if a
    value is not finite; executor.Cancelled if the ``cancel`` event (a threading.Event) is set while it runs."""
    plan = lookup_kind(spec.kind).plan(spec)
    with Timer() as t:
        full = execute_tiles(
            plan, workers=workers, device=device, progress=progress, label=spec.name, cancel=cancel, spec=spec
        )
    data = full[:, : plan.n_channels].reshape(plan.shape)
    if not np.all(np.isfinite(data)):
        bad = int(np.size(data) - np.count_nonzero(np.isfinite(data)))
        raise TableError(f"{spec.source}: table '{spec.name}': {bad} non-finite values; nothing written")
    extra = {}
    estimate = estimate_error(plan, full, device, spec)
    if estimate is not None:
        err, how = estimate
        extra.update(error_estimate=f"{err:.3e}", error_estimate_method=how)
    if plan.attributes_after is not None:
        extra.update(plan.attributes_after(data))
    table = Table(
        spec.name,
        spec.kind,
        data.astype(np.float32),
        plan.axes,
        plan.channels,
        plan.reconstruction,
        attributes(spec, plan, extra),
    )
    return table, t.seconds, plan.samples
