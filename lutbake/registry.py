"""One open registry: every name a config may choose is a ``Record`` of a ``Family``.

A family (ndf, masking, fresnel, model, diffuse, facet_fresnel, aniso_model, ltc_lobe, estimator, kind, layout)
holds one record per entry: its name, aliases, a one-line description, its citation, the object it names and where
that object came from. lutbake's own records (lutbake.records, the kinds, the layouts) name their object lazily
(``Lazy("module:attr")``), so listing and validating names imports no Warp; a plugin's records (lutbake.plugins)
hold their objects and the source they came from. After colour-science's ``CanonicalMapping`` (one mapping per
family of methods, colour/utilities/data_structures.py) and mitsuba3's plugin registry (``mi.register_bsdf``):
a name is looked up once, where a config is read (lutbake.config), and the record travels below it.

Warp-free and at the foundation: it imports nothing of lutbake but its errors.
"""

from __future__ import annotations

import hashlib
import importlib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from .errors import did_you_mean

BUILTIN = "lutbake"  # Record.origin of lutbake's own records


@dataclass(frozen=True)
class Lazy:
    """``module:attr`` (optionally ``[key]`` into a mapping attribute), imported on first use."""

    target: str
    key: str | None = None

    def load(self):
        module, attr = self.target.split(":")
        value = getattr(importlib.import_module(module), attr)
        return value[self.key] if self.key is not None else value


@dataclass(frozen=True)
class Plugin:
    """Where a plugin's records came from: its file (or module), its source text and that text's sha256."""

    path: str  # the file, or "module NAME" for an installed entry point
    text: str
    module: str  # the name its code runs under (sys.modules)

    @property
    def sha256(self) -> str:
        return hashlib.sha256(self.text.encode()).hexdigest()


@dataclass(frozen=True, eq=False)
class Record:
    """One named entry of a family. ``fields`` holds the objects and facts the family needs (a Fresnel: ``F``, and
    ``Fc`` where F = f0 + (1 - f0) Fc is linear in f0; an NDF: its Distribution; a kind: its Kind), each either the
    object or a ``Lazy`` reference; ``record[name]`` loads it. Equality is identity: a plugin edited and registered
    again is a new record, so nothing cached for the old one is reused."""

    family: str
    name: str
    description: str
    citation: str = ""
    aliases: tuple[str, ...] = ()
    fields: Mapping[str, Any] = field(default_factory=dict)
    plugin: Plugin | None = None  # None: lutbake's own
    line: int | None = None  # the line of the plugin that registered it

    def __post_init__(self):
        object.__setattr__(self, "fields", MappingProxyType(dict(self.fields)))
        object.__setattr__(self, "_loaded", {})

    def __getitem__(self, name: str):
        loaded = self._loaded  # type: ignore[attr-defined]
        if name not in loaded:
            value = self.fields[name]
            loaded[name] = value.load() if isinstance(value, Lazy) else value
        return loaded[name]

    def get(self, name: str, default=None):
        return self[name] if name in self.fields else default

    @property
    def obj(self):
        """The object the record names (``fields["obj"]``)."""
        return self["obj"]

    @property
    def summary(self) -> str:
        """The description with its citation and, for a plugin's record, where it came from."""
        text = f"{self.description} ({self.citation})" if self.citation else self.description
        return text if self.plugin is None else f"{text} [plugin {self.plugin.path}]"

    @property
    def origin(self) -> str:
        return BUILTIN if self.plugin is None else self.plugin.path

    def sources(self) -> bytes:
        """What the record adds to a content hash: nothing for lutbake's own (the package's sources are hashed,
        lutbake.provenance), the plugin's path, name and source text for a plugin's."""
        if self.plugin is None:
            return b""
        return b"\0".join(x.encode() for x in (self.family, self.name, self.plugin.path, self.plugin.text))

    def provenance(self) -> dict[str, str]:
        """The record as an output's metadata names it (lutbake:plugins)."""
        out = {"family": self.family, "name": self.name, "origin": self.origin}
        if self.plugin is not None:
            out.update(sha256=self.plugin.sha256, line=str(self.line))
            mine = [
                v
                for v in self.fields.values()
                if getattr(getattr(v, "func", None), "__module__", 0) == self.plugin.module
            ]
            out["functions"] = ", ".join(v.key for v in mine)  # the plugin's own @wp.funcs (not lutbake's defaults)
        return out

    def __reduce__(self):
        # a Dask worker gets the record by (family, name), loading the plugin's shipped text first where needed
        return (_resolve, (self.family, self.name, self.plugin))

    def __repr__(self) -> str:
        return f"<{self.family} {self.name!r} from {self.origin}>"


class RegistryError(ValueError):
    """A record that cannot be added (a name taken by another origin) or a name no record has."""


class Family:
    """The records of one family by name and alias; ``lookup`` validates a name and suggests the nearest."""

    def __init__(self, name: str, doc: str):
        self.name, self.doc = name, doc
        self._records: dict[str, Record] = {}
        self._aliases: dict[str, str] = {}

    def add(self, record: Record) -> Record:
        """Register ``record``; a name or alias another origin holds is refused (a plugin cannot redefine lutbake's
        names or another plugin's); the same plugin file registering again replaces its own record."""
        for n in (record.name, *record.aliases):
            holder = self._records.get(self._aliases.get(n, n))
            if holder is not None and holder.origin != record.origin:
                raise RegistryError(
                    f"{self.name} {n!r} is already defined by {holder.origin}"
                    + (f" (line {holder.line})" if holder.line else "")
                    + ": choose another name"
                )
        old = self._records.get(record.name)
        if old is not None:
            for a in old.aliases:
                self._aliases.pop(a, None)
        self._records[record.name] = record
        self._aliases.update({a: record.name for a in record.aliases})
        return record

    def remove(self, record: Record) -> None:
        """Take ``record`` out (a plugin that failed after registering it: lutbake.plugins), if it is still held."""
        if self._records.get(record.name) is record:
            del self._records[record.name]
            for a in record.aliases:
                self._aliases.pop(a, None)

    def lookup(self, name: str) -> Record:
        key = self._aliases.get(name, name)
        if key not in self._records:
            raise RegistryError(
                f"unknown {self.name} {name!r}{did_you_mean(name, list(self._records) + list(self._aliases))}; "
                f"valid: {', '.join(self._records)}"
            )
        return self._records[key]

    def __contains__(self, name) -> bool:
        return isinstance(name, str) and self._aliases.get(name, name) in self._records

    def __iter__(self) -> Iterator[Record]:
        return iter(list(self._records.values()))

    def names(self) -> list[str]:
        return list(self._records)


FAMILIES: dict[str, Family] = {}


def family(name: str, doc: str = "") -> Family:
    """The family ``name``, created on first use."""
    if name not in FAMILIES:
        FAMILIES[name] = Family(name, doc)
    elif doc and not FAMILIES[name].doc:
        FAMILIES[name].doc = doc
    return FAMILIES[name]


def lookup(family_name: str, name: str) -> Record:
    return family(family_name).lookup(name)


class Choices(Mapping):
    """A live view name -> description of a family's records that pass ``where``: a Key's allowed values, which
    include the records a plugin registers after the key was declared. ``in`` accepts aliases too."""

    def __init__(self, family_name: str, where: Callable[[Record], bool] | None = None, doc: str = ""):
        self.family_name, self.where, self.doc = family_name, where, doc

    def records(self) -> list[Record]:
        return [r for r in family(self.family_name) if self.where is None or self.where(r)]

    def own(self) -> dict[str, str]:
        """name -> description of lutbake's own records only (what the documentation lists: a plugin's records
        are listed by ``lutbake list`` in the process that loaded them)."""
        return {r.name: r.summary for r in self.records() if r.plugin is None}

    def resolve(self, name: str) -> Record:
        record = family(self.family_name).lookup(name)
        if self.where is not None and not self.where(record):
            raise RegistryError(f"{self.why_not(name)}")
        return record

    def why_not(self, name) -> str | None:
        """Why a record of the family cannot be chosen here (``doc``), or None (a name no record has)."""
        if name in family(self.family_name) and name not in self:
            return f"{self.family_name} {name!r} cannot be used here: {self.doc}"
        return None

    def __getitem__(self, name):
        for r in self.records():
            if name == r.name or name in r.aliases:
                return r.summary
        raise KeyError(name)

    def __iter__(self):
        return iter([r.name for r in self.records()])

    def __len__(self) -> int:
        return len(self.records())

    def __contains__(self, name) -> bool:
        try:
            self[name]
        except KeyError:
            return False
        return True

    def __hash__(self) -> int:
        return hash((self.family_name, self.where))

    def __eq__(self, other) -> bool:
        return isinstance(other, Choices) and (self.family_name, self.where) == (other.family_name, other.where)


def choices(of: Family | str, where: Callable[[Record], bool] | None = None, doc: str = "") -> Choices:
    """The live choices of a family (or its name), the records passing ``where`` (``doc`` says why others fail)."""
    return Choices(of.name if isinstance(of, Family) else of, where, doc)


# the hook lutbake.plugins installs: (family, name, plugin) -> record, loading a shipped plugin text where needed
_PLUGIN_LOADER: list[Callable[[Plugin], None]] = []


def _resolve(family_name: str, name: str, plugin: Plugin | None) -> Record:
    """The record (family, name) in this process; a plugin's record is loaded from its shipped text when this
    process has not loaded that very text (a Dask worker)."""
    fam = family(family_name)
    if plugin is not None:
        held = fam._records.get(name)
        if held is None or held.plugin is None or held.plugin.sha256 != plugin.sha256:
            if not _PLUGIN_LOADER:
                importlib.import_module("lutbake.plugins")
            _PLUGIN_LOADER[0](plugin)
    elif family_name in ("kind", "layout") and name not in fam:
        importlib.import_module("lutbake.kinds")  # lutbake's kinds and layouts register on import
    elif name not in fam:
        importlib.import_module("lutbake.records")
        if name not in fam:  # a family a kind module declares (lutbake.kinds.environment: mip_curve, ...)
            importlib.import_module("lutbake.kinds")
    return fam.lookup(name)
