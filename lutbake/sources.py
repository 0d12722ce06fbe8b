"""The source files that define what a table holds, and their digest: part of every content hash
(lutbake.provenance) and of the identity a cluster worker must share with its client (lutbake.runtime.worker).

``HASH_SOURCES``: terms, integrands, sampling, kinds, layouts, LTC fits, axes, edge policy, tolerances and the texel
plan record. ``ENVIRONMENT_SOURCES``: what else defines an environment kind's cube (the prefilter, the source reader,
the cube writers); only those kinds' content hashes cover them (lutbake.kinds.environment), so an edit there rebakes
no DFG table.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

PACKAGE = Path(__file__).parent
# the modules whose source defines what a table holds (kernels, terms, estimators, kinds, axes, edge policy)
HASH_SOURCES = (
    "terms/*.py",
    "integrands/*.py",
    "sampling/*.py",
    "kinds/*.py",
    "layouts/*.py",
    "ltc/*.py",
    "axes.py",
    "edge.py",
    "tolerance.py",
    "runtime/plan.py",  # TexelPlan: a table's shape
)
ENVIRONMENT_SOURCES = (
    "environment/*.py",
    "io/environment.py",
    "io/cubemap.py",
    "io/cube_read.py",
    "io/encodings.py",
    "io/ktx1.py",
)


def source_files(patterns: tuple[str, ...] = HASH_SOURCES) -> list[Path]:
    """The source files matching ``patterns`` (default: those that enter every content hash), sorted by their path
    in the package."""
    files = {f for pattern in patterns for f in PACKAGE.glob(pattern) if f.is_file()}
    return sorted(files, key=lambda f: f.relative_to(PACKAGE).as_posix())


def sources_digest(patterns: tuple[str, ...] = HASH_SOURCES) -> bytes:
    """sha256 over (relative path, text) of every file in source_files(patterns)."""
    h = hashlib.sha256()
    for f in source_files(patterns):
        data = f.read_bytes()
        h.update(f.relative_to(PACKAGE).as_posix().encode() + b"\0" + str(len(data)).encode() + b"\0" + data)
    return h.digest()
