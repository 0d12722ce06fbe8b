"""The commands that read and check tables: ``list``, ``inspect``, ``preview``, ``plot``, ``validate``."""

from __future__ import annotations

import shutil
import sys
import textwrap
from pathlib import Path

import click

from .options import fail, force_png_option, out_dir_option, out_file_option


@click.command("list")
def list_():
    """List table kinds, selectable terms, estimators and presets."""
    from ..axes import TEXELS
    from ..catalog import (
        ANISO_ESTIMATORS,
        ANISO_MODELS,
        DIFFUSE_MODELS,
        FRESNELS,
        HEMISPHERE_ESTIMATORS,
        MASKINGS,
        NDF_DESCRIPTIONS,
        SPECULAR_MODELS,
    )
    from ..config import presets
    from ..io.formats import ALL_FORMATS
    from ..kinds import KINDS
    from ..kinds.dfg import LAYOUTS
    from ..kinds.diffuse import DIFFUSE_ESTIMATORS
    from ..kinds.specular_aniso import VIEW_AZIMUTHS
    from ..metals import METALS

    width = max(60, min(shutil.get_terminal_size((100, 24)).columns, 120))

    def section(title, items):
        click.echo(click.style(title, bold=True))
        for k, v in items.items():
            lines = textwrap.wrap(v, width - 29, break_on_hyphens=False, break_long_words=False) or [
                ""
            ]  # whole descriptions, wrapped under their column
            click.echo(f"  {k:<26} {lines[0]}" + "".join(f"\n{'':29}{line}" for line in lines[1:]))
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
    section("Output formats (format = ... / --format)", ALL_FORMATS)
    section(
        "Presets (--preset NAME): what each is, and the files it writes",
        {k: preset_text(p) for k, p in presets().items()},
    )


def preset_text(path: Path) -> str:
    """A preset's description (its leading comment, every line of it) and the files it writes."""
    import tomllib

    from ..io.formats import written_files

    text = path.read_text(encoding="utf-8")
    lines = []
    for line in text.splitlines():
        if not line.startswith("#"):
            break
        lines.append(line.lstrip("#").strip())
    # the shipped TOML read as it is (validating an ltc preset would start Warp: lutbake list imports none of it)
    tables = tomllib.loads(text)["table"]
    files = [f for t in tables for f in written_files(t["name"], t.get("format", "exr"))]
    return " ".join(filter(None, lines)) + f" Writes: {', '.join(files)}."


@click.command()
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
    from ..errors import LutbakeError
    from ..io.describe import describe

    try:
        click.echo(describe(file), nl=False)
    except (LutbakeError, OSError) as e:
        fail(e)


@click.command()
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
    from ..commands.figures import error_table, plot_all

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


@click.command()
def validate():
    """Run the analytic checks; print each measured error against its tolerance.

    Per check: PASS or FAIL and its name; "measured" (the one number compared) and what it is;
    "tolerance"; then any secondary figure on its own labelled line (where the worst case is, other
    limits that are checked separately). Ends with the total ("37 passed, 0 failed"); exits with
    status 1 if any check fails.
    """
    from ..validate.checks import run_all
    from ..validate.results import summary

    results = []
    for r in run_all():
        results.append(r)
        head, *rest = r.lines()
        click.echo(click.style(head[:4], fg="green" if r.passed else "red") + head[4:])
        for line in rest:
            click.echo(line)
    click.echo(summary(results))
    sys.exit(0 if all(r.passed for r in results) else 1)


@click.command()
@click.argument("file", type=click.Path(path_type=Path))
@out_file_option("the PNG here (default: FILE's stem + .preview.png beside it)")
@force_png_option("the PNG")
def preview(file, out, force):
    """Render a PNG of a table file (any format lutbake writes; see inspect): 1D tables as curves, 2D
    tables as colour-mapped channels with labelled axes, 3D tables as labelled slice grids, btf tables as
    light x view images per sigma and phi; and, where the table has a split-sum reconstruction, a row of
    spheres shaded with it.

    \b
    Example:
      lutbake preview outputs/dfg.exr        # -> outputs/dfg.preview.png
    """
    from ..commands.preview import render
    from ..errors import LutbakeError

    try:
        path = render(file, out, force=force)
    except ImportError as e:
        fail(f"preview needs matplotlib (pip install 'lutbake[plot]'): {e}")
    except (LutbakeError, OSError) as e:
        fail(e)
    click.echo(str(path))
