"""The ``lutbake`` command's entry point: Ctrl-C at any moment, even while the start-up imports (click, numpy,
Warp, OpenImageIO) run, ends the command quietly with status 130 instead of a KeyboardInterrupt traceback
(issue 11). Imports nothing heavy itself; ``lutbake/__init__`` is lazy for the same reason. The process then
ends without the interpreter's teardown (``_exit``, issue 13)."""

from __future__ import annotations

import sys

EXIT_SIGINT = 130


def _interrupted() -> None:
    try:
        sys.stderr.write("\ninterrupted (SIGINT)\n")
        sys.stderr.flush()
    finally:
        sys.exit(EXIT_SIGINT)


def _exit(status: int) -> None:
    """End the process with ``status``, as sys.exit would but without the interpreter's teardown: once Warp is
    loaded, its final garbage collections over ~10^5 objects took 0.3-0.5 s of a 1-2 s bake, for memory the OS
    frees anyway (issue 13). What a user can see of the teardown still happens: the atexit hooks (Warp's, the
    flush of logging's handlers, temporary directories' removal), then the flush of stdout and stderr. While
    another thread runs (the interpreter would wait for it), or when a stream cannot be flushed (sys.exit reports
    it), this is sys.exit itself."""
    import atexit
    import os
    import signal
    import threading

    if threading.active_count() == 1:
        signal.signal(signal.SIGINT, signal.SIG_DFL)  # as the teardown does: a Ctrl-C now ends it, no traceback
        atexit._run_exitfuncs()  # runs each hook once, reporting any that fails, as the teardown does
        try:
            for stream in (sys.stdout, sys.stderr):
                if stream is not None:  # None: the descriptor was closed when Python started
                    stream.flush()
        except (OSError, ValueError):  # a closed pipe, a closed stream
            sys.exit(status)
        os._exit(status)
    sys.exit(status)


def _run() -> None:
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


def main() -> None:
    try:
        _run()
    except SystemExit as e:  # every status of the command, its own sys.exit included; a message is sys.exit's
        if e.code is None or isinstance(e.code, int):
            _exit(e.code or 0)
        raise
