"""Warp, started quietly. Warp prints a banner and one line per module load (at its INFO log level), and
its native library prints "Warp CUDA warning: Could not find or load the NVIDIA CUDA driver" to the
process' stderr on every machine without a GPU. lutbake's commands and its Python API print their own
lines only, unless asked: ``LUTBAKE_VERBOSE=1`` in the environment (``lutbake --verbose ...``) keeps
everything Warp says.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
import threading

VERBOSE_ENV = "LUTBAKE_VERBOSE"
_LOCK = threading.Lock()
_started = False


def verbose() -> bool:
    """True when LUTBAKE_VERBOSE is set to anything but '', 0, false, no, off."""
    return os.environ.get(VERBOSE_ENV, "").strip().lower() not in ("", "0", "false", "no", "off")


@contextlib.contextmanager
def stderr_silenced():
    """Point file descriptor 2 at /dev/null (native code writes there, not to sys.stderr)."""
    try:
        sys.stderr.flush()
    except (AttributeError, ValueError):
        pass
    saved = os.dup(2)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def init_warp():
    """Import and initialise Warp once per process, quietly unless ``verbose()``; returns the module.
    ``lutbake.terms`` calls it on import: every lutbake kernel is built from its terms, so Warp is started
    (and its log level set) before any lutbake kernel loads, from the CLI and the Python API alike."""
    global _started
    import warp as wp

    loud = verbose()
    wp.config.log_level = logging.INFO if loud else logging.WARNING
    with _LOCK:
        if not _started:
            if loud:
                wp.init()
            else:
                with stderr_silenced():
                    wp.init()
            _started = True
    return wp
