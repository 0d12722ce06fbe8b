"""``lutbake bake``: parse, call lutbake.api.bake, print a line per table, the progress of the batch and a closing
summary."""

from __future__ import annotations

import sys
import threading
import time
from pathlib import Path

import click

from ..io.formats import ALL_FORMATS
from .options import fail, out_dir_option, set_option, workers_option

ACCEPT = "accept_over_tolerance"  # the config key that accepts a table over its tolerance (exit 0)
PROGRESS_MIN_EVALS = 1.5e7  # about a second of work on two busy cores: a single table shows a bar above it
DRAW_INTERVAL = 0.5  # seconds between redraws of the progress line as tiles finish


@click.command()
@click.argument("configs", nargs=-1, type=click.Path(path_type=Path))
@click.option("--preset", "presets", multiple=True, metavar="NAME", help="Bake a preset config (lutbake list).")
@out_dir_option("outputs", "tables")
@set_option("Override a key in every table (KEY=VALUE) or one table (NAME.KEY=VALUE); VALUE is TOML.")
@workers_option
@click.option(
    "--device", type=click.Choice(["cpu", "cuda"]), default="cpu", help="Warp device of the kernels: cpu, cuda."
)
@click.option(
    "--progress/--no-progress",
    default=None,
    help="Progress of the batch (tables done / total, the running table, elapsed, an estimate) on stderr; "
    "default: on a terminal.",
)
@click.option("--force", is_flag=True, help="Rebake every table, even those whose output is up to date.")
@click.option(
    "--cache",
    "cache_dir",
    type=click.Path(path_type=Path, file_okay=False),
    default=None,
    metavar="DIR",
    help="Keep each computation's values in DIR (content-addressed) and lay out again from there, without "
    "computing, any table whose values are known (make luts: <out-dir>/.cache). --force reads no entry.",
)
@click.option(
    "--report",
    type=click.Path(path_type=Path, dir_okay=False),
    default=None,
    metavar="FILE.json",
    help="Write a JSON summary: per table status, path, content hash, seconds, samples, error estimate.",
)
@click.option(
    "--scheduler",
    default=None,
    metavar="local:N|tcp://HOST:PORT",
    help="Run the tiles on a Dask cluster: local:N starts N worker processes here, tcp://HOST:8786 uses a running "
    "`dask scheduler` (pip install 'lutbake[dask]'; docs/cluster.md). Same files as without.",
)
@click.option(
    "--environment",
    type=click.Path(path_type=Path, dir_okay=False),
    default=None,
    metavar="FILE",
    help="The lat-long environment (.exr or .hdr, width = 2 x height) of every environment table (key `environment`; "
    "a preset such as bevy-ibl or gltf-ibl names none): its cubes are baked from FILE.",
)
@click.option(
    "--format",
    "fmt",
    type=click.Choice(list(ALL_FORMATS)),
    default=None,
    help="Output format of every table (same as --set format=...; default: each table's `format`, exr); each kind "
    "allows some of these (lutbake list; an ltc table: exr, npy, ltc_dds, js, c, cs).",
)
def bake(
    configs,
    presets,
    out_dir,
    overrides,
    workers,
    device,
    progress,
    force,
    cache_dir,
    report,
    scheduler,
    environment,
    fmt,
):
    """Bake every [[table]] of CONFIGS into OUT_DIR/<name>.<ext> (EXR unless `format` / --format says otherwise).

    All configs are validated before any kernel runs; a bad config exits with status 2 and writes
    nothing; so does an out-dir or --report that cannot be written. A table whose output exists with
    the same content hash (its config, the lutbake version and the kernels' source), and whose bytes
    match the sha256 recorded with it, is skipped ("skipped PATH (up to date)"); --force rebakes it. Tables bake
    in parallel; each prints one line: path, shape, seconds, samples per texel; on a terminal a progress line
    shows tables done / total, the running table, elapsed time and an estimate. The last line sums up the batch
    ("40 tables: 12 baked, 28 up to date, 0 failed, 64 s"). A table that fails does not stop the others; the exit
    status is then 1. A table whose texels end over their tolerance is written and prints "OVER TOLERANCE name: ..."
    (how many texels, their rows / columns, the worst estimate / tolerance); the exit status is then 1 unless its
    config sets accept_over_tolerance = true. Outputs are replaced atomically: Ctrl-C (exit 130) or SIGTERM
    (exit 143) keeps finished tables, writes no unfinished one, and lists the tables that did not finish; the next
    run bakes only those.

    \b
    Examples:
      lutbake bake configs/dfg.toml
      lutbake bake configs/*.toml --report outputs/report.json
      lutbake bake configs/dfg.toml --force --set size=[64,64] --set layout=multiscatter
      lutbake bake configs/dfg.toml --set dfg.estimator=sobol_vndf --set dfg.samples=4096
      lutbake bake --preset unreal --format dds        # -> outputs/preintegrated_gf.dds (R16G16_FLOAT)
      lutbake bake --preset bevy-ibl --environment studio.exr   # dfg + specular and diffuse cubes, one record
      lutbake bake configs/*.toml --scheduler local:2  # tiles on 2 Dask worker processes
      lutbake bake configs/*.toml --scheduler tcp://farm:8786 --device cuda
    """
    from .. import api, batch
    from ..config import preset_path
    from ..errors import ConfigError, LutbakeError

    t0 = time.perf_counter()
    terminal = sys.stderr.isatty() if progress is None else progress
    display = BatchProgress(terminal, t0)
    try:
        paths = [preset_path(p) for p in presets] + list(configs)
        if not paths:
            raise ConfigError("<command line>", None, message="give at least one CONFIG or --preset")
        with batch.signal_handlers():
            results = api.bake(
                paths,
                out_dir,
                overrides,
                workers,
                device,
                progress=display.texels,
                on_result=display.done,
                force=force,
                cache_dir=cache_dir,
                fmt=fmt,
                scheduler=scheduler,
                report=report,
                on_schedule=display.scheduled,
                check=False,
                environment=environment,
            )
    except LutbakeError as e:  # a bad config or path, an unreachable scheduler: before any kernel ran
        display.close()
        fail(e)
    except RecursionError:  # a value nested too deeply for some check that slipped past load_configs
        fail("a config or --set value is nested too deeply")
    except (KeyboardInterrupt, batch.Interrupted) as e:
        display.close()
        signum = getattr(e, "signum", batch.signal.SIGINT)
        click.echo(f"interrupted ({batch.signal_name(signum)}) while planning: nothing was baked or written", err=True)
        sys.exit(batch.exit_status([], signum))
    display.close()
    if results.report_error:
        click.echo(f"error: {results.report_error}", err=True)
    failed = [r.name for r in results if r.status == "failed"]
    unfinished = [r.name for r in results if r.status in ("interrupted", "pending")]
    if failed:
        click.echo(f"{len(failed)} of {len(results)} tables failed: {', '.join(failed)}", err=True)
    over = [r.name for r in results if r.status == "over_tolerance"]
    if over:
        refused = [r.name for r in results if r.status == "over_tolerance" and not r.spec.options.get(ACCEPT)]
        click.echo(
            f"{len(over)} of {len(results)} tables over their tolerance: {', '.join(over)}"
            + (
                f" (exit 1; {ACCEPT} = true in a table's config accepts it)"
                if refused
                else f" (accepted: {ACCEPT} = true)"
            ),
            err=True,
        )
    if results.interrupted_by is not None:
        click.echo(
            f"interrupted ({batch.signal_name(results.interrupted_by)}): {len(unfinished)} of {len(results)} tables "
            f"did not finish: {', '.join(unfinished) or '-'}; run the same command again to bake only those",
            err=True,
        )
    click.echo(summary(results, time.perf_counter() - t0))
    sys.exit(results.exit_status)


def summary(results, seconds: float) -> str:
    """The closing line: "40 tables: 12 baked, 28 up to date, 0 failed, 64 s" (and how many ended over their
    tolerance, how many were interrupted)."""
    statuses = ("baked", "skipped", "over_tolerance", "failed", "interrupted", "pending")
    n = {s: sum(r.status == s for r in results) for s in statuses}
    stopped = n["interrupted"] + n["pending"]
    return (
        f"{len(results)} table{'s' if len(results) != 1 else ''}: {n['baked']} baked, {n['skipped']} up to date, "
        + (f"{n['over_tolerance']} over tolerance, " if n["over_tolerance"] else "")
        + f"{n['failed']} failed"
        + (f", {stopped} interrupted" if stopped else "")
        + f", {seconds:.0f} s"
    )


class WorkClock:
    """The time left of a batch, from the work done rather than the tables done.

    Each pending table is planned with its texel count; once it starts (after its kernels are built) its cost, the
    integrand evaluations of its plan, is known, and each tile adds its texels. A table not started yet is weighed
    by its texels at the mean cost per texel of those started. The rate is the work done over the time since the
    first tile began, so the kernels' first compile (before any tile) does not count as baking:

        left = (now - first tile) * (work planned - work done) / work done

    (counting tables instead overestimates the time left when the large tables finish last, and counting the
    compile overestimates it by the compile's share). Times are whatever clock the caller passes."""

    def __init__(self):
        self.texels: dict[str, int] = {}
        self.cost: dict[str, float] = {}
        self.done: dict[str, int] = {}
        self.first: float | None = None

    def plan(self, name: str, texels: int) -> None:
        self.texels[name] = max(int(texels), 1)

    def start(self, name: str, texels: int, cost: float, now: float) -> None:
        self.texels[name] = max(int(texels), 1)
        self.cost[name] = float(cost)
        self.first = now if self.first is None else self.first

    def advance(self, name: str, n: int) -> None:
        self.done[name] = min(self.done.get(name, 0) + n, self.texels.get(name, n))

    def finish(self, name: str) -> None:
        if name in self.texels:
            self.done[name] = self.texels[name]

    def left(self, now: float) -> float | None:
        """Seconds left, or None before any work is done."""
        started = [n for n in self.texels if n in self.cost]
        if self.first is None or not started or now <= self.first:
            return None
        per_texel = sum(self.cost[n] for n in started) / sum(self.texels[n] for n in started)
        work = {n: self.cost.get(n, t * per_texel) for n, t in self.texels.items()}
        done = sum(w * self.done.get(n, 0) / self.texels[n] for n, w in work.items())
        if done <= 0:
            return None
        return (now - self.first) * (sum(work.values()) - done) / done


class BatchProgress:
    """What ``lutbake bake`` prints while the batch runs: one line per table as it ends ("[done/total] ...", stdout:
    plain lines wherever the output goes) and, on a terminal,
    a progress line on stderr redrawn in place: tables done / total, the running tables, elapsed, an estimate of
    the time left (WorkClock: the work done, weighed by each table's cost); a single long table gets a texel bar
    instead. Tables finish on the batch's threads while their tiles report from others: every write to the terminal
    goes through ``_write`` under one lock, and the status line is cleared before any other line is printed, so no
    line is ever glued to another."""

    def __init__(self, terminal: bool, t0: float):
        self.terminal, self.t0 = terminal, t0
        self.total = self.finished = self.pending = 0
        self.running: list[str] = []
        self.shown = False
        self.cache_warned = False  # a --cache that cannot be written is said once, not once per table
        self.clock = WorkClock()
        self.lock = threading.RLock()
        self.last_draw = 0.0

    def _write(self, text: str, nl: bool = True, err: bool = False) -> None:
        with self.lock:
            click.echo(text, nl=nl, err=err)

    def scheduled(self, results) -> None:
        from ..config import kind_of

        self.total = len(results)
        self.pending = sum(r.status == "pending" for r in results)
        for r in results:
            if r.status == "pending":
                self.clock.plan(r.name, kind_of(r.spec).texels(r.spec.options))

    def texels(self, label: str, n_texels: int, cost: float):
        """lutbake.runtime.executor.Progress: a table starts (its tiles are about to run)."""
        with self.lock:
            self.running.append(label)
            self.clock.start(label, n_texels, cost, time.perf_counter())
            self.draw()
            if self.terminal and self.pending == 1 and cost > PROGRESS_MIN_EVALS:
                return self._texel_bar(label, n_texels)
        return lambda n: self._advance(label, n)

    def _advance(self, label: str, n: int) -> None:
        """A tile of ``label`` is done: count its texels, and redraw at most every DRAW_INTERVAL seconds."""
        with self.lock:
            self.clock.advance(label, n)
            if time.perf_counter() - self.last_draw >= DRAW_INTERVAL:
                self.draw()

    def _texel_bar(self, label: str, n_texels: int):
        self.clear()
        bar = click.progressbar(length=n_texels, label=label, file=sys.stderr, show_eta=True)
        bar.__enter__()
        left = [n_texels]

        def update(n: int) -> None:
            with self.lock:
                self.clock.advance(label, n)
                bar.update(n)
                left[0] -= n
                if left[0] <= 0:
                    bar.__exit__(None, None, None)

        return update

    def done(self, r) -> None:
        with self.lock:
            self._done(r)

    def _done(self, r) -> None:
        from ..api import samples_note
        from ..textsafe import escape_controls

        if r.name in self.running:
            self.running.remove(r.name)
        self.finished += 1
        self.clock.finish(r.name)
        self.clear()
        count = f"[{self.finished}/{self.total}] "
        if r.status == "skipped":
            self._write(f"{count}skipped {escape_controls(str(r.path))} (up to date)")
        elif r.status == "over_tolerance" and r.table is None:  # up to date, as its file records
            self._write(f"{count}skipped {escape_controls(str(r.path))} (up to date)")
            self._write(f"OVER TOLERANCE {r.name}: {escape_controls(r.message)}", err=True)
        elif r.status in ("baked", "over_tolerance"):
            note = samples_note(r.spec, r.samples)
            if r.values_from is not None:
                note = "; ".join(filter(None, (note, f"values computed once with {r.values_from}")))
            samples = f"  {r.samples} samples/texel" if r.samples is not None else ""  # none: an environment cube
            self._write(
                f"{count}{escape_controls(str(r.path))}  {r.shape}  {r.seconds:.2f} s{samples}"
                + (f" ({note})" if note else "")
            )
            if r.status == "over_tolerance":
                self._write(f"OVER TOLERANCE {r.name}: {escape_controls(r.message)}", err=True)
        elif r.status == "failed":
            self._write(f"{count}FAILED {r.name}: {escape_controls(r.message)}", err=True)
        if r.cache_error and not self.cache_warned:
            self.cache_warned = True
            self._write(
                f"warning: {escape_controls(r.cache_error)}; the tables are baked, their values not kept", err=True
            )
        self.draw()

    def line(self) -> str:
        now = time.perf_counter()
        left = self.clock.left(now) if self.finished < self.total else None
        running = ""
        if self.running:
            running = f"  running {self.running[0]}" + (f" +{len(self.running) - 1}" if len(self.running) > 1 else "")
        return f"[{self.finished}/{self.total}]{running}  {now - self.t0:.0f} s" + (
            f", ~{left:.0f} s left" if left is not None else ""
        )

    def draw(self) -> None:
        with self.lock:
            if self.terminal and self.total and self.finished < self.total and self.pending > 1:
                self._write("\r\x1b[2K" + self.line(), nl=False, err=True)
                self.shown = True
                self.last_draw = time.perf_counter()

    def clear(self) -> None:
        with self.lock:
            if self.shown:
                self._write("\r\x1b[2K", nl=False, err=True)
                self.shown = False

    def close(self) -> None:
        self.clear()
