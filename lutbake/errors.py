"""Errors users see. A ConfigError always names the file, the key, the bad value and what is allowed.
Keys and values are shown repr-escaped and bounded (lutbake.textsafe): no terminal escape sequence and no
RecursionError reaches the user."""

from __future__ import annotations

import difflib

from .textsafe import safe_repr, shorten

MESSAGE_LIMIT = 2000  # characters of one error line: a 10 000-character name is shown cut in the middle


def did_you_mean(value, names) -> str:
    """ "; did you mean 'x'?" for the name of ``names`` closest to ``value`` (difflib), or "" when none is close."""
    if not isinstance(value, str):
        return ""
    close = difflib.get_close_matches(value, [str(n) for n in names], n=1, cutoff=0.6)
    return f"; did you mean {close[0]!r}?" if close else ""


class LutbakeError(Exception):
    """Base of lutbake's user-facing errors (the CLI prints them without a traceback)."""


class ConfigError(LutbakeError):
    def __init__(
        self,
        file,
        key: str | None,
        value=None,
        allowed: str | None = None,
        message: str | None = None,
        table: str | None = None,
    ):
        self.file, self.key, self.value, self.allowed, self.table = str(file), key, value, allowed, table
        self.message = message
        where = shorten(self.file)
        if table is not None:
            where += f": table {table}"
        parts = [where]
        if key is not None:
            shown = safe_repr(key)
            parts.append(f"key {shown} = {safe_repr(value)}" if value is not None else f"key {shown}")
        text = ": ".join(parts)
        if message:
            text += f": {message}"
        if allowed:
            text += f" (allowed: {allowed})"
        super().__init__(shorten(text, MESSAGE_LIMIT))

    def blamed(self, file) -> ConfigError:
        """The same error, naming ``file`` (the --set argument that set the key) as its source."""
        return ConfigError(file, self.key, self.value, self.allowed, self.message, self.table)


class ArgumentError(ConfigError):
    """A wrong argument of the Python API (``lutbake.bake``, ``bake_table``, ``load_config``, ``load_configs``): the
    message names the function, the argument, the value and what is accepted. A ConfigError, so one ``except
    lutbake.ConfigError`` catches every input the API refuses."""

    def __init__(self, function: str, argument: str, value, allowed: str):
        super().__init__(
            f"lutbake.{function}()", None, message=f"argument {argument} = {safe_repr(value)}: must be {allowed}"
        )
        self.key, self.value, self.allowed = argument, value, allowed


class TableError(LutbakeError):
    """A table failed while baking (non-finite values, a kernel error); other tables are unaffected."""
