"""The commands that read and check tables: ``list``, ``inspect``, ``preview``, ``plot``, ``validate``."""

from __future__ import annotations

import shutil
import sys
import textwrap
from pathlib import Path

import click

from .options import fail, force_png_option, out_dir_option, out_file_option

LIST_TOPICS = ("kinds", "presets", "formats", "keys", "terms")
LIST_EXAMPLES = """
\b
Examples:
  lutbake list                 # a summary, and how to ask for more
  lutbake list kinds           # every table kind, its aliases and what it holds
  lutbake list presets         # every engine preset: what it is, the files it writes
  lutbake list formats         # every output format (format = ... / --format)
  lutbake list keys dfg        # every key of kind dfg: type, default, allowed values and their meaning
  lutbake list terms           # NDFs, masking, models, Fresnel, metals, layouts, estimators, texel conventions
"""


@click.command("list", epilog=LIST_EXAMPLES)
@click.argument("topic", required=False, type=click.Choice(LIST_TOPICS))
@click.argument("kind", required=False)
def list_(topic, kind):
    """List what lutbake offers: a short summary, or one TOPIC in full (kinds, presets, formats, keys KIND, terms)."""
    width = max(60, min(shutil.get_terminal_size((100, 24)).columns, 120))
    if kind is not None and topic != "keys":
        fail(f"only 'lutbake list keys KIND' takes a second argument (got {kind!r} after {topic or 'list'!r})")
    if topic == "keys":
        _list_keys(kind, width)
    else:
        {None: _list_summary, "kinds": _list_kinds, "presets": _list_presets, "formats": _list_formats}.get(
            topic, _list_terms
        )(width)


def _section(width: int, title: str, items: dict[str, str]) -> None:
    """A bold title, then one entry a line: its name, and its description wrapped under its column."""
    click.echo(click.style(title, bold=True))
    for k, v in items.items():
        lines = textwrap.wrap(v, width - 29, break_on_hyphens=False, break_long_words=False) or [""]
        click.echo(f"  {k:<26} {lines[0]}" + "".join(f"\n{'':29}{line}" for line in lines[1:]))
    click.echo()


def _names(width: int, title: str, names, more: str) -> None:
    """A bold title, the names wrapped into a paragraph, and the command that lists them in full."""
    click.echo(click.style(title, bold=True))
    text = ", ".join(names)
    click.echo(textwrap.fill(text, width, initial_indent="  ", subsequent_indent="  ", break_on_hyphens=False))
    click.echo(f"  ({more})")
    click.echo()


def _kind_entries() -> dict[str, str]:
    from ..kinds import KINDS

    return {k.name + (f" ({', '.join(k.aliases)})" if k.aliases else ""): k.description for k in KINDS.values()}


def _list_summary(width: int) -> None:
    from ..config import presets
    from ..io.formats import ALL_FORMATS
    from ..kinds import KINDS

    _names(width, "Table kinds (kind = ...)", KINDS, "lutbake list kinds; a kind's keys: lutbake list keys KIND")
    _names(width, "Presets (--preset NAME)", presets(), "lutbake list presets: what each is, the files it writes")
    _names(width, "Output formats (format = ... / --format)", ALL_FORMATS, "lutbake list formats")
    _names(width, "Terms", dict.fromkeys(title.split(" (")[0] for title in _terms()), "lutbake list terms")
    click.echo("Every key of a kind with its type, default and allowed values: lutbake list keys dfg")


def _list_kinds(width: int) -> None:
    _section(width, "Table kinds (kind = ...)", _kind_entries())


def _list_presets(width: int) -> None:
    from ..config import presets

    _section(
        width,
        "Presets (--preset NAME): what each is, and the files it writes",
        {k: preset_text(p) for k, p in presets().items()},
    )


def _list_formats(width: int) -> None:
    from ..io.formats import ALL_FORMATS

    _section(width, "Output formats (format = ... / --format)", ALL_FORMATS)


def _list_keys(kind: str | None, width: int) -> None:
    from ..config import kind_of
    from ..kinds import KINDS
    from ..kinds.reference import text

    if kind is None:
        fail(f"'lutbake list keys' needs a kind, e.g. 'lutbake list keys dfg'; kinds: {', '.join(KINDS)}")
    try:
        found = kind_of(kind)
    except KeyError as e:
        fail(e.args[0])
    for line in text(found):
        indent = len(line) - len(line.lstrip())
        hang = indent + (29 if indent else 2)
        click.echo(textwrap.fill(line, width, subsequent_indent=" " * hang, break_on_hyphens=False) if line else "")


def _terms() -> dict[str, dict[str, str]]:
    """The selectable terms, by section title: the registry's families (lutbake.records, and any plugin's records:
    lutbake.plugins) and the kinds' own name lists; warp-free."""
    from ..axes import TEXELS
    from ..kinds.dfg import LAYOUTS
    from ..kinds.diffuse import DIFFUSE_ESTIMATORS
    from ..kinds.specular_aniso import VIEW_AZIMUTHS
    from ..metals import METALS
    from ..plugins import load_entry_points
    from ..records import (
        ANISO_ESTIMATOR,
        ANISO_MODEL,
        DIFFUSE,
        FRESNEL,
        HEMISPHERE_ESTIMATOR,
        LTC_LOBE,
        MASKING,
        MODEL,
        NDF,
    )
    from ..registry import choices

    load_entry_points()  # an installed package's records are listed beside lutbake's
    return {
        "NDFs (ndf = ...)": choices(NDF),
        "Masking-shadowing (masking = ...)": choices(MASKING),
        "Models (dfg, albedo, albedo_avg, specular_3d: model = ...)": choices(MODEL),
        "Anisotropic models (specular_aniso: model = ...)": choices(ANISO_MODEL),
        "View azimuth (specular_aniso: view_azimuth = ...)": VIEW_AZIMUTHS,
        "Fresnel (dfg: those linear in f0; specular_3d: those of f0; fresnel = ...)": choices(FRESNEL),
        "Metals (specular_3d: metal = ...)": {k: f"n+ik R,G,B = {m.n} + i{m.k}; {m.source}" for k, m in METALS.items()},
        "DFG layouts (layout = ...)": LAYOUTS,
        "Estimators (dfg, albedo, albedo_avg, specular_3d: estimator = ...)": choices(HEMISPHERE_ESTIMATOR),
        "Diffuse models (kind = diffuse, model = ...)": choices(DIFFUSE),
        "Estimators (diffuse, diffuse_3d: estimator = ...)": DIFFUSE_ESTIMATORS,
        "Estimators (specular_aniso: estimator = ...)": choices(ANISO_ESTIMATOR),
        "LTC lobes (kind = ltc, lobe = ...)": choices(LTC_LOBE),
        "Texel conventions (texel = ...)": TEXELS,
    }


def _list_terms(width: int) -> None:
    for title, items in _terms().items():
        _section(width, title, items)


def kind_outputs(kind) -> tuple[str, ...]:
    """The suffixes of the files a table of ``kind`` writes beside its data file (lutbake.kinds.base.Kind.outputs)."""
    from ..kinds import KINDS

    return tuple(suffix for suffix, _ in KINDS[kind].outputs) if kind in KINDS else ()


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
    files = [
        f
        for t in tables
        for f in written_files(t["name"], t.get("format", "exr"), kind_outputs(t.get("kind")), t.get("kind"), t)
    ]
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
    spheres shaded with it. An environment's cube map (KTX 2.0, DDS, EXR): every mip's faces as a cross,
    and for an irradiance cube its SH and the cube on a sphere.

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
