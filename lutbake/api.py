"""The public Python API: ``bake`` configs (or specs) into tables and files, through the same path as the CLI.

    bake(configs) = config.load_configs -> batch.schedule (skip what is up to date unless ``force``) -> batch.run
Each table goes through lutbake.pipeline.bake_table (``bake_table`` here: one table, nothing written).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from . import batch, preflight
from .config import TableSpec, load_configs
from .errors import TableError
from .pipeline import bake_table
from .runtime.executor import Progress
from .table import Table
from .values_cache import open_cache

__all__ = ["BakeResult", "bake", "bake_table"]


@dataclass
class BakeResult:
    """One table of ``bake``: its spec, the baked Table (None when ``skipped``: its output was up to date), the
    written path, seconds, samples per texel and the status (baked or skipped)."""

    spec: TableSpec
    table: Table | None
    path: Path | None
    seconds: float
    samples: int | None
    status: str = "baked"


def samples_note(spec: TableSpec, effective: int | None) -> str:
    """Why a table integrates ``effective`` samples per texel when its config asked for another number
    ('' when they agree or none was asked): each quadrature rounds the budget to its own grid."""
    asked = spec.options.get("samples")
    if not asked or effective is None or asked == effective:
        return ""
    estimator = spec.options.get("estimator", "")
    if estimator == "gauss_legendre":
        from .sampling.hemisphere import gl_order

        n = gl_order(asked)
        if 3 * n * n == effective:
            return (
                f"samples = {asked} asked; gauss_legendre integrates 3 regions x n x n points with "
                f"n = round(sqrt({asked} / 3)) = {n}: 3 x {n}^2 = {effective}"
            )
    if estimator.startswith("sobol") and effective == 1 << (asked - 1).bit_length():
        return f"samples = {asked} asked; Sobol' points come in powers of two: {effective}"
    return f"samples = {asked} asked; the {spec.kind} quadrature evaluates {effective} per texel (docs/config.md)"


def bake(
    configs,
    out_dir="outputs",
    overrides=(),
    workers: int | None = None,
    device: str = "cpu",
    write: bool = True,
    progress: Progress | None = None,
    on_result=None,
    force: bool = False,
    cache_dir=None,
) -> list[BakeResult]:
    """Validate every config, then bake each table and write ``out_dir/<name>.<ext>`` (key ``format``, default
    EXR) atomically; a table whose output is up to date (same content hash, lutbake.provenance) is skipped unless
    ``force``. ``write=False`` bakes every table and writes nothing.

    ``configs``: paths to TOML files, or TableSpecs. Nothing runs unless every config is valid. A table that
    fails raises TableError (after the other tables finished). ``on_result(BakeResult)`` is called as each ends.
    ``cache_dir``: the values cache of ``lutbake bake --cache`` (lutbake.values_cache; ``force`` reads no entry).
    """
    specs = [c for c in configs if isinstance(c, TableSpec)]
    paths = [c for c in configs if not isinstance(c, TableSpec)]
    specs += load_configs(paths, overrides) if paths else []
    if not write:
        results = []
        for spec in specs:
            table, seconds, samples = bake_table(spec, workers, device, progress)
            results.append(BakeResult(spec, table, None, seconds, samples))
            if on_result:
                on_result(results[-1])
        return results
    preflight.check_out_dir(out_dir)
    jobs = batch.schedule(specs, out_dir, force=force)
    preflight.check_outputs(jobs)
    results: dict[int, BakeResult] = {}

    def done(job: batch.Job):
        r = BakeResult(job.spec, job.table, job.path, job.seconds or 0.0, job.samples, job.status)
        results[id(job)] = r
        if on_result and job.status in ("baked", "skipped"):
            on_result(r)

    for job in jobs:
        if job.status == "skipped":
            done(job)
    signum = batch.run(jobs, workers, device, progress, on_done=done, cache=open_cache(cache_dir, force))
    if signum is not None:
        raise KeyboardInterrupt(batch.signal_name(signum))
    failed = [j for j in jobs if j.status == "failed"]
    if failed:
        raise TableError("; ".join(j.message for j in failed))
    return [results[id(j)] for j in jobs]
