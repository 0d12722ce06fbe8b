"""The ``lutbake`` command line: a thin layer over the public Python API. Each command parses its options (the
shared ones declared once: lutbake.cli.options), calls the function a Python user would call (``bake``:
lutbake.api.bake; ``audit``, ``size``, ``fit``, ``preview``, ``spheres``: lutbake.commands.*; ``inspect``:
lutbake.io.describe; ``validate``: lutbake.validate) and prints."""

from __future__ import annotations

import click

from .. import __version__
from .bake import bake
from .engines import audit, fit, size
from .environment import spheres
from .tables import inspect, list_, plot, preview, validate


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
      lutbake spheres studio.exr                     # the split sum vs the ground truth, as spheres
      lutbake audit outputs/filament_dfg.dds         # against the file's own recorded conventions
      lutbake list
      lutbake validate
    """
    if verbose:
        import os

        from ..runtime.warp_runtime import VERBOSE_ENV

        os.environ[VERBOSE_ENV] = "1"


for _command in (bake, list_, inspect, plot, validate, preview, audit, size, fit, spheres):
    main.add_command(_command)
