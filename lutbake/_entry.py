"""The ``lutbake`` command's entry point: Ctrl-C at any moment, even while the start-up imports (click, numpy,
Warp, OpenImageIO) run, ends the command quietly with status 130 instead of a KeyboardInterrupt traceback
(issue 11). Imports nothing heavy itself; ``lutbake/__init__`` is lazy for the same reason."""

from __future__ import annotations

import sys

EXIT_SIGINT = 130


def _interrupted() -> None:
    try:
        sys.stderr.write("\ninterrupted (SIGINT)\n")
        sys.stderr.flush()
    finally:
        sys.exit(EXIT_SIGINT)


def main() -> None:
    try:
        import click

        from .cli import main as cli

        try:
            status = cli.main(prog_name="lutbake", standalone_mode=False)
        except click.exceptions.Abort as e:  # click turns Ctrl-C into Abort
            if isinstance(e.__cause__ or e.__context__, KeyboardInterrupt):
                _interrupted()
            sys.stderr.write("Aborted!\n")
            sys.exit(1)
        except click.ClickException as e:  # usage errors: click prints them as in standalone mode
            e.show()
            sys.exit(e.exit_code)
        sys.exit(status if isinstance(status, int) else 0)
    except KeyboardInterrupt:
        _interrupted()
