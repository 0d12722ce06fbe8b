"""Compute once, write many: tables of a batch that hold the same values share one computation.

Two specs hold the same values when they have the same kind and differ only in their *layout keys*: ``name`` and
the keys their kind declares (lutbake.kinds.base.Kind.layout_keys, e.g. ``format`` and ``dtype`` of the ``ltc``
kind, whose fit reads neither). The ``values_key`` names those values:

    values_key = sha256(kind, canonical TOML of the options without the layout keys, lutbake version,
                        source digest (lutbake.sources.sources_digest), the kind's inputs (Kind.inputs))

so it changes whenever anything that enters a table's values changes, and never with a file name or format.
The batch (lutbake.batch) runs one pipeline.compute per distinct key and lays the result out per table
(pipeline.assemble: each table keeps its own name, config, content hash and writer); the files are bit-identical
to baking each table alone (tests/test_sharing.py). Declaring a key that does steer the computation (a format
whose storage precision sets the tolerance, lutbake.tolerance) as a layout key would be a bug: the same tests
check, for every kind, that its plan's records do not depend on its layout keys.
"""

from __future__ import annotations

import hashlib

from . import __version__
from .config import TableSpec, kind_of
from .provenance import kind_inputs

ALWAYS_LAYOUT = ("name", "accept_over_tolerance")  # the output stem, the exit-status policy: never the values


def layout_keys(kind: str) -> tuple[str, ...]:
    """``name`` and the kind's declared layout keys; a kind baked whole (the environment cubes) keeps its name in its
    values (an irradiance cube's record names its SH file after it)."""
    found = kind_of(kind)
    always = ALWAYS_LAYOUT if found.bake is None else tuple(k for k in ALWAYS_LAYOUT if k != "name")
    return always + found.layout_keys


def values_toml(spec: TableSpec) -> str:
    """The canonical TOML of ``spec`` without its layout keys (kind included)."""
    skip = set(layout_keys(spec.kind))
    kept = sorted((k, v) for k, v in spec.options.items() if k not in skip and v is not None)
    # a list option is a tuple in a TableSpec: shown as the list it was, so the keys stay those of a list
    return f"kind = {spec.kind!r}\n" + "".join(f"{k} = {list(v) if isinstance(v, tuple) else v!r}\n" for k, v in kept)


def values_key(spec: TableSpec, digest: bytes) -> str:
    """The hex sha256 naming the values ``spec``'s table holds (module docstring); ``digest``:
    lutbake.sources.sources_digest()."""
    inputs = kind_inputs(spec)  # an environment file's sha256 (lutbake.kinds.base.Kind.inputs); b"" for most kinds
    h = hashlib.sha256()
    for part in (b"lutbake-values-key-v1", values_toml(spec).encode(), __version__.encode(), digest, inputs):
        if part:
            h.update(str(len(part)).encode() + b"\0" + part)
    return h.hexdigest()


def group_by(items: list, key) -> list[list]:
    """``items`` grouped by ``key(item)``, groups in order of their first item, items in order."""
    groups: dict = {}
    for item in items:
        groups.setdefault(key(item), []).append(item)
    return list(groups.values())
