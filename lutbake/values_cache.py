"""A content-addressed cache of computed table values: ``lutbake bake --cache DIR`` (``make luts``: <out>/.cache).

An entry holds what one computation made (lutbake.pipeline.Computed): the float64 values in the plan's shape and
the attributes known only after the bake (error estimate, fit statistics), under the computation's values key
(lutbake.sharing.values_key, which covers the options that determine the values, the lutbake version and the
kernels' source):

    DIR/<values_key>.npy    the values, float64
    DIR/<values_key>.json   {"values_key", "sources", "shape", "sha256" of the .npy bytes, "extra"}: written last

Both writes are atomic (lutbake.io.atomic) and the JSON names the sha256 of the data it describes (as the outputs'
sidecars, lutbake.io.integrity), so an entry is used only whole: its JSON parses and names this key, and the
.npy bytes match its sha256 and shape; anything else is a miss (the table is computed, the entry rewritten).
A later run thus lays out again, without computing, a table whose values are known: an output deleted or written
in another format or dtype (``ltc``, ``dielectric``: layout keys). Entries made by other sources can never be hit
again and are removed at the start of a run (``prune``). ``--force`` recomputes (reads no entry, writes them).
"""

from __future__ import annotations

import io
import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .io.atomic import atomic_write, atomic_write_bytes, remove_stale_temps
from .io.integrity import sha256_bytes

FORMAT = "lutbake-values-cache-v1"


@dataclass(frozen=True)
class ValuesCache:
    """The cache at ``directory``; ``read``: entries may be used (False under --force: computed again, written)."""

    directory: Path
    sources: str  # hex of lutbake.provenance.sources_digest(): what made the entries this run can use
    read: bool = True

    def paths(self, key: str) -> tuple[Path, Path]:
        return self.directory / f"{key}.npy", self.directory / f"{key}.json"

    def load(self, key: str) -> tuple[np.ndarray, dict[str, str]] | None:
        """(values, extra attributes) of entry ``key``, or None when it is missing, partial or corrupt."""
        if not self.read:
            return None
        data_path, meta_path = self.paths(key)
        try:
            meta = json.loads(meta_path.read_text(encoding="utf-8"))
            blob = data_path.read_bytes()
            if (meta.get("format"), meta.get("values_key"), meta.get("sha256")) != (FORMAT, key, sha256_bytes(blob)):
                return None
            data = np.load(io.BytesIO(blob), allow_pickle=False)
        except (OSError, ValueError, UnicodeDecodeError, AttributeError):  # AttributeError: JSON not an object
            return None
        if data.dtype != np.float64 or list(data.shape) != meta.get("shape") or not np.all(np.isfinite(data)):
            return None
        return data, {str(k): str(v) for k, v in meta.get("extra", {}).items()}

    def store(self, key: str, data: np.ndarray, extra: dict[str, str]) -> None:
        """Write entry ``key`` (the .npy, then the JSON naming its sha256), both atomically."""
        data_path, meta_path = self.paths(key)
        data = np.ascontiguousarray(data, dtype=np.float64)
        atomic_write(data_path, lambda tmp: np.save(tmp, data, allow_pickle=False))
        meta = {
            "format": FORMAT,
            "values_key": key,
            "sources": self.sources,
            "shape": list(data.shape),
            "sha256": sha256_bytes(data_path.read_bytes()),
            "extra": dict(extra),
            "written": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        }
        atomic_write_bytes(meta_path, (json.dumps(meta, indent=1) + "\n").encode("utf-8"))

    def prune(self) -> list[Path]:
        """Remove the entries of other sources (never hit again) and temporary files of killed writers; entries
        of these sources, and anything the cache did not write, stay. Returns the removed paths."""
        removed = remove_stale_temps(self.directory) if self.directory.is_dir() else []
        for meta_path in sorted(self.directory.glob("*.json")):
            try:
                meta = json.loads(meta_path.read_text(encoding="utf-8"))
            except (OSError, ValueError, UnicodeDecodeError):
                continue
            if not isinstance(meta, dict) or meta.get("format") != FORMAT or meta.get("values_key") != meta_path.stem:
                continue  # not an entry this cache wrote
            if meta.get("sources") != self.sources:
                for p in self.paths(meta_path.stem)[::-1]:  # the JSON first: never a JSON without its data
                    if p.is_file():
                        p.unlink(missing_ok=True)
                        removed.append(p)
        return removed


def open_cache(directory, force: bool = False) -> ValuesCache | None:
    """The cache at ``directory`` for this lutbake's sources (None without a directory); ``force``: write only."""
    if directory is None:
        return None
    from .provenance import sources_digest

    return ValuesCache(Path(directory), sources_digest().hex(), read=not force)
