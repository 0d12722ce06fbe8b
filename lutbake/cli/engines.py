"""The commands for shipping tables to engines: ``audit``, ``size``, ``fit`` (each parses, calls
lutbake.commands.<name>, prints)."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from ..environment.curves import CURVES as CURVE_NAMES
from ..io.cubemap import cube_kind
from .options import (
    FiniteFloat,
    conventions_of,
    conventions_options,
    fail,
    force_png_option,
    json_option,
    out_file_option,
    quiet_warp,
    workers_option,
)


def _shape(text: str | None):
    if text is None:
        return None
    try:
        parts = tuple(int(p) for p in text.lower().split("x"))
    except ValueError:
        parts = ()
    if len(parts) != 3 or min(parts) < 1:
        raise click.BadParameter(f"{text!r}: expected ROWSxCOLUMNSxCHANNELS, e.g. 16x16x2", param_hint="--shape")
    return parts


@click.command()
@click.argument("file", type=click.Path(path_type=Path))
@conventions_options("Override a convention key (texel, row_order, roughness, layout, ...); the size is the file's.")
@click.option(
    "--tolerance",
    type=FiniteFloat(minimum=0.0),
    default=1e-3,
    show_default=True,
    help="Exit 0 when the chosen error metric is within this, 1 otherwise.",
)
@click.option(
    "--metric",
    type=click.Choice(["max", "p99", "mean"]),
    default="max",
    show_default=True,
    help="Which |file - converged| statistic is held against --tolerance.",
)
@click.option(
    "--max-side",
    type=click.IntRange(min=2),
    default=128,
    show_default=True,
    help="Re-integrate at most this many rows and columns (strided subset, last row/column included).",
)
@click.option(
    "--shape",
    default=None,
    metavar="RxCxC",
    help="Layout of a text array (C header / JS / WGSL / Rust) whose file does not declare it, e.g. 16x16x2.",
)
@click.option(
    "--error-map",
    type=click.Path(path_type=Path),
    default=None,
    metavar="PNG",
    help="Write |file - converged| per channel with labelled axes.",
)
@click.option(
    "--curve",
    type=click.Choice(sorted(CURVE_NAMES)),
    default=None,
    help="A cube map's roughness -> mip curve (default: the preset's, the file's record, else linear).",
)
@json_option("report (for CI)")
@workers_option
@force_png_option("--error-map")
def audit(
    file, preset, config, overrides, tolerance, metric, max_side, shape, error_map, curve, as_json, workers, force
):
    """Compare the LUT FILE with a converged re-bake under declared conventions and diagnose mistakes.

    Reports max/mean/percentile |file - converged| per channel and where the maximum sits, tests each usual
    hand-over mistake against the data (flipped/swapped axes, half- and one-texel offsets, alpha vs
    perceptual roughness, sRGB decoding, swapped channels, the other split-sum layout) and names the one that
    explains the data, the storage quantisation and the Monte-Carlo noise (estimated sample count).
    Exit 0 when within --tolerance, 1 otherwise, 2 on a bad option, file or config.

    A prefiltered cube map (KTX 2.0, KTX 1.1, DDS, EXR cube) is checked against lutbake's exact prefilter of its own
    mip 0: the GGX alpha fitted per mip against the curve's (--curve, or the preset's: --preset bevy-ibl), a gamma
    mistake, misplaced faces, the noise; an irradiance cube (one mip) against a Lambertian convolution. Exit 0 when
    nothing is named, 1 otherwise.

    \b
    Examples:
      lutbake audit dfg.dds --preset filament
      lutbake audit pisa_specular.ktx2 --preset bevy-ibl
      lutbake audit default_env_ibl.ktx --curve filament
      lutbake audit lut_ggx.png --preset gltf --error-map lut_ggx.err.png --json
      lutbake audit brdf.h --set texel=endpoint --set axis_order=roughness_x --shape 64x64x3
    """
    from ..commands.audit import audit as run_audit
    from ..commands.audit import report_json
    from ..errors import ConfigError

    conventions = conventions_of(preset, config, overrides)
    if cube_kind(file) is not None:
        _audit_cube(file, preset, curve, overrides, as_json, workers)
    quiet_warp()
    try:
        from ..preflight import check_image_output, input_files

        check_image_output(error_map, input_files(file) + ([config] if config else []), force, "--error-map")
        report = run_audit(
            file,
            conventions,
            tolerance=tolerance,
            metric=metric,
            max_side=max_side,
            error_map=error_map,
            shape=_shape(shape),
            workers=workers,
        )
    except (ConfigError, OSError, ValueError) as e:
        fail(e)
    click.echo(report_json(report) if as_json else report.text())
    sys.exit(0 if report.passed else 1)


def _audit_cube(file, preset, curve, overrides, as_json, workers):
    """``lutbake audit`` of a cube map (lutbake.commands.audit_cube): print, exit 0 when nothing is named, else 1."""
    import json

    from ..commands.audit_cube import audit_cube

    try:
        report = audit_cube(file, preset, curve, overrides, threads=workers)
    except (OSError, ValueError) as e:
        fail(e)
    click.echo(json.dumps(report.as_dict(), indent=1, default=str) if as_json else report.text(), nl=not as_json)
    sys.exit(0 if report.passed else 1)


@click.command()
@conventions_options("Override a convention key.")
@click.option(
    "--max-error",
    type=FiniteFloat(minimum=0.0, open_min=True),
    required=True,
    help="Target max |bilinear(table) - integral| between texels.",
)
@click.option(
    "--sizes",
    default="8,16,32,64,128,256,512",
    show_default=True,
    help="Square sizes N to try, in increasing order (stops once every format meets the target).",
)
@click.option(
    "--nov-min",
    type=FiniteFloat(0.0, 1.0),
    default=0.0,
    show_default=True,
    help="Measure only where NoV >= this (the grazing corner never converges on a linear NoV axis).",
)
@json_option("result")
@workers_option
def size(preset, config, overrides, max_error, sizes, nov_min, as_json, workers):
    """Smallest N x N resolution per storage format (UNORM8/10/16, F16, F32) whose max error after bilinear
    filtering, measured between texels against the integral, is within --max-error.

    \b
    Examples:
      lutbake size --preset default --max-error 1e-3
      lutbake size --preset unity-hdrp --max-error 1e-4 --nov-min 0.05 --json
    """
    import json

    from ..commands.size import smallest_sizes
    from ..errors import ConfigError

    conventions = conventions_of(preset, config, overrides)
    try:
        ns = tuple(int(s) for s in sizes.split(","))
        if not ns or min(ns) < 2:
            raise ValueError
    except ValueError:
        fail(f"--sizes {sizes!r}: a comma-separated list of integers >= 2")
    quiet_warp()
    try:
        result = smallest_sizes(
            conventions,
            max_error,
            ns,
            workers=workers,
            nov_min=nov_min,
        )
    except (ConfigError, OSError, ValueError) as e:
        fail(e)
    click.echo(json.dumps(result.as_dict(), indent=1) if as_json else result.text())


@click.command()
@click.argument("family", type=click.Choice(["karis-mobile", "gotanda-eq8"]))
@click.option("--lang", type=click.Choice(["glsl", "hlsl"]), default="glsl", show_default=True)
@out_file_option("the shader function here (default: print it after the error table)", dir_okay=False)
@json_option("constants and errors")
def fit(family, lang, out, as_json):
    """Refit a published closed form to lutbake's integral and emit it as GLSL/HLSL with its measured error
    (published constants vs refit, side by side).

    \b
    Examples:
      lutbake fit karis-mobile --lang hlsl -o env_brdf_approx.hlsl
      lutbake fit gotanda-eq8 --json
    """
    import json

    from ..commands.fit import fit as run_fit
    from ..io.atomic import atomic_write_bytes

    quiet_warp()
    result = run_fit(family)
    if as_json:
        click.echo(
            json.dumps(
                {
                    "family": family,
                    "published": list(result.published),
                    "refit": list(result.refit),
                    "errors": result.errors,
                },
                indent=1,
            )
        )
    else:
        click.echo(result.text())
    if out is not None:
        atomic_write_bytes(out, result.code[lang].encode())
        click.echo(str(out))
    elif not as_json:
        click.echo(result.code[lang])
