"""Table kinds: declarations, a registry with aliases and a validating lookup (``lutbake list`` prints it).

Every kind is one module here that declares its keys, axes, channels and reconstruction text and names its
integrand (lutbake.integrands) and estimator (lutbake.sampling); ``base.declare`` adds the keys every kind has
(name, kind, format, dtype, seed, samples, estimator). The texel cap is config.MAX_TEXELS, for every kind.
A module registers its kinds by existing (``kind_modules``, as lutbake.layouts finds its engine modules): each
``Kind`` it declares becomes a record of the registry's ``kind`` family (lutbake.registry).
"""

from __future__ import annotations

import importlib
import pkgutil

from ..registry import Record, RegistryError, family
from .base import Key, Kind

NOT_KINDS = ("base", "reference")
FIRST = ("dfg",)  # the default kind leads the listings


def kind_modules() -> tuple:
    """Every kind module of this package: ``dfg`` first, then by name (a new module registers by existing)."""
    names = sorted(m.name for m in pkgutil.iter_modules(__path__) if m.name not in NOT_KINDS)
    names = [n for n in FIRST if n in names] + [n for n in names if n not in FIRST]
    return tuple(importlib.import_module(f"{__name__}.{n}") for n in names)


KINDS: dict[str, Kind] = {}
for _module in kind_modules():  # each module's Kinds in the order it declares them
    KINDS.update((k.name, k) for k in vars(_module).values() if isinstance(k, Kind) and k.name not in KINDS)
ALIASES: dict[str, str] = {alias: k.name for k in KINDS.values() for alias in k.aliases}
KIND = family("kind", "table kinds: what a table integrates (keys, axes, channels, integrand, estimator)")
for _k in KINDS.values():
    KIND.add(Record("kind", _k.name, _k.description, aliases=_k.aliases, fields={"obj": _k}))

__all__ = ["ALIASES", "KINDS", "Key", "Kind", "kind_record", "lookup_kind"]


def kind_record(name: str) -> Record:
    """The record of the kind named ``name`` or one of its aliases; KeyError lists the valid names."""
    try:
        return KIND.lookup(name)
    except RegistryError as e:
        raise KeyError(f"unknown table kind {name!r}; valid kinds: {', '.join(sorted(KINDS) + sorted(ALIASES))}") from e


def lookup_kind(name: str) -> Kind:
    """The kind registered under ``name`` or one of its aliases (kind_record's object)."""
    return kind_record(name).obj
