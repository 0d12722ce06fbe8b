"""Checks of a config file before it is parsed: its path (a regular file of sane size, a name that is UTF-8) and its
TOML text (nesting depth, dotted-key length), each a message or None (lutbake.config raises them as ConfigErrors).
lutbake.preflight checks the paths a batch writes with the same ``encoding_problem``."""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

from .io.bounded import what_is

MAX_CONFIG_BYTES = 1 << 20  # a config is a few KiB; a larger file is not one (and is not read into memory)


def config_file_problem(path) -> str | None:
    """Why ``path`` cannot be read as a config (says what it is), or None for a regular file of sane size."""
    path = Path(path)
    problem = encoding_problem(path)
    if problem:
        return problem
    try:
        st = os.stat(path)
    except FileNotFoundError:
        if os.path.islink(path):
            return f"is a dangling symlink (to {os.readlink(path)!r}): no such config file"
        return "no such config file"
    except NotADirectoryError:
        return "no such config file (a parent in the path is a file)"
    except OSError as e:
        return f"cannot read: {e.strerror or e}"
    if not stat.S_ISREG(st.st_mode):
        return f"is {what_is(st.st_mode)}, not a config file"
    if st.st_size > MAX_CONFIG_BYTES:
        return f"is {st.st_size} bytes; a config is at most {MAX_CONFIG_BYTES} bytes (is it a config file?)"
    return None


def encoding_problem(path) -> str | None:
    """Why ``path`` cannot be handed to the libraries that write and record files (OpenImageIO takes UTF-8 text
    only; the path is recorded in the file's metadata), or None: a byte that is not UTF-8 (``\\xff``) in it."""
    try:
        os.fsencode(str(path)).decode("utf-8")
    except (UnicodeDecodeError, UnicodeEncodeError):
        raw = os.fsencode(str(path))
        bad = next(i for i in range(len(raw)) if not _utf8_prefix_ok(raw[: i + 1]))
        return f"its name holds the byte {raw[bad : bad + 1]!r} at byte {bad}, which is not UTF-8; rename it"
    return None


def _utf8_prefix_ok(raw: bytes) -> bool:
    try:
        raw.decode("utf-8")
    except UnicodeDecodeError as e:
        return e.reason == "unexpected end of data"
    return True


MAX_NESTING = 32  # arrays / inline tables inside each other; lutbake's deepest value is a list of numbers
MAX_KEY_PARTS = 32  # parts of one dotted key; tomllib takes quadratic time on long ones (20 000 parts: ~45 s)
_STRINGS = re.compile(r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'')
_COMMENT = re.compile(r"#[^\n]*")
_NOT_BRACKET = re.compile(r"[^\[\]{}]")


def nesting_problem(text: str) -> str | None:
    """Why ``text`` (TOML) is too deeply nested to be a config, found in one linear pass before parsing it
    (a RecursionError or minutes of parsing otherwise), or None."""
    import numpy as np

    bare = _COMMENT.sub("", _STRINGS.sub('""', text))
    # the depth after each bracket, an unmatched closing one ignored (depth >= 0): the walk of +-1 steps reflected at
    # 0 is its running sum minus the running sum's lowest value so far below 0
    brackets = np.frombuffer(_NOT_BRACKET.sub("", bare).encode(), np.uint8)
    walk = np.cumsum(np.where((brackets == ord("[")) | (brackets == ord("{")), 1, -1))
    deepest = int(np.max(walk - np.minimum(np.minimum.accumulate(walk), 0), initial=0))
    if deepest > MAX_NESTING:
        return f"arrays or inline tables nested {deepest} deep (at most {MAX_NESTING})"
    for line in bare.splitlines():
        key = line.split("=", 1)[0]
        parts = key.count(".") + 1
        if parts > MAX_KEY_PARTS:
            return f"a dotted key of {parts} parts (at most {MAX_KEY_PARTS})"
    return None
