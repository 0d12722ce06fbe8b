"""Errors users see. A ConfigError always names the file, the key, the bad value and what is allowed."""

from __future__ import annotations


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
        where = self.file
        if table is not None:
            where += f": table {table}"
        parts = [where]
        if key is not None:
            parts.append(f"key '{key}' = {value!r}" if value is not None else f"key '{key}'")
        text = ": ".join(parts)
        if message:
            text += f": {message}"
        if allowed:
            text += f" (allowed: {allowed})"
        super().__init__(text)


class TableError(LutbakeError):
    """A table failed while baking (non-finite values, a kernel error); other tables are unaffected."""
