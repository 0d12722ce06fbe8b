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
