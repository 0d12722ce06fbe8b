"""The public Python API: ``bake`` configs (or specs) into tables and files; ``lutbake bake`` is this function.

    bake(configs) = config.load_configs -> preflight (out-dir, outputs, report) -> batch.schedule (skip what is up to
                    date unless ``force``) -> [cluster session] -> batch.run -> [report]
Each table goes through lutbake.pipeline.bake_table (``bake_table`` here: one table, nothing written).
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass
from pathlib import Path

from . import arguments, batch, pipeline, preflight
from .config import TableSpec, load_configs, validate_spec
from .errors import ArgumentError, ConfigError, TableError
from .pipeline import OVER_TOLERANCE
from .runtime.executor import Progress
from .table import CubeTable, Table
from .values_cache import open_cache

__all__ = ["BakeResult", "BakeResults", "bake", "bake_table"]


@dataclass
class BakeResult:
    """One table of ``bake``: its spec, the baked Table (None unless ``baked``), the written path, seconds, samples
    per texel, the status (lutbake.batch.STATUSES: baked, skipped (its output was up to date), over_tolerance
    (written, or up to date, with texels over their tolerance: ``message`` names them), failed, interrupted), why
    (``message``), and the table whose computation its values came from (``values_from``)."""

    spec: TableSpec
    table: Table | CubeTable | None
    path: Path | None
    seconds: float
    samples: int | None
    status: str = "baked"
    message: str = ""
    values_from: str | None = None
    shape: str = ""
    cache_error: str = ""  # why its values could not be written into the --cache (the table is baked all the same)

    @property
    def name(self) -> str:
        return self.spec.name


class BakeResults(list):
    """``bake``'s results, one per table in config order, with the run's outcome: ``interrupted_by`` (the signal
    number, or None), ``exit_status`` (0, 1 if a table failed or ended over its tolerance without
    accept_over_tolerance = true, 130 / 143 after SIGINT / SIGTERM) and
    ``report_error`` (why ``report`` could not be written, or None)."""

    interrupted_by: int | None = None
    exit_status: int = batch.EXIT_OK
    report_error: str | None = None

    def counts(self) -> dict[str, int]:
        return {s: sum(r.status == s for r in self) for s in batch.STATUSES}


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


def _result(job: batch.Job) -> BakeResult:
    return BakeResult(
        job.spec,
        job.table,
        job.path,
        job.seconds or 0.0,
        job.samples,
        job.status,
        job.message,
        job.values_from,
        job.shape,
        job.cache_error,
    )


def bake_table(spec: TableSpec, workers: int | None = None, device: str = "cpu", progress=None, **options):
    """Bake one spec into a Table, nothing written: (table, seconds, samples per texel) (lutbake.pipeline.bake_table;
    ``options``: ``cancel``, ``runner``); an environment kind's spec into its CubeTable: (cube, seconds, None).
    ``spec`` is checked as its config would be (lutbake.config.validate_spec): ConfigError for a wrong input, before
    any kernel runs."""
    spec = validate_spec(spec, "bake_table")
    arguments.workers_arg("bake_table", workers)
    arguments.device_arg("bake_table", device)
    if pipeline.baked_whole(spec):  # an environment cube: (CubeTable, seconds, None)
        cube, seconds = pipeline.bake_cube_table(spec, workers, device, progress, options.get("cancel"))
        return cube, seconds, None
    return pipeline.bake_table(spec, workers, device, progress, **options)


def _check_arguments(out_dir, workers, device, flags: dict, callbacks: dict, cache_dir, fmt, scheduler, report):
    """bake()'s arguments other than ``configs`` and ``overrides``: ArgumentError naming the first wrong one."""
    arguments.path_arg("bake", "out_dir", out_dir)
    arguments.workers_arg("bake", workers)
    arguments.device_arg("bake", device)
    for name, value in flags.items():
        arguments.flag_arg("bake", name, value)
    for name, value in callbacks.items():
        arguments.callback_arg("bake", name, value)
    arguments.path_arg("bake", "cache_dir", cache_dir, optional=True)
    arguments.path_arg("bake", "report", report, optional=True)
    arguments.text_arg("bake", "fmt", fmt, "a format name")
    arguments.text_arg("bake", "scheduler", scheduler, "'local:N' or a Dask address")


def _specs(configs, overrides, fmt, environment=None) -> tuple[list[TableSpec], list[Path]]:
    """(every spec of the batch, the config paths): TableSpecs checked as a config's (validate_spec), paths loaded
    (``environment``: the file of their environment tables, lutbake.config.load_configs)."""
    items = arguments.configs_arg("bake", "configs", configs, (TableSpec,), f"{arguments.PATH} or a TableSpec")
    overrides = arguments.overrides_arg("bake", overrides)
    if fmt is not None:
        overrides = overrides + [(None, "format", fmt, "--format")]
    specs = [validate_spec(c) for c in items if isinstance(c, TableSpec)]
    paths = [c for c in items if not isinstance(c, TableSpec)]
    if environment is not None and not paths:
        raise ArgumentError("bake", "environment", environment, "None when configs are TableSpecs (set their option)")
    return specs + (load_configs(paths, overrides, environment) if paths else []), paths


def _check_device(device: str, scheduler: str | None) -> None:
    from .runtime import cluster

    if scheduler is not None:
        cluster.check_scheduler(scheduler)
    elif device == "cuda":  # on a cluster the workers' GPUs count (lutbake.runtime.cluster checks them)
        from .runtime.warp_runtime import init_warp

        if not init_warp().is_cuda_available():
            raise ConfigError("--device", "device", "cuda", "cpu", "no CUDA device is available")


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
    *,
    fmt: str | None = None,
    scheduler: str | None = None,
    report=None,
    on_schedule=None,
    check: bool = True,
    environment=None,
) -> BakeResults:
    """Validate every config, then bake each table and write ``out_dir/<name>.<ext>`` (key ``format``, default
    EXR) atomically; a table whose output is up to date (same content hash, lutbake.provenance) is skipped unless
    ``force``. ``write=False`` bakes every table and writes nothing.

    ``configs``: a path to a TOML file (str or Path), a TableSpec, or a list of them; a TableSpec is checked as its
    config would be. Nothing runs unless every config and argument is valid and every path the batch writes can be
    written (ConfigError; ArgumentError, a ConfigError, for an argument of the wrong type). ``fmt``: the format of
    every table (as ``format`` in each; blamed as --format). ``on_schedule(results)``: called once, before anything
    runs, with every table's BakeResult (status ``pending`` or ``skipped``). ``on_result(BakeResult)`` is called
    as each ends (skipped ones first).
    ``cache_dir``: the values cache of ``lutbake bake --cache`` (lutbake.values_cache; ``force`` reads no entry).
    ``scheduler``: run the tiles on a Dask cluster (lutbake.runtime.cluster: ``local:N`` or ``tcp://HOST:PORT``),
    started only when a table is to be baked. ``report``: write the JSON summary there (lutbake.batch.write_report).
    ``check``: raise TableError when a table failed or ended over its tolerance (unless its config sets
    accept_over_tolerance = true; the file is written either way) and KeyboardInterrupt when the run was
    interrupted (after the others finished); False: return every result, with the outcome on the BakeResults.
    """
    _check_arguments(
        out_dir,
        workers,
        device,
        {"write": write, "force": force, "check": check},
        {"progress": progress, "on_result": on_result, "on_schedule": on_schedule},
        cache_dir,
        fmt,
        scheduler,
        report,
    )
    specs, paths = _specs(configs, overrides, fmt, environment)
    _check_device(device, scheduler)
    results = BakeResults()
    if not write:
        for spec in specs:
            if pipeline.baked_whole(spec):
                cube, seconds = pipeline.bake_cube_table(spec, workers, device, progress)
                results.append(BakeResult(spec, cube, None, seconds, None, "baked", "", shape=cube.shape))
            else:
                table, seconds, samples = pipeline.bake_table(spec, workers, device, progress)
                over = table.attributes.get(OVER_TOLERANCE, "")
                status = "over_tolerance" if over else "baked"
                results.append(BakeResult(spec, table, None, seconds, samples, status, over))
            if on_result:
                on_result(results[-1])
        return results
    preflight.check_out_dir(out_dir)
    preflight.check_cache(cache_dir)
    jobs = batch.schedule(specs, out_dir, force=force)
    preflight.check_outputs(jobs)
    preflight.check_inputs(jobs, paths, cache_dir)
    preflight.check_path_lengths(jobs, cache_dir, report)
    if report is not None:
        preflight.check_report(report, jobs, paths, cache_dir)
    if on_schedule:
        on_schedule([_result(j) for j in jobs])
    done: dict[int, BakeResult] = {}

    def finished(job: batch.Job):
        done[id(job)] = _result(job)
        if on_result:
            on_result(done[id(job)])

    for job in jobs:
        if job.status in ("skipped", "over_tolerance"):  # up to date (over_tolerance: as its file records)
            finished(job)
    pending = sum(j.status == "pending" for j in jobs)
    signum = None
    try:
        with contextlib.ExitStack() as stack:
            runner = None
            if scheduler is not None and pending:
                from .runtime import cluster

                runner = stack.enter_context(cluster.session(scheduler, device))
                workers = pending  # every table in flight: the client's threads only wait for tiles
            signum = batch.run(
                jobs, workers, device, progress, on_done=finished, cache=open_cache(cache_dir, force), runner=runner
            )
    except (KeyboardInterrupt, batch.Interrupted) as e:  # a second Ctrl-C while tables wind down
        signum = getattr(e, "signum", 2)
        for job in jobs:
            if job.status == "pending":
                job.status, job.message = "interrupted", "interrupted; nothing written"
    results.extend(done.get(id(j)) or _result(j) for j in jobs)
    results.interrupted_by = signum
    results.exit_status = batch.exit_status(jobs, signum)
    if report is not None:
        try:
            batch.write_report(report, jobs, results.exit_status, signum)
        except OSError as e:
            from .io.oserror import os_error_text
            from .textsafe import escape_controls

            results.report_error = (
                f"cannot write the report {escape_controls(str(report))}: "
                f"{escape_controls(os_error_text(e, Path(report).parent))}"
            )
            results.exit_status = results.exit_status or batch.EXIT_FAILED
    if check:
        if signum is not None:
            raise KeyboardInterrupt(batch.signal_name(signum))
        failed = [j for j in jobs if j.status == "failed" or (j.status == "over_tolerance" and not j.accepted)]
        if failed:
            raise TableError("; ".join(j.message for j in failed))
    return results
