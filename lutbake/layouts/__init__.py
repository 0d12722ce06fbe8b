"""Engine layouts as data: one ``Layout`` record per layout (lutbake.layouts.base), one module per engine.

Each module declares ``LAYOUTS`` (the layouts it defines: the values of a kind's ``layout`` key) and ``TABLES`` (the
``EngineTable`` records of the tables its engine loads: the preset that bakes each, the grid and storage keys the
engine fixes, its shipped table in tests/data). ``lookup_layout(kind, name)`` is the validating lookup (its error
lists the valid names and the nearest); kinds, value_bounds, preview and audit read the records, never a name.
Adding an engine: one module here (found by engine_modules), its preset TOMLs, its shipped table in tests/data.
"""

from __future__ import annotations

import difflib
import importlib
import pkgutil

from ..registry import Family, Record, choices, family
from .base import IBL, EngineChannel, EngineTable, Layout, Storage, Terms

NOT_ENGINES = ("base",)
FIRST = ("plain",)  # lutbake's own layouts lead the ``layout`` keys' lists (their defaults)


def engine_modules() -> tuple:
    """Every engine module of this package: ``plain`` first, then by name (a new module registers by existing)."""
    names = sorted(m.name for m in pkgutil.iter_modules(__path__) if m.name not in NOT_ENGINES)
    names = [n for n in FIRST if n in names] + [n for n in names if n not in FIRST]
    return tuple(importlib.import_module(f"{__name__}.{n}") for n in names)


ENGINES = engine_modules()
REGISTRY: dict[tuple[str, str], Layout] = {(lay.kind, lay.name): lay for m in ENGINES for lay in m.LAYOUTS}
TABLES: tuple[EngineTable, ...] = tuple(t for m in ENGINES for t in m.TABLES)


def layout_family(kind: str) -> Family:
    """The registry family of ``kind``'s layouts (lutbake.registry): a config's ``layout`` resolves to its record."""
    return family(f"{kind}_layout", f"the engine table layouts of kind {kind} (lutbake.layouts)")


for (_kind, _name), _lay in REGISTRY.items():
    layout_family(_kind).add(
        Record(
            f"{_kind}_layout", _name, _lay.summary, fields={"obj": _lay, "engine": _lay.engine, "source": _lay.source}
        )
    )


def layouts_of(kind: str) -> dict[str, Layout]:
    """The layouts of ``kind``, by name, in registration order."""
    return {name: lay for (k, name), lay in REGISTRY.items() if k == kind}


def lookup_layout(kind: str, name: str) -> Layout:
    """The record of layout ``name`` of ``kind``; KeyError naming the valid layouts and the nearest."""
    try:
        return REGISTRY[(kind, name)]
    except KeyError:
        names = sorted(layouts_of(kind))
        near = difflib.get_close_matches(str(name), names, n=1)
        hint = f" (did you mean {near[0]!r}?)" if near else ""
        raise KeyError(f"kind {kind!r} has no layout {name!r}{hint}; layouts: {', '.join(names)}") from None


def summaries(kind: str):
    """name -> summary of the layouts of ``kind``: the ``layout`` key's allowed values, each resolved to its record
    where a config is read (lutbake.registry.Choices)."""
    return choices(layout_family(kind), doc=f"kind {kind}'s layouts")


def engine_table(kind: str, name: str, options: dict) -> EngineTable | None:
    """The engine table a table ``name`` of ``kind`` with ``options`` is (EngineTable.holds), or None."""
    return next((t for t in TABLES if t.holds(kind, name, options)), None)


def reconstruction_with_engine_line(kind: str, name: str, options: dict, reconstruction: str) -> str:
    """``reconstruction`` led by the engine's own shader line where the table is an engine's (EngineTable.shader):
    the line ``lutbake inspect`` prints first and the README's engine table shows."""
    table = engine_table(kind, name, options)
    if table is None or not table.shader:
        return reconstruction
    return f"{table.engine}: {table.shader}\n{reconstruction}"


def exclusive_owner(kind: str, fmt: str) -> Layout | None:
    """The layout of ``kind`` that alone writes format ``fmt`` (OpenPBR's header), or None."""
    return next((lay for lay in layouts_of(kind).values() if fmt in lay.storage.exclusive), None)


__all__ = [
    "ENGINES",
    "REGISTRY",
    "TABLES",
    "EngineChannel",
    "EngineTable",
    "IBL",
    "Layout",
    "Storage",
    "Terms",
    "engine_table",
    "exclusive_owner",
    "layouts_of",
    "lookup_layout",
    "reconstruction_with_engine_line",
    "summaries",
]
