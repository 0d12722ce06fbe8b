"""Hashing and provenance: what makes an output current, and the ``lutbake:*`` record every output carries.

- **Content hash.** Every output records ``lutbake:content_hash`` = sha256 of the table's canonical TOML
  (``TableSpec.toml()``), the lutbake version and the source text of the modules that define what a table holds
  (lutbake.sources: terms, integrands, sampling, kinds, layouts, axes, edge policy). An output with the same hash is
  up to date (lutbake.batch skips it); anything else (no file, unreadable file, other hash) is baked again.
- **Provenance.** ``attributes(spec, plan)``: terms, estimator, samples, seed, config text, versions, the plan's
  own records, the engine's image-based-lighting conventions (``ibl``) and the content hash, written as
  ``lutbake:*`` (EXR header or the JSON sidecar); ``cube_attributes`` the same for an environment cube.
- **Inputs.** A kind that reads files (the environment kinds) adds their digests to the content hash
  (lutbake.kinds.base.Kind.inputs): editing the file makes the output stale.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from . import __version__
from .config import TableSpec, kind_of
from .io.integrity import verified_attributes
from .layouts import engine_table
from .sources import sources_digest

HASH_ATTRIBUTE = "content_hash"


def content_hash(spec: TableSpec, digest: bytes | None = None, inputs: bytes | None = None) -> str:
    """The hex sha256 of (spec.toml(), lutbake version, source digest, the sources of the plugin records the spec
    uses: lutbake.registry.Record.sources, and what else its kind says its values depend on: Kind.inputs, an
    environment file's sha256): what makes an output current. ``inputs``: those bytes as a bake read them
    (lutbake.table.CubeTable.inputs); None: the kind's ``inputs(spec)`` now."""
    if inputs is None:
        inputs = kind_inputs(spec)
    h = hashlib.sha256()
    for part in (
        b"lutbake-content-hash-v1",
        spec.toml().encode(),
        __version__.encode(),
        digest if digest is not None else sources_digest(),
        *(r.sources() for r in spec.plugins),
        *([inputs] if inputs else []),  # none for the table kinds: their hashes are what they were
    ):
        h.update(str(len(part)).encode() + b"\0" + part)
    return h.hexdigest()


def kind_inputs(spec: TableSpec) -> bytes:
    """What ``spec``'s kind says its values depend on besides its config and lutbake's sources (Kind.inputs), b""
    for most kinds."""
    kind = kind_of(spec)
    return kind.inputs(spec) if kind.inputs is not None else b""


def read_header(path) -> dict[str, str] | None:
    """The ``lutbake:*`` attributes of an existing output (prefix removed), only if the output passes its
    integrity check (lutbake.io.integrity: the recorded sha256 of the stored bytes; for the non-EXR formats
    the ``<file>.json`` sidecar written last); None if missing, corrupt or half-written (not up to date)."""
    return verified_attributes(path)


def warp_version() -> str:
    import warp as wp

    return wp.config.version


def attributes(spec: TableSpec, plan, extra: dict[str, str] | None = None) -> dict[str, str]:
    """The provenance of a table baked from ``spec`` by ``plan`` (lutbake.runtime.plan.TexelPlan)."""
    return {
        "terms": json.dumps(plan.terms),
        "estimator": plan.estimator,
        "samples": str(plan.samples),
        "seed": str(spec.options.get("seed", 0)),
        **config_attributes(spec),
        **plan.extra,
        **(extra or {}),
        **({"plugins": json.dumps([r.provenance() for r in spec.plugins])} if spec.plugins else {}),
        **ibl_attributes(spec),
        HASH_ATTRIBUTE: content_hash(spec),  # what makes the file current
    }


def config_attributes(spec: TableSpec) -> dict[str, str]:
    """The config and versions every output records."""
    return {
        "config": spec.toml(),
        "config_file": Path(spec.source).name,
        "version": __version__,
        "warp_version": warp_version(),
    }


def ibl_attributes(spec: TableSpec) -> dict[str, str]:
    """``ibl``: the conventions an engine's image-based lighting shares between its DFG table and its environment
    cubes (lutbake.layouts.base.IBL), where ``spec``'s table is one of that engine's tables (EngineTable.ibl): the
    same record in every file of the run."""
    table = engine_table(spec.kind, spec.name, spec.options)
    return {"ibl": json.dumps(table.ibl.record(), sort_keys=True)} if table is not None and table.ibl else {}


def cube_attributes(spec: TableSpec, inputs: bytes) -> dict[str, str]:
    """The provenance of a cube table (lutbake.table.CubeTable) baked from ``spec`` with ``inputs`` (the bytes its
    bake read: its content hash names them)."""
    return {**config_attributes(spec), **ibl_attributes(spec), HASH_ATTRIBUTE: content_hash(spec, inputs=inputs)}
