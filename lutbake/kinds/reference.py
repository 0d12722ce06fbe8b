"""The config-key reference of a kind, rendered from its declarations (lutbake.kinds.base.Key): one row per key with
its type, default, allowed values (each with its description, or the numeric range) and documentation.

``lutbake list keys KIND`` prints ``text(kind)``; ``docs/keys/<kind>.md`` is ``markdown(kind)``, written by
``python -m lutbake.kinds.reference docs/keys`` and checked by tests/test_docs.py, so the reference cannot drift from
the code. No Warp: the declarations are plain data.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

from ..registry import Choices
from .base import Key, Kind

TYPE_NAMES = {
    "str": "string",
    "int": "integer",
    "float": "float",
    "int_pair": "[int, int]",
    "float_range": "[float, float]",
    "float_list": "[float, ...]",
    "name": "string",
    "bool": "boolean",
}


@dataclass(frozen=True)
class KeyRow:
    """One key as the reference shows it."""

    name: str
    type: str
    default: str
    allowed: str
    choices: tuple[tuple[str, str], ...]
    doc: str


def toml_value(value) -> str:
    """A default as TOML writes it: strings quoted, lists bracketed, None as "(none)"."""
    if value is None:
        return "(none)"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return repr(value)


def documented(choices):
    """The allowed values the documentation lists: a family's (lutbake.registry.Choices) lutbake's own records only,
    whatever plugin this process loaded; other choices as declared."""
    return choices.own() if isinstance(choices, Choices) else choices


def allowed_text(key: Key, own: bool = False) -> str:
    """The allowed values: the choices' names (``own``: lutbake's records only), or the numeric range, or "any"."""
    choices = documented(key.choices) if own else key.choices
    if choices:
        return ", ".join(choices)
    lo, hi = _number(key.minimum), _number(key.maximum)
    if lo and hi:
        return f"{lo} … {hi}"
    return f"≥ {lo}" if lo else f"≤ {hi}" if hi else "any"


def _number(value) -> str:
    """A bound as written: integers in full (2^24 = 16777216), other floats in %g."""
    if value is None:
        return ""
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


def rows(kind: Kind, own: bool = False) -> list[KeyRow]:
    """Every key of ``kind`` in declaration order (the common keys first); ``own``: a family's choices are lutbake's
    records only (the documentation), else every record this process holds (``lutbake list keys``)."""
    return [
        KeyRow(
            key.name,
            TYPE_NAMES.get(key.type, key.type),
            "required" if key.required else toml_value(key.default),
            allowed_text(key, own),
            tuple(((documented(key.choices) if own else key.choices) or {}).items()),
            key.doc,
        )
        for key in kind.keys.values()
    ]


def text(kind: Kind) -> list[str]:
    """The terminal reference of ``kind``'s keys: one block per key, its choices indented under it."""
    aliases = f" (aliases: {', '.join(kind.aliases)})" if kind.aliases else ""
    lines = [f"Keys of kind {kind.name}{aliases}: {kind.description}", ""]
    for row in rows(kind):
        lines.append(f"{row.name}  {row.type}, default {row.default}: {row.doc}")
        if row.choices:
            lines += [f"    {value:<24} {meaning}" for value, meaning in row.choices]
        elif row.allowed != "any":
            lines.append(f"    allowed {row.allowed}")
    return lines


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def markdown(kind: Kind) -> str:
    """docs/keys/<kind>.md: the keys of ``kind`` as one Markdown table."""
    aliases = f" (aliases {', '.join(f'`{a}`' for a in kind.aliases)})" if kind.aliases else ""
    out = [
        f"# Keys of kind `{kind.name}`{aliases}",
        "",
        f"{_cell(kind.description)}. Rendered from the kind's key declarations (`lutbake/kinds/`) by",
        f"`python -m lutbake.kinds.reference docs/keys`; `lutbake list keys {kind.name}` prints the same. How the keys "
        "work together: [config.md](../config.md).",
        "",
        "| key | type | default | allowed | meaning |",
        "| --- | --- | --- | --- | --- |",
    ]
    for row in rows(kind, own=True):
        if row.choices:
            allowed = "; ".join(f"`{value}`: {_cell(meaning)}" for value, meaning in row.choices)
        else:
            allowed = _cell(row.allowed)
        default = row.default if row.default in ("required", "(none)") else f"`{row.default}`"
        out.append(f"| `{row.name}` | {row.type} | {default} | {allowed} | {_cell(row.doc)} |")
    return "\n".join(out) + "\n"


def write_pages(folder: Path) -> list[Path]:
    """Write docs/keys/<kind>.md for every kind; returns the paths."""
    from . import KINDS

    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for kind in KINDS.values():
        path = folder / f"{kind.name}.md"
        path.write_text(markdown(kind), encoding="utf-8")
        paths.append(path)
    return paths


if __name__ == "__main__":  # python -m lutbake.kinds.reference docs/keys
    for written in write_pages(Path(sys.argv[1] if len(sys.argv) > 1 else "docs/keys")):
        print(written)
