"""Hashing and provenance: what makes an output current, and the ``lutbake:*`` record every output carries.

- **Content hash.** Every output records ``lutbake:content_hash`` = sha256 of the table's canonical TOML
  (``TableSpec.toml()``), the lutbake version and the source text of the modules that define what a table holds
  (lutbake.sources: terms, integrands, sampling, kinds, layouts, axes, edge policy). An output with the same hash is
  up to date (lutbake.batch skips it); anything else (no file, unreadable file, other hash) is baked again.
- **Provenance.** ``attributes(spec, plan)``: terms, estimator, samples, seed, config text, versions, the plan's
  own records and the content hash, written as ``lutbake:*`` (EXR header or the JSON sidecar).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from . import __version__
from .config import TableSpec
from .io.integrity import verified_attributes
from .sources import sources_digest

HASH_ATTRIBUTE = "content_hash"


def content_hash(spec: TableSpec, digest: bytes | None = None) -> str:
    """The hex sha256 of (spec.toml(), lutbake version, source digest, the sources of the plugin records the spec
    uses: lutbake.registry.Record.sources): what makes an output current."""
    h = hashlib.sha256()
    for part in (
        b"lutbake-content-hash-v1",
        spec.toml().encode(),
        __version__.encode(),
        digest if digest is not None else sources_digest(),
        *(r.sources() for r in spec.plugins),
    ):
        h.update(str(len(part)).encode() + b"\0" + part)
    return h.hexdigest()


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
        "config": spec.toml(),
        "config_file": Path(spec.source).name,
        "version": __version__,
        "warp_version": warp_version(),
        **plan.extra,
        **(extra or {}),
        **({"plugins": json.dumps([r.provenance() for r in spec.plugins])} if spec.plugins else {}),
        HASH_ATTRIBUTE: content_hash(spec),  # what makes the file current
    }
