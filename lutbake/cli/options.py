"""What the commands share: the options declared once (click decorators), the exit status of a bad option, file or
config, and the one way a command reports such an error."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import click

EXIT_CONFIG = 2


def fail(message, status: int = EXIT_CONFIG):
    """Print ``error: message`` on stderr (control characters escaped) and exit with ``status``."""
    from ..textsafe import escape_controls

    click.echo(f"error: {escape_controls(str(message))}", err=True)
    sys.exit(status)


class FiniteFloat(click.ParamType):
    """A finite number within [``minimum``, ``maximum``] (``open_min``: above ``minimum``), for every float option.
    click's float and FloatRange let NaN through (every comparison with it is false: ``--max-error nan`` was never
    met, ``--nov-min nan`` measured nothing) and Inf; both are refused here."""

    name = "number"

    def __init__(self, minimum: float | None = None, maximum: float | None = None, open_min: bool = False):
        self.minimum, self.maximum, self.open_min = minimum, maximum, open_min

    def convert(self, value, param, ctx):
        try:
            x = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(x):
            self.fail(f"{value!r}: must be a finite number", param, ctx)
        lo, hi = self.minimum, self.maximum
        if lo is not None and (x < lo or (self.open_min and x == lo)):
            self.fail(f"{value!r}: must be {'>' if self.open_min else '>='} {lo:g}", param, ctx)
        if hi is not None and x > hi:
            self.fail(f"{value!r}: must be <= {hi:g}", param, ctx)
        return x


def out_dir_option(default: str, what: str):
    """``--out-dir``, of the commands that write files."""
    return click.option(
        "--out-dir",
        type=click.Path(path_type=Path),
        default=Path(default),
        show_default=True,
        help=f"Directory the {what} are written to.",
    )


def out_file_option(what: str, dir_okay: bool = True):
    """``-o/--out FILE``: the one file a command writes (preview, fit); ``dir_okay``: a directory passes the option
    (the command's own check then says why it is refused)."""
    return click.option(
        "-o", "--out", type=click.Path(path_type=Path, dir_okay=dir_okay), default=None, help=f"Write {what}."
    )


def force_png_option(what: str):
    """``--force``: write the PNG ``what`` names even under a name that does not end in .png (audit, preview)."""
    return click.option("--force", is_flag=True, help=f"Write {what} even under a name that does not end in .png.")


def set_option(help_text: str):
    """``--set KEY=VALUE`` (repeatable): a config key over every table, or NAME.KEY=VALUE over one."""
    return click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE", help=help_text)


def workers_option(f):
    """``--workers``: tile threads."""
    return click.option(
        "--workers", type=click.IntRange(min=1), default=None, help="Worker threads (default: every core)."
    )(f)


def json_option(what: str):
    """``--json``: the result as JSON."""
    return click.option("--json", "as_json", is_flag=True, help=f"Print the {what} as JSON.")


def conventions_options(set_help: str):
    """``--preset NAME`` / ``--config FILE`` / ``--set KEY=VALUE``: the conventions a file or a size is measured
    under (audit, size); the command receives them as one dict ``conventions`` {"preset", "config", "overrides"}."""

    def decorate(f):
        f = set_option(set_help)(f)
        f = click.option(
            "--config", type=click.Path(path_type=Path), default=None, help="Conventions of a config's first table."
        )(f)
        f = click.option(
            "--preset",
            default=None,
            metavar="NAME",
            help="Conventions of a preset (lutbake list); default: the file's own recorded conventions, else "
            "'default'.",
        )(f)
        return f

    return decorate


def conventions_of(preset, config, overrides) -> dict:
    """The ``conventions`` dict of conventions_options' values (exit 2 when both a preset and a config are given)."""
    if preset and config:
        fail("give --preset or --config, not both")
    return {"preset": preset, "config": config, "overrides": overrides}


def quiet_warp() -> None:
    """Start Warp without its banner and CUDA-driver warning (lutbake.runtime.warp_runtime; --verbose brings them
    back)."""
    from ..runtime.warp_runtime import init_warp

    init_warp()
