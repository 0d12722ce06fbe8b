"""Table kinds: a registry with aliases and a validating lookup (``lutbake list`` prints it)."""

from __future__ import annotations

from .base import Kind
from .albedo import ALBEDO, ALBEDO_AVG
from .dfg import DFG
from .specular3d import SPECULAR_3D
from .diffuse import DIFFUSE
from .aniso import SPECULAR_ANISO
from .diffuse3d import DIFFUSE_3D
from .btf import BTF

KINDS: dict[str, Kind] = {
    k.name: k for k in (DFG, ALBEDO, ALBEDO_AVG, SPECULAR_3D, SPECULAR_ANISO, DIFFUSE, DIFFUSE_3D, BTF)
}
ALIASES: dict[str, str] = {alias: k.name for k in KINDS.values() for alias in k.aliases}


def lookup_kind(name: str) -> Kind:
    """The kind registered under ``name`` or one of its aliases; KeyError lists the valid names."""
    key = ALIASES.get(name, name)
    if key not in KINDS:
        raise KeyError(f"unknown table kind {name!r}; valid kinds: {', '.join(sorted(KINDS) + sorted(ALIASES))}")
    return KINDS[key]
