"""Untrusted text (config keys and values, file names, messages of other libraries) made safe to print:
control characters (C0 but tab and newline, DEL, C1) and the bidirectional overrides are shown as escapes,
so a key holding ``"\\x1b]0;PWNED\\x07\\x1b[2J"`` cannot retitle or clear the terminal (issue 11)."""

from __future__ import annotations

import re

# C0 controls except \t and \n, DEL, C1 controls, line/paragraph separators, bidi embeddings/overrides/isolates
_UNSAFE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")
REPR_LIMIT = 200  # characters of a value shown in a message


def escape_controls(text: str) -> str:
    """``text`` with every unsafe character written as a Python escape (``\\x1b``, ``\\u202e``)."""
    return _UNSAFE.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), str(text))


def safe_repr(value, limit: int = REPR_LIMIT) -> str:
    """repr(value), escaped (repr escapes controls in strings), at most ``limit`` characters, and never a
    RecursionError for a value nested 100 000 deep."""
    try:
        text = repr(value)
    except RecursionError:
        return f"<a {type(value).__name__} nested too deeply to show>"
    text = escape_controls(text)
    return text if len(text) <= limit else text[: limit - 1] + "…"


NAME_LIMIT = 160  # characters of a file name or path shown in a message
TEXT_LIMIT = 4096  # characters of any one string from a file shown in a figure or on the terminal


def shorten(text, limit: int = NAME_LIMIT) -> str:
    """``text`` escaped (escape_controls) and, past ``limit`` characters, cut in the middle with the count said:
    a 10 000-character name is echoed as its head and tail, never as a 10 KB line."""
    text = escape_controls(str(text))
    if len(text) <= limit:
        return text
    keep = max(limit - 40, 8)
    return f"{text[: keep // 2]}…[{len(text) - keep} characters]…{text[-(keep - keep // 2) :]}"


def bounded(text, limit: int = TEXT_LIMIT) -> str:
    """A string read from a file, made safe for matplotlib and the terminal: escaped, at most ``limit`` characters
    (matplotlib lays text out in time quadratic in its length; a 50 MiB sidecar string took gigabytes)."""
    text = str(text)
    if len(text) > limit:
        text = text[:limit] + f"… [{len(text) - limit} more characters]"
    return escape_controls(text)
