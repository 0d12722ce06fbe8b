"""Batch runs that never lose work: scheduling, parallel tables, interrupts, reports.

- **Schedule first.** ``schedule()`` takes already-validated specs (``config.load_configs`` validates every
  config before anything runs) and decides, per table, its output path, its content hash
  (lutbake.provenance) and whether it is up to date (*skipped*: same content hash, and the stored bytes match
  the sha256 recorded with it, lutbake.io.integrity). Nothing is baked while scheduling.
- **Run.** ``run()`` bakes the pending tables on a small thread pool (tables in parallel, each on the
  tile executor; the result is bit-identical for any worker count). One failing table (a NaN, an
  exception in a kernel, a MemoryError) is marked ``failed`` and does not stop the others. Each table goes
  through lutbake.pipeline (compute, assemble), as in the Python API (lutbake.api.bake is schedule + run).
- **Compute once, write many.** Pending tables with the same values key (lutbake.sharing: same kind and options
  but for name and the kind's layout keys, e.g. one LTC fit written as DDS, JS and C) are computed once and
  written each in its own layout; the files are those each table gets baked alone.
- **Cubes.** A kind baked whole (the environment cubes, lutbake.kinds.environment) is baked by its kind and written
  by lutbake.io.cubemap; its content hash covers its environment file, and --cache holds no cube.
- **Over tolerance.** A table whose texels end over their tolerance (the adaptive rule's last order reached; the
  plan says where: lutbake.tolerance.over_tolerance, lutbake:over_tolerance in the file) is written and marked
  ``over_tolerance``, with a message naming its texels and the worst estimate / tolerance, also when it is up to
  date; the run exits 1 unless its config sets ``accept_over_tolerance = true``.
- **Interrupts.** A KeyboardInterrupt (SIGINT) or ``Interrupted`` (raised by the SIGTERM handler of
  ``signal_handlers()``) while the main thread waits cancels every table that has not written its
  file: those are marked ``interrupted``; finished files stay. Writes are atomic (io.exr.write_exr),
  so an unfinished table never appears or replaces a good file, and the next run resumes only the
  tables that did not finish (their outputs are missing or stale).
"""

from __future__ import annotations

import contextlib
import json
import signal
import threading
import time
from collections import deque
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

from . import __version__
from .config import TableSpec
from .errors import LutbakeError
from .io.atomic import atomic_write_bytes, remove_stale_temps
from .io.formats import output_path, write_table
from .io.oserror import os_error_text
from .pipeline import OVER_TOLERANCE, Computed, assemble, bake_cube_table, baked_whole, compute, plan_of
from .provenance import HASH_ATTRIBUTE, content_hash, read_header
from .runtime.executor import Cancelled, Progress, default_workers
from .runtime.plan import TexelPlan
from .runtime.warp_runtime import ModuleBusy, defer_if_busy
from .sharing import group_by, values_key
from .sources import sources_digest
from .values_cache import ValuesCache, valid_extra

# over_tolerance: written (baked now, or up to date from an earlier run), but texels ended over their tolerance
# (lutbake.tolerance.over_tolerance): the run exits 1 unless the table's config sets accept_over_tolerance = true
STATUSES = ("baked", "skipped", "over_tolerance", "failed", "interrupted")
EXIT_OK, EXIT_FAILED, EXIT_SIGINT, EXIT_SIGTERM = 0, 1, 130, 143


class Interrupted(BaseException):
    """Raised in the main thread by the SIGTERM handler (KeyboardInterrupt stands for SIGINT)."""

    def __init__(self, signum: int = signal.SIGTERM):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


@dataclass
class Job:
    """One table of a batch and, once run, its outcome."""

    spec: TableSpec
    path: Path
    content_hash: str
    values_key: str = ""  # lutbake.sharing.values_key: pending jobs with the same key are computed once
    status: str = "pending"  # then one of STATUSES
    seconds: float | None = None
    cpu_seconds: float | None = None  # CPU of its computation (0 when its values came from ``values_from``)
    values_from: str | None = None  # the table whose computation this one's values came from (same values key)
    samples: int | None = None
    error_estimate: float | None = None
    message: str = ""
    shape: str = ""
    table: object = None  # the baked lutbake.table.Table, once baked
    cache_error: str = ""  # why its values could not be written into the --cache (the table itself is baked)
    _plan: TexelPlan | None = field(default=None, repr=False, compare=False)

    @property
    def name(self) -> str:
        return self.spec.name

    def plan(self) -> TexelPlan:
        """Its table's plan, built once (lutbake.pipeline.plan_of) and shared by the checks before the run
        (lutbake.preflight: the shape), a --cache hit and the computation; dropped once its group is written."""
        if self._plan is None:
            self._plan = plan_of(self.spec)
        return self._plan

    @property
    def accepted(self) -> bool:
        """Its config accepts an over_tolerance outcome (accept_over_tolerance = true): no exit status 1 for it."""
        return self.spec.options.get("accept_over_tolerance") is True

    def check_tolerance(self, attributes: dict[str, str], up_to_date: bool = False) -> None:
        """Status over_tolerance, and a message that names the texels, where ``attributes`` (its file's lutbake:*)
        say texels ended over the tolerance (lutbake.pipeline.OVER_TOLERANCE)."""
        over = attributes.get(OVER_TOLERANCE)
        if not over:
            return
        self.status = "over_tolerance"
        policy = "accepted (accept_over_tolerance = true)" if self.accepted else "exit status 1"
        self.message = (
            f"{self.spec.source}: table '{self.name}': {over}; {'up to date in' if up_to_date else 'written to'} "
            f"{self.path}; {policy}"
        )

    def report(self) -> dict:
        return {
            "name": self.name,
            "status": self.status,
            "path": str(self.path),
            "content_hash": self.content_hash,
            "seconds": self.seconds,
            "cpu_seconds": self.cpu_seconds,
            "values_from": self.values_from,
            "samples": self.samples,
            "error_estimate": self.error_estimate,
            "message": self.message,
        }


def _float_or_none(text) -> float | None:
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def schedule(specs: list[TableSpec], out_dir, force: bool = False) -> list[Job]:
    """One Job per (validated) spec: output path, content hash, and ``skipped`` if the output exists
    with that hash (unless ``force``). Runs no kernel."""
    digest = sources_digest()
    jobs = []
    for spec in specs:
        path = output_path(out_dir, spec.name, spec.options.get("format", "exr"), spec.kind)
        job = Job(spec, path, content_hash(spec, digest), values_key(spec, digest))
        header = None if force else read_header(job.path)
        if header is not None and header.get(HASH_ATTRIBUTE) == job.content_hash:
            job.status = "skipped"
            job.seconds = 0.0
            job.samples = int(header["samples"]) if header.get("samples", "").isdigit() else None
            job.error_estimate = _float_or_none(header.get("error_estimate"))
            job.message = "up to date"
            job.check_tolerance(header, up_to_date=True)
        jobs.append(job)
    return jobs


def _record_failure(job: Job, e: Exception, needed: int = 0) -> None:
    """Mark ``job`` interrupted (executor.Cancelled) or failed, with a message that says why."""
    if isinstance(e, Cancelled):
        job.status, job.message = "interrupted", "interrupted before its file was written; nothing written"
    elif isinstance(e, MemoryError):
        job.status = "failed"
        job.message = (
            f"{job.spec.source}: table '{job.name}': out of memory{': ' + str(e) if str(e) else ''}; nothing written"
        )
    elif isinstance(e, LutbakeError):
        job.status, job.message = "failed", str(e)
    elif isinstance(e, OSError):  # the output could not be written: say why (a full disk, a read-only mount ...)
        job.status = "failed"
        job.message = (
            f"{job.spec.source}: table '{job.name}': cannot write {job.path}: "
            f"{os_error_text(e, job.path.parent, needed)}; the next run bakes it again"
        )
    else:  # a kernel error, an I/O error, anything: this table fails, the others go on
        job.status = "failed"
        job.message = f"{job.spec.source}: table '{job.name}': {type(e).__name__}: {e}; nothing written"


def _cached(cache: ValuesCache | None, job: Job) -> Computed | None:
    """``job``'s values from the cache (lutbake.values_cache), with its plan; None on a miss."""
    entry = cache.load(job.values_key) if cache is not None else None
    if entry is None:
        return None
    t0 = time.thread_time()
    plan = job.plan()
    if plan.shape != entry[0].shape:
        return None
    after = plan.attributes_after(entry[0]) if plan.attributes_after is not None else {}
    if not valid_extra(entry[1], after):  # only what a bake records, the cheap part recomputed: else a miss
        return None
    return Computed(plan, entry[0], entry[1], 0.0, time.thread_time() - t0)


def _store(cache: ValuesCache | None, job: Job, computed: Computed) -> None:
    """Write ``job``'s values into the cache; a cache that cannot be written only loses its use (said in the
    job's message), never the table."""
    if cache is None:
        return
    try:
        cache.store(job.values_key, computed.data, computed.extra)
    except OSError as e:
        job.cache_error = f"values cache {cache.directory} not written: " + os_error_text(
            e, cache.directory, computed.data.nbytes
        )
        job.message = job.cache_error


def _bake_group(
    group: list[Job],
    workers: int,
    device: str,
    progress,
    cancel: threading.Event,
    cache: ValuesCache | None = None,
    runner=None,
) -> list[Job]:
    """_compute_and_write, then each finished job's plan dropped (it holds its texel grid and memos: not kept with the
    outcome); a group set back (ModuleBusy: still pending) keeps its plans for its next try."""
    try:
        return _compute_and_write(group, workers, device, progress, cancel, cache, runner)
    finally:
        for job in group:
            if job.status != "pending":
                job._plan = None


def _compute_and_write(group: list[Job], workers, device, progress, cancel, cache, runner) -> list[Job]:
    """Compute the values of ``group`` (pending jobs with one values key, lutbake.sharing) once, from the lead job's
    plan, or take them from ``cache``, then assemble and write each job's table in its own layout; any failure is
    recorded on the jobs it concerns, never raised."""
    lead = group[0]
    if baked_whole(lead.spec):
        return [_bake_cube(job, workers, device, progress, cancel) for job in group]
    t0 = time.perf_counter()
    try:
        if cancel.is_set():
            raise Cancelled(lead.name)
        computed = _cached(cache, lead)
        origin = "cache" if computed is not None else None
        if computed is None:
            computed = compute(lead.spec, workers, device, progress, cancel=cancel, runner=runner, plan=lead.plan())
            _store(cache, lead, computed)
    except ModuleBusy:  # before any tile ran (warp_runtime.defer_if_busy): the caller runs another group first
        raise
    except Exception as e:  # every table of the group lacks its values
        for job in group:
            _record_failure(job, e)
            if job is not lead and job.status == "failed":
                job.message = f"its values are computed with table '{lead.name}', which failed: {job.message}"
            job.seconds = time.perf_counter() - t0
        return group
    for job in group:
        _write_one(job, computed, lead.name if job is not lead else origin, cancel)
    return group


def _write_one(job: Job, computed: Computed, values_from: str | None, cancel: threading.Event) -> None:
    """Assemble ``job``'s table from ``computed`` (its group's values: computed for this job, for the job named
    ``values_from``, or taken from the cache: ``values_from`` = "cache") and write it."""
    t0 = time.perf_counter()
    needed = 0
    try:
        if cancel.is_set():
            raise Cancelled(job.name)
        table = assemble(job.spec, computed)
        needed = table.data.nbytes
        if table.attributes.get(HASH_ATTRIBUTE) != job.content_hash:  # sources changed under a running batch
            raise RuntimeError("the lutbake sources changed while the batch ran; run it again")
        if cancel.is_set():
            raise Cancelled(job.name)
        write_table(
            table,
            job.path.parent,
            job.spec.options.get("format", "exr"),
            dtype=job.spec.options.get("dtype", "float32"),
        )
    except Exception as e:
        _record_failure(job, e, needed)
        job.seconds = time.perf_counter() - t0
        return
    shared = values_from is not None and values_from != "cache"
    job.status, job.samples, job.table = "baked", computed.plan.samples, table
    job.seconds = 0.0 if shared else computed.seconds
    job.cpu_seconds = 0.0 if shared else computed.cpu_seconds
    job.values_from = values_from
    job.error_estimate = _float_or_none(table.attributes.get("error_estimate"))
    job.shape = "x".join(str(a.count) for a in table.axes) + f"x{len(table.channels)}"
    job.check_tolerance(table.attributes)


def _bake_cube(job: Job, workers, device, progress, cancel: threading.Event) -> Job:
    """Bake and write the cube of ``job``, a kind baked whole (lutbake.pipeline.bake_cube_table; its name is part of
    its values, so it is alone in its group, and no --cache entry holds it); any failure is recorded on the job,
    never raised, and leaves every file as it was (atomic writes: an older cube stays)."""
    from .io.cubemap import write_cube_table

    t0 = time.perf_counter()
    try:
        cube, seconds = bake_cube_table(job.spec, workers, device, progress, cancel)
        if cube.attributes.get(HASH_ATTRIBUTE) != job.content_hash:  # the environment or the sources changed meanwhile
            raise RuntimeError("its environment file or lutbake's sources changed while the batch ran; run it again")
        if cancel.is_set():
            raise Cancelled(job.name)
        write_cube_table(cube, job.path, job.spec.options["format"], job.spec.options["dtype"])
    except Exception as e:
        _record_failure(job, e)
        job.seconds = time.perf_counter() - t0
        return job
    errors = cube.record.get("error_estimate_per_mip") or []
    job.status, job.table, job.seconds, job.shape = "baked", cube, seconds, cube.shape
    job.error_estimate = max(errors) if errors else None
    return job


def run(
    jobs: list[Job],
    workers: int | None = None,
    device: str = "cpu",
    progress: Progress | None = None,
    on_done: Callable[[Job], None] | None = None,
    poll: float = 0.2,
    cache: ValuesCache | None = None,
    runner=None,
) -> int | None:
    """Bake every ``pending`` job; ``on_done(job)`` is called in the calling thread as each finishes.

    Pending jobs with one values key (lutbake.sharing) form a group, computed once and written per job.
    Groups run on min(workers, groups) threads, each on the tile executor with ``workers`` tile threads:
    a big table keeps every core busy after the small ones are done (the OS shares the cores while
    several tables run; the result is bit-identical either way).
    Returns None, or the signal number if the run was interrupted (the unfinished jobs are then marked
    ``interrupted``; finished files are kept). ``progress``: lutbake.runtime.executor.Progress, per table.
    ``cache``: lutbake.values_cache.ValuesCache, whose entries of other sources are pruned first.
    ``runner``: where the tiles run (lutbake.runtime.cluster.DaskRunner); None: this process' threads.
    """
    workers = workers or default_workers()
    for d in sorted({j.path.parent for j in jobs}):
        remove_stale_temps(d)  # left by writers that were killed before their rename
    pending = [j for j in jobs if j.status == "pending"]
    if not pending:
        return None
    if cache is not None:
        cache.prune()
    groups = group_by(pending, lambda j: j.values_key)
    threads = max(1, min(workers, len(groups)))
    per_table = workers
    cancel = threading.Event()
    pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="lutbake-table")
    queue = deque(groups)
    queue_lock = threading.Lock()
    set_back: set[int] = set()

    def bake_next() -> list[Job]:
        """Bake the group at the head of the queue. A group whose first kernel module another table's thread is
        compiling steps back once, behind the next group (lutbake.runtime.warp_runtime.defer_if_busy: that core
        compiles or
        bakes something else meanwhile); each task bakes exactly one group."""
        while True:
            with queue_lock:
                g = queue.popleft()
                may_defer = bool(queue) and id(g) not in set_back
            try:
                with defer_if_busy() if may_defer else contextlib.nullcontext():
                    return _bake_group(g, per_table, device, progress, cancel, cache, runner)
            except ModuleBusy:
                with queue_lock:
                    set_back.add(id(g))
                    queue.insert(1, g)

    futures: list = []
    signum = None
    reported: set[int] = set()
    try:
        futures = [pool.submit(bake_next) for _ in groups]
        remaining = set(futures)
        while remaining:
            done, remaining = wait(remaining, timeout=poll, return_when=FIRST_COMPLETED)
            for f in done:
                g = f.result()
                reported.add(id(g))
                for j in g:
                    if on_done:
                        on_done(j)
    except (KeyboardInterrupt, Interrupted) as e:
        signum = getattr(e, "signum", int(signal.SIGINT))
        cancel.set()
        for f in futures:
            f.cancel()
    finally:
        pool.shutdown(wait=True)  # running tables stop at their next tile (or finish writing)
    if signum is not None:
        for j in pending:
            if j.status == "pending":  # cancelled before it started
                j.status, j.message = "interrupted", "not started; nothing written"
        for g in groups:
            if id(g) not in reported and on_done:
                for j in g:
                    on_done(j)
    return signum


def signal_name(signum: int) -> str:
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


def exit_status(jobs: list[Job], signum: int | None) -> int:
    """130 after SIGINT, 143 after SIGTERM, 1 if any table failed or ended over its tolerance unaccepted
    (Job.accepted), else 0."""
    if signum is not None:
        return EXIT_SIGTERM if signum == signal.SIGTERM else EXIT_SIGINT
    if any(j.status == "failed" or (j.status == "over_tolerance" and not j.accepted) for j in jobs):
        return EXIT_FAILED
    return EXIT_OK


def write_report(path, jobs: list[Job], status: int, signum: int | None = None) -> Path:
    """``--report FILE.json``: the run's summary, one entry per table, written atomically."""
    path = Path(path)
    doc = {
        "lutbake_version": __version__,
        "exit_status": status,
        "interrupted_by": signal_name(signum) if signum is not None else None,
        "counts": {s: sum(j.status == s for j in jobs) for s in STATUSES},
        "tables": [j.report() for j in jobs],
    }
    remove_stale_temps(path.parent)  # a report writer killed before its rename left one
    atomic_write_bytes(path, (json.dumps(doc, indent=2) + "\n").encode("utf-8"))
    return path


@contextlib.contextmanager
def signal_handlers():
    """While active (main thread only), SIGTERM raises Interrupted in the main thread, as Ctrl-C
    raises KeyboardInterrupt, so run() can cancel cleanly. Restores the previous handlers."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def on_term(signum, frame):
        raise Interrupted(signum)

    old = signal.signal(signal.SIGTERM, on_term)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)
