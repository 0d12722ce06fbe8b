"""The ``lutbake`` command line: a thin layer over lutbake.api."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from . import __version__
from .io.formats import FORMATS

EXIT_CONFIG = 2


def out_dir_option(default: str, what: str):
    """The shared ``--out-dir`` option of the commands that write files."""
    return click.option(
        "--out-dir",
        type=click.Path(path_type=Path),
        default=Path(default),
        show_default=True,
        help=f"Directory the {what} are written to.",
    )


@click.group(context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.version_option(__version__, prog_name="lutbake")
@click.option(
    "-v",
    "--verbose",
    is_flag=True,
    help="Keep Warp's banner, CUDA-driver warning and module-load lines (same as LUTBAKE_VERBOSE=1).",
)
def main(verbose):
    """Bake pre-integrated BRDF lookup tables (split-sum DFG, ...) into EXR files.

    \b
    Examples:
      lutbake bake configs/dfg.toml                  # -> outputs/dfg.exr
      lutbake bake configs/*.toml --out-dir build/luts --workers 2
      lutbake bake --preset default --set samples=2048 --set dtype=half --out-dir outputs/examples
      lutbake inspect outputs/dfg.exr
      lutbake preview outputs/dfg.exr                # -> outputs/dfg.preview.png
      lutbake list
      lutbake validate
    """
    if verbose:
        import os

        from .runtime.warp_runtime import VERBOSE_ENV

        os.environ[VERBOSE_ENV] = "1"


@main.command()
@click.argument("configs", nargs=-1, type=click.Path(path_type=Path))
@click.option("--preset", "presets", multiple=True, metavar="NAME", help="Bake a preset config (lutbake list).")
@out_dir_option("outputs", "tables")
@click.option(
    "--set",
    "overrides",
    multiple=True,
    metavar="KEY=VALUE",
    help="Override a key in every table (KEY=VALUE) or one table (NAME.KEY=VALUE); VALUE is TOML.",
)
@click.option("--workers", type=click.IntRange(min=1), default=None, help="Worker threads (default: every core).")
@click.option(
    "--device", type=click.Choice(["cpu", "cuda"]), default="cpu", help="Warp device of the kernels: cpu, cuda."
)
@click.option("--progress/--no-progress", default=None, help="Progress bar (default: on a terminal, for long bakes).")
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
    "--format",
    "fmt",
    type=click.Choice(list(FORMATS)),
    default=None,
    help="Output format of every table (same as --set format=...; default: each table's `format`, exr).",
)
def bake(configs, presets, out_dir, overrides, workers, device, progress, force, cache_dir, report, scheduler, fmt):
    """Bake every [[table]] of CONFIGS into OUT_DIR/<name>.<ext> (EXR unless `format` / --format says otherwise).

    All configs are validated before any kernel runs; a bad config exits with status 2 and writes
    nothing; so does an out-dir or --report that cannot be written. A table whose output exists with
    the same content hash (its config, the lutbake version and the kernels' source), and whose bytes
    match the sha256 recorded with it, is skipped ("skipped PATH (up to date)"); --force rebakes it. Tables bake
    in parallel; each prints one line: path, shape, seconds, samples per texel. A table that fails
    does not stop the others; the exit status is then 1. Outputs are replaced atomically: Ctrl-C
    (exit 130) or SIGTERM (exit 143) keeps finished tables, writes no unfinished one, and lists the
    tables that did not finish; the next run bakes only those.

    \b
    Examples:
      lutbake bake configs/dfg.toml
      lutbake bake configs/*.toml --report outputs/report.json
      lutbake bake configs/dfg.toml --force --set size=[64,64] --set layout=multiscatter
      lutbake bake configs/dfg.toml --set dfg.estimator=sobol_vndf --set dfg.samples=4096
      lutbake bake --preset unreal --format dds        # -> outputs/preintegrated_gf.dds (R16G16_FLOAT)
      lutbake bake configs/*.toml --scheduler local:2  # tiles on 2 Dask worker processes
      lutbake bake configs/*.toml --scheduler tcp://farm:8786 --device cuda
    """
    import contextlib

    from . import batch, preflight
    from .api import samples_note
    from .config import load_configs, preset_path
    from .errors import ConfigError, LutbakeError
    from .runtime import cluster
    from .textsafe import escape_controls
    from .values_cache import open_cache

    try:
        paths = [preset_path(p) for p in presets] + list(configs)
        if not paths:
            raise ConfigError("<command line>", None, message="give at least one CONFIG or --preset")
        if fmt:
            overrides = tuple(overrides) + (f'format="{fmt}"',)
        specs = load_configs(paths, overrides)
        preflight.check_out_dir(out_dir)
        if scheduler is not None:
            cluster.parse_scheduler(scheduler)
        elif device == "cuda":  # on a cluster the workers' GPUs count (lutbake.runtime.cluster checks them)
            from .runtime.warp_runtime import init_warp

            if not init_warp().is_cuda_available():
                raise ConfigError("--device", "device", "cuda", "cpu", "no CUDA device is available")
        jobs = batch.schedule(specs, out_dir, force=force)
        preflight.check_outputs(jobs)
        preflight.check_report(report, jobs, paths)
    except ConfigError as e:
        click.echo(f"error: {e}", err=True)
        sys.exit(EXIT_CONFIG)
    except RecursionError:  # a value nested too deeply for some check that slipped past load_configs
        click.echo("error: a config or --set value is nested too deeply", err=True)
        sys.exit(EXIT_CONFIG)
    except KeyboardInterrupt:
        click.echo("interrupted (SIGINT) while planning: nothing was baked or written", err=True)
        sys.exit(batch.EXIT_SIGINT)

    def on_done(job):
        if job.status == "baked":
            note = samples_note(job.spec, job.samples)
            if job.values_from is not None:
                note = "; ".join(filter(None, (note, f"values computed once with {job.values_from}")))
            click.echo(
                f"{escape_controls(str(job.path))}  {job.shape}  {job.seconds:.2f} s  {job.samples} samples/texel"
                + (f" ({note})" if note else "")
            )
        elif job.status == "failed":
            click.echo(f"FAILED {job.name}: {escape_controls(job.message)}", err=True)

    for job in jobs:
        if job.status == "skipped":
            click.echo(f"skipped {escape_controls(str(job.path))} (up to date)")
    pending = sum(j.status == "pending" for j in jobs)
    bars = progress if progress is not None else (sys.stderr.isatty() and pending == 1)
    signum = None
    try:
        with batch.signal_handlers(), contextlib.ExitStack() as stack:
            if scheduler is not None and pending:
                try:
                    stack.enter_context(cluster.session(scheduler, device))
                except LutbakeError as e:  # unreachable scheduler, refused workers: before any tile runs
                    click.echo(f"error: {escape_controls(str(e))}", err=True)
                    sys.exit(EXIT_CONFIG)
                workers = pending  # every table in flight: the client's threads only wait for tiles
            signum = batch.run(
                jobs,
                workers,
                device,
                progress_bars if bars else None,
                on_done=on_done,
                cache=open_cache(cache_dir, force),
            )
    except (KeyboardInterrupt, batch.Interrupted) as e:  # a second Ctrl-C while tables wind down
        signum = getattr(e, "signum", 2)
        for job in jobs:
            if job.status == "pending":
                job.status, job.message = "interrupted", "interrupted; nothing written"
    status = batch.exit_status(jobs, signum)
    if report is not None:
        try:
            batch.write_report(report, jobs, status, signum)
        except OSError as e:
            from .io.oserror import os_error_text

            click.echo(
                f"error: cannot write the report {escape_controls(str(report))}: "
                f"{escape_controls(os_error_text(e, report.parent))}",
                err=True,
            )
            status = status or batch.EXIT_FAILED
    failed = [j.name for j in jobs if j.status == "failed"]
    unfinished = [j.name for j in jobs if j.status in ("interrupted", "pending")]
    if failed:
        click.echo(f"{len(failed)} of {len(jobs)} tables failed: {', '.join(failed)}", err=True)
    if signum is not None:
        click.echo(
            f"interrupted ({batch.signal_name(signum)}): {len(unfinished)} of {len(jobs)} tables did not "
            f"finish: {', '.join(unfinished) or '-'}; run the same command again to bake only those",
            err=True,
        )
    sys.exit(status)


PROGRESS_MIN_EVALS = 1.5e7  # about a second of work on two busy cores: show a bar above it


def progress_bars(label: str, n_texels: int, cost: float):
    """lutbake.runtime.executor.Progress drawn as a click progress bar on stderr (tables above PROGRESS_MIN_EVALS)."""
    if cost <= PROGRESS_MIN_EVALS:
        return None
    bar = click.progressbar(length=n_texels, label=label, file=sys.stderr, show_eta=True)
    bar.__enter__()
    left = [n_texels]

    def update(n: int) -> None:
        bar.update(n)
        left[0] -= n
        if left[0] <= 0:
            bar.__exit__(None, None, None)

    return update


@main.command("list")
def list_():
    """List table kinds, selectable terms, estimators and presets."""
    from .axes import TEXELS
    from .catalog import (
        ANISO_ESTIMATORS,
        ANISO_MODELS,
        DIFFUSE_MODELS,
        FRESNELS,
        HEMISPHERE_ESTIMATORS,
        MASKINGS,
        NDF_DESCRIPTIONS,
        SPECULAR_MODELS,
    )
    from .config import presets
    from .io.formats import FORMATS
    from .kinds import KINDS
    from .kinds.dfg import LAYOUTS
    from .kinds.diffuse import DIFFUSE_ESTIMATORS
    from .kinds.specular_aniso import VIEW_AZIMUTHS
    from .metals import METALS

    def section(title, items):
        click.echo(click.style(title, bold=True))
        for k, v in items.items():
            click.echo(f"  {k:<26} {v}")
        click.echo()

    section(
        "Table kinds (kind = ...)",
        {k.name + (f" ({', '.join(k.aliases)})" if k.aliases else ""): k.description for k in KINDS.values()},
    )
    section("NDFs (ndf = ...)", NDF_DESCRIPTIONS)
    section("Masking-shadowing (masking = ...)", MASKINGS)
    section("Models (dfg, albedo, albedo_avg, specular_3d: model = ...)", SPECULAR_MODELS)
    section("Anisotropic models (specular_aniso: model = ...)", ANISO_MODELS)
    section("View azimuth (specular_aniso: view_azimuth = ...)", VIEW_AZIMUTHS)

    section("Fresnel (specular_3d: fresnel = ...; dfg factors Schlick out)", FRESNELS)
    section(
        "Metals (specular_3d: metal = ...)", {k: f"n+ik R,G,B = {m.n} + i{m.k}; {m.source}" for k, m in METALS.items()}
    )
    section("DFG layouts (layout = ...)", LAYOUTS)
    section("Estimators (dfg, albedo, albedo_avg, specular_3d: estimator = ...)", HEMISPHERE_ESTIMATORS)
    section("Diffuse models (kind = diffuse, model = ...)", DIFFUSE_MODELS)
    section("Estimators (diffuse, diffuse_3d: estimator = ...)", DIFFUSE_ESTIMATORS)
    section("Estimators (specular_aniso: estimator = ...)", ANISO_ESTIMATORS)
    section("Texel conventions (texel = ...)", TEXELS)
    section("Output formats (format = ... / --format)", FORMATS)
    section("Presets (--preset NAME)", {k: _first_comment(p) for k, p in presets().items()})


def _first_comment(path: Path) -> str:
    for line in path.read_text().splitlines():
        if line.startswith("#"):
            return line.lstrip("# ").strip()
    return ""


@main.command()
@click.argument("file", type=click.Path(path_type=Path))
def inspect(file):
    """Print what a table file holds: kind, axes, channels, reconstruction, provenance and statistics.

    Reads every format lutbake writes, recognised by its first bytes (EXR, .npy, PNG, DDS, KTX2, C
    header, and the .json sidecars, with the data file they name); a table without lutbake metadata
    (as an engine ships it) gets its format, size, channels and value ranges.

    \b
    Examples:
      lutbake inspect outputs/dfg.exr
      lutbake inspect outputs/filament_dfg.dds      # metadata from its .json sidecar
    """
    from .errors import LutbakeError
    from .io.describe import describe

    try:
        click.echo(describe(file), nl=False)
    except (LutbakeError, OSError) as e:
        click.echo(f"error: {e}", err=True)
        sys.exit(EXIT_CONFIG)


@main.command()
@out_dir_option("outputs/figures", "PNGs")
@click.option(
    "--sigma-to-alpha",
    type=click.Choice(["sigma", "sigma_squared"]),
    default="sigma",
    show_default=True,
    help="GGX alpha from sigma for the integrated microfacet model.",
)
@click.option(
    "--order",
    type=click.IntRange(min=2, max=64),
    default=12,
    show_default=True,
    help="Gauss-Legendre order of the microfacet integral over m.",
)
@click.option("--no-png", is_flag=True, help="Only print the error table.")
def plot(out_dir, sigma_to_alpha, order, no_png):
    """Reproduce Figures 11-15 of Gotanda 2014 (settings of its Figures 6-10): Oren-Nayar, Oren-Nayar with Fresnel,
    the integrated microfacet model and the fitted model; print the fitted model's error per figure.

    \b
    Example:
      lutbake plot --out-dir outputs/figures
    """
    from .commands.figures import error_table, plot_all

    if not no_png:
        for p in plot_all(out_dir, sigma_to_alpha, order):
            click.echo(str(p))
    click.echo(
        f"fitted (Eq. 8) vs integrated (Eq. 4), alpha from sigma: {sigma_to_alpha}; errors in units of the "
        "integrated curve's maximum"
    )
    click.echo(
        f"{'figure':<7}{'abscissa':<9}{'fixed cos':>10}{'cos phi':>9}{'sigma':>7}{'max err':>9}{'rms err':>9}"
        f"{'at deg':>8}"
    )
    for r in error_table(sigma_to_alpha=sigma_to_alpha, order=order):
        click.echo(
            f"{r['figure']:<7}{r['vary']:<9}{r['fixed_cos']:>10.3f}{r['cos_phi']:>9.3f}{r['sigma']:>7.2f}"
            f"{r['max_err']:>9.3f}{r['rms_err']:>9.3f}{r['argmax_deg']:>8.0f}"
        )


@main.command()
def validate():
    """Run the analytic checks; print each measured error against its tolerance.

    Per check: PASS or FAIL and its name; "measured" (the one number compared) and what it is;
    "tolerance"; then any secondary figure on its own labelled line (where the worst case is, other
    limits that are checked separately). Ends with the total ("37 passed, 0 failed"); exits with
    status 1 if any check fails.
    """
    from .validate.checks import run_all, summary

    results = []
    for r in run_all():
        results.append(r)
        head, *rest = r.lines()
        click.echo(click.style(head[:4], fg="green" if r.passed else "red") + head[4:])
        for line in rest:
            click.echo(line)
    click.echo(summary(results))
    sys.exit(0 if all(r.passed for r in results) else 1)


@main.command()
@click.argument("file", type=click.Path(path_type=Path))
@click.option(
    "-o",
    "--out",
    type=click.Path(path_type=Path),
    default=None,
    help="PNG to write (default: FILE's stem + .preview.png beside it).",
)
@click.option("--force", is_flag=True, help="Write the PNG even under a name that does not end in .png.")
def preview(file, out, force):
    """Render a PNG of a table file (any format lutbake writes; see inspect): 1D tables as curves, 2D
    tables as colour-mapped channels with labelled axes, 3D tables as labelled slice grids, btf tables as
    light x view images per sigma and phi; and, where the table has a split-sum reconstruction, a row of
    spheres shaded with it.

    \b
    Example:
      lutbake preview outputs/dfg.exr        # -> outputs/dfg.preview.png
    """
    from .commands.preview import render
    from .errors import LutbakeError

    try:
        path = render(file, out, force=force)
    except ImportError as e:
        click.echo(f"error: preview needs matplotlib (pip install 'lutbake[plot]'): {e}", err=True)
        sys.exit(EXIT_CONFIG)
    except (LutbakeError, OSError) as e:
        click.echo(f"error: {e}", err=True)
        sys.exit(EXIT_CONFIG)
    click.echo(str(path))


from .cli_engines import audit, fit, size  # noqa: E402  (commands for shipping tables to engines)

for _command in (audit, size, fit):
    main.add_command(_command)

if __name__ == "__main__":
    main()
