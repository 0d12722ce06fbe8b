"""The ``lutbake`` command line: a thin layer over lutbake.api."""
from __future__ import annotations

import sys
from pathlib import Path

import click

from . import __version__

EXIT_CONFIG = 2


def _quiet_warp():
    """Warp >= 1.10 logs its banner and module loads at INFO; keep the CLI's output to its own lines."""
    import logging

    import warp as wp

    wp.config.log_level = logging.WARNING


@click.group(context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100})
@click.version_option(__version__, prog_name="lutbake")
def main():
    """Bake pre-integrated BRDF lookup tables (split-sum DFG, ...) into EXR files.

    \b
    Examples:
      lutbake bake configs/dfg.toml                  # -> outputs/dfg.exr
      lutbake bake configs/*.toml --out-dir build/luts --workers 2
      lutbake bake --preset default --set samples=2048 --set dtype=half
      lutbake inspect outputs/dfg.exr
      lutbake preview outputs/dfg.exr                # -> outputs/dfg.preview.png
      lutbake list
      lutbake validate
    """


@main.command()
@click.argument("configs", nargs=-1, type=click.Path(path_type=Path))
@click.option("--preset", "presets", multiple=True, metavar="NAME", help="Bake a preset config (lutbake list).")
@click.option("--out-dir", type=click.Path(path_type=Path), default=Path("outputs"), show_default=True,
              help="Directory the EXRs are written to.")
@click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
              help="Override a key in every table (KEY=VALUE) or one table (NAME.KEY=VALUE); VALUE is TOML.")
@click.option("--workers", type=click.IntRange(min=1), default=None,
              help="Worker threads (default: every core).")
@click.option("--device", type=click.Choice(["cpu", "cuda"]), default="cpu", show_default=True,
              help="Warp device the kernels run on.")
@click.option("--progress/--no-progress", default=None, help="Progress bar (default: on a terminal, for long bakes).")
@click.option("--format", "fmt", type=click.Choice(["exr", "npy", "png16", "dds", "ktx2", "h"]), default=None,
              help="Output format of every table (same as --set format=...; default: each table's `format`, exr).")
def bake(configs, presets, out_dir, overrides, workers, device, progress, fmt):
    """Bake every [[table]] of CONFIGS into OUT_DIR/<name>.<ext> (EXR unless `format` / --format says otherwise).

    All configs are validated before any kernel runs; a bad config exits with status 2 and writes
    nothing. Each table prints one line: path, shape, seconds, samples per texel. A table that fails
    does not stop the others; the exit status is then 1. Outputs are replaced atomically.

    \b
    Examples:
      lutbake bake configs/dfg.toml
      lutbake bake configs/dfg.toml --set size=[64,64] --set layout=multiscatter
      lutbake bake configs/dfg.toml --set dfg.estimator=sobol_vndf --set dfg.samples=4096
      lutbake bake --preset unreal --format dds        # -> outputs/preintegrated_gf.dds (R16G16_FLOAT)
    """
    from .config import load_configs, preset_path
    from .errors import ConfigError, LutbakeError

    _quiet_warp()
    try:
        paths = [preset_path(p) for p in presets] + list(configs)
        if not paths:
            raise ConfigError("<command line>", None, message="give at least one CONFIG or --preset")
        if fmt:
            overrides = tuple(overrides) + (f'format="{fmt}"',)
        specs = load_configs(paths, overrides)
        if device == "cuda":
            import warp as wp

            if not wp.is_cuda_available():
                raise ConfigError("--device", "device", "cuda", "cpu", "no CUDA device is available")
    except ConfigError as e:
        click.echo(f"error: {e}", err=True)
        sys.exit(EXIT_CONFIG)

    from .api import bake_table
    from .io.formats import write_table

    failed = []
    for spec in specs:
        try:
            table, seconds, samples = bake_table(spec, workers, device, progress)
            path = write_table(table, out_dir, spec.options["format"], spec.options["dtype"])
        except (LutbakeError, ValueError, OSError) as e:
            failed.append(spec.name)
            click.echo(f"FAILED {spec.name}: {e}", err=True)
            continue
        shape = "x".join(str(a.count) for a in table.axes) + f"x{len(table.channels)}"
        click.echo(f"{path}  {shape}  {seconds:.2f} s  {samples} samples/texel")
    if failed:
        click.echo(f"{len(failed)} of {len(specs)} tables failed: {', '.join(failed)}", err=True)
        sys.exit(1)


@main.command("list")
def list_():
    """List table kinds, selectable terms, estimators and presets."""
    from .axes import TEXELS
    from .config import presets
    from .io.formats import FORMATS
    from .tables import KINDS
    from .tables.dfg import LAYOUTS
    from .tables.specular import ESTIMATORS
    from .terms.sets import MASKINGS, NDFS

    def section(title, items):
        click.echo(click.style(title, bold=True))
        for k, v in items.items():
            click.echo(f"  {k:<26} {v}")
        click.echo()

    section("Table kinds (kind = ...)", {k.name + (f" ({', '.join(k.aliases)})" if k.aliases else ""): k.description
                                         for k in KINDS.values()})
    section("NDFs (ndf = ...)", {k: v.description for k, v in NDFS.items()})
    section("Masking-shadowing (masking = ...)", MASKINGS)
    section("Fresnel", {"schlick": "f0 + (1 - f0)(1 - v.h)^5: factored out by the dfg layouts"})
    section("DFG layouts (layout = ...)", LAYOUTS)
    section("Estimators (estimator = ...)", ESTIMATORS)
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
    """Print a baked table's kind, axes, channels, reconstruction, provenance and statistics.

    \b
    Example:
      lutbake inspect outputs/dfg.exr
    """
    from .io.exr import describe_exr

    _quiet_warp()
    try:
        click.echo(describe_exr(file))
    except (OSError, ValueError) as e:
        click.echo(f"error: {file}: {e}", err=True)
        sys.exit(EXIT_CONFIG)


@main.command()
@click.argument("file", type=click.Path(path_type=Path))
@click.option("-o", "--out", type=click.Path(path_type=Path), default=None,
              help="PNG to write (default: FILE's stem + .preview.png beside it).")
def preview(file, out):
    """Render a PNG of a baked table: each channel colour-mapped with labelled axes, and (dfg) a row of
    spheres lit with the split-sum through the table. Reads EXR, or .npy with its .json sidecar.

    \b
    Example:
      lutbake preview outputs/dfg.exr        # -> outputs/dfg.preview.png
    """
    from .preview import render

    try:
        path = render(file, out)
    except ImportError as e:
        click.echo(f"error: preview needs matplotlib (pip install 'lutbake[plot]'): {e}", err=True)
        sys.exit(EXIT_CONFIG)
    except (OSError, ValueError, KeyError) as e:
        click.echo(f"error: {file}: {e}", err=True)
        sys.exit(EXIT_CONFIG)
    click.echo(str(path))


@main.command()
def validate():
    """Run the analytic checks; print each measured error against its tolerance.

    Exits with status 1 if any check fails.
    """
    from .validate.checks import run_all

    _quiet_warp()
    ok = True
    for r in run_all():
        ok &= r.passed
        status = click.style("PASS", fg="green") if r.passed else click.style("FAIL", fg="red")
        click.echo(f"{status}  {r.name:<48} measured {r.measured:.3e}  tolerance {r.tolerance:.1e}  {r.detail}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
