"""The source files that define what a table holds, and their digest: part of every content hash
(lutbake.provenance) and of the identity a cluster worker must share with its client (lutbake.runtime.worker).

``HASH_SOURCES``: terms, integrands, sampling, kinds, layouts, LTC fits, axes, edge policy, tolerances and the texel
plan record.
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


def source_files() -> list[Path]:
    """The source files that enter every content hash, sorted by their path in the package."""
    files = {f for pattern in HASH_SOURCES for f in PACKAGE.glob(pattern) if f.is_file()}
    return sorted(files, key=lambda f: f.relative_to(PACKAGE).as_posix())


def sources_digest() -> bytes:
    """sha256 over (relative path, text) of every file in source_files()."""
    h = hashlib.sha256()
    for f in source_files():
        data = f.read_bytes()
        h.update(f.relative_to(PACKAGE).as_posix().encode() + b"\0" + str(len(data)).encode() + b"\0" + data)
    return h.digest()
