"""Table kinds: declarations, a registry with aliases and a validating lookup (``lutbake list`` prints it).

Every kind is one module here that declares its keys, axes, channels and reconstruction text and names its
integrand (lutbake.integrands) and estimator (lutbake.sampling); ``base.declare`` adds the keys every kind has
(name, kind, format, dtype, seed, samples, estimator). The texel cap is config.MAX_TEXELS, for every kind.
"""

from __future__ import annotations

from ..registry import Record, RegistryError, family
from .albedo import ALBEDO, ALBEDO_AVG
from .base import Key, Kind
from .btf import BTF
from .dfg import DFG
from .dielectric import DIELECTRIC, DIELECTRIC_AVG
from .diffuse import DIFFUSE
from .diffuse_3d import DIFFUSE_3D
from .ltc import LTC
from .specular_3d import SPECULAR_3D
from .specular_aniso import SPECULAR_ANISO

KINDS: dict[str, Kind] = {
    k.name: k
    for k in (
        DFG,
        ALBEDO,
        ALBEDO_AVG,
        SPECULAR_3D,
        SPECULAR_ANISO,
        DIFFUSE,
        DIFFUSE_3D,
        BTF,
        DIELECTRIC,
        DIELECTRIC_AVG,
        LTC,
    )
}
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
