"""The environment's picture command: ``spheres`` (parses, calls lutbake.commands.spheres, prints)."""

from __future__ import annotations

from pathlib import Path

import click

from .options import fail, force_png_option, out_file_option, quiet_warp, workers_option


@click.command()
@click.argument("environment", type=click.Path(path_type=Path))
@out_file_option("the spheres' PNG here (default: ENVIRONMENT's stem + .spheres.png in the working directory)")
@click.option("--size", type=click.IntRange(8, 512), default=64, show_default=True, help="Pixels a side per sphere.")
@click.option(
    "--height",
    type=click.IntRange(min=1),
    default=128,
    show_default=True,
    help="Rows of the environment both methods see: the source's box-pyramid level at or below it.",
)
@click.option(
    "--cube-size", type=click.IntRange(1, 1024), default=64, show_default=True, help="The prefiltered cube's face."
)
@click.option(
    "--estimator",
    type=click.Choice(["auto", "harmonic", "quadrature"]),
    default="auto",
    show_default=True,
    help="How the cubes are prefiltered (the environment kinds' estimator key).",
)
@click.option(
    "--lobe",
    type=click.Choice(["ggx_nl", "ggx"]),
    default="ggx_nl",
    show_default=True,
    help="The weight the specular cube is prefiltered with (the environment_specular kind's lobe key).",
)
@click.option("--no-diffuse", is_flag=True, help="Leave out the diffuse models' spheres (<stem>_diffuse.png).")
@click.option(
    "--microfacet",
    is_flag=True,
    help="Add Gotanda's integrated microfacet diffuse (sigma = 1) to the diffuse spheres (minutes: its BRDF is an "
    "integral per texel).",
)
@force_png_option("the PNG")
@workers_option
def spheres(environment, out, size, height, cube_size, estimator, lobe, no_diffuse, microfacet, force, workers):
    """Spheres of roughness r = 0 ... 1 (gold, and a dielectric f0 = 0.04 over a Lambert base) under a lat-long
    ENVIRONMENT (.exr or .hdr, width = 2 x height), shaded by the ground truth (the BRDF against every texel of the
    environment) and by lutbake's split sum (its prefiltered and irradiance cubes, its DFG table), and their
    difference: a PNG, the diffuse models' PNG and the float arrays (.npz); prints the split sum's error per sphere.

    \b
    Example:
      lutbake spheres studio.exr -o outputs/studio.spheres.png
    """
    from ..commands import spheres as sp
    from ..errors import LutbakeError
    from ..io.environment import read_latlong
    from ..preflight import check_image_output
    from ..textsafe import shorten

    out = Path(out) if out else Path(environment.stem + ".spheres.png")
    try:
        check_image_output(out, [environment], force, "--out")
        env = read_latlong(environment)
    except (LutbakeError, OSError, ValueError) as e:
        fail(e)
    quiet_warp()
    image = sp.reduce(env.image, height)
    light = sp.lighting(image, cube_size=cube_size, lobe=lobe, workers=workers, method=estimator)
    renders = sp.render_spheres(light, size=size)
    diffuse = None
    if not no_diffuse:
        models = sp.DIFFUSE_MODELS + ((("microfacet", 1.0),) if microfacet else ())
        diffuse = sp.render_diffuse(light, size=max(8, size * 3 // 4), models=models, workers=workers)
    h, w = image.shape[:2]
    title = f"{shorten(environment.name)} at {w} x {h}, cube {cube_size}² ({lobe}, linear curve), DFG of preset bevy"
    try:
        paths = sp.write(renders, out, diffuse, title)
    except (LutbakeError, OSError) as e:
        fail(e)
    for line in sp.table_lines(renders):
        click.echo(line)
    if diffuse is not None:
        for (model, sigma), e, t in zip(diffuse.models, diffuse.errors(), diffuse.truth_error):
            click.echo(
                f"diffuse {model:<11} sigma {sigma:<4g} max {sp.share(e[0])[1:]:>7} RMS {sp.share(e[1])[1:]:>7} "
                f"mean {sp.share(e[2]):>7} truth ±{t:.1e}"
            )
    for p in paths:
        click.echo(str(p))
