"""A content-addressed cache of computed table values: ``lutbake bake --cache DIR`` (``make luts``: <out>/.cache).

An entry holds what one computation made (lutbake.pipeline.Computed): the float64 values in the plan's shape and
the attributes known only after the bake (error estimate, fit statistics), under the computation's values key
(lutbake.sharing.values_key, which covers the options that determine the values, the lutbake version and the
kernels' source):

    DIR/<values_key>.npy    the values, float64
    DIR/<values_key>.json   {"values_key", "sources", "shape", "bytes" and "sha256" of the .npy, "extra",
                            "entry_sha256"}: written last

Both writes are atomic (lutbake.io.atomic) and the JSON names the sha256 of the data it describes (as the outputs'
sidecars, lutbake.io.integrity), so an entry is used only whole: its JSON parses and names this key, and the
.npy bytes match its sha256 and shape; anything else is a miss (the table is computed, the entry rewritten).
A later run thus lays out again, without computing, a table whose values are known: an output deleted or written
in another format or dtype (``ltc``, ``dielectric``: layout keys). Entries made by other sources can never be hit
again and are removed at the start of a run (``prune``). ``--force`` recomputes (reads no entry, writes them).

Nothing in the directory is believed blindly (issue 38): ``entry_sha256`` covers everything the output will carry
from the entry (key, sources, shape, the data's sha256 and ``extra``), so an edited ``error_estimate`` is a miss;
``extra`` holds only the attributes a bake records after computing (valid_extra: the error estimate, checked as a
number; the plan's ``attributes_after``, recomputed from the values and compared); the .npy is opened only as a
regular file, not through a symlink, never blocking on a FIFO, and only with the size its JSON declares; the JSON is
size- and depth-bounded. Anything else is a miss.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import stat
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .io import bounded
from .io.atomic import atomic_write_bytes, atomic_write_hashed, remove_stale_temps
from .io.integrity import sha256_bytes
from .limits import MAX_EXTRA_CHARS

FORMAT = "lutbake-values-cache-v2"  # v2: "bytes" and "entry_sha256" (v1 entries are misses, then rewritten)
# what lutbake.pipeline.compute records besides
ESTIMATE_KEYS = ("error_estimate", "error_estimate_method", "over_tolerance")


def entry_digest(meta: dict) -> str:
    """sha256 of what an entry says about its values (every field but ``written`` and the digest itself)."""
    covered = {k: meta.get(k) for k in ("format", "values_key", "sources", "shape", "bytes", "sha256", "extra")}
    return hashlib.sha256(json.dumps(covered, sort_keys=True, ensure_ascii=True).encode("ascii")).hexdigest()


def valid_extra(extra: dict[str, str], recomputed: dict[str, str]) -> bool:
    """``extra`` of an entry may be laid out: only the error estimate (a finite number >= 0 and its method) and
    the attributes computed from the values, which must equal ``recomputed`` (plan.attributes_after of the data)."""
    if set(extra) - set(ESTIMATE_KEYS) != set(recomputed) or any(extra[k] != str(v) for k, v in recomputed.items()):
        return False
    if "error_estimate" in extra:
        try:
            value = float(extra["error_estimate"])
        except ValueError:
            return False
        if not math.isfinite(value) or value < 0 or f"{value:.3e}" != extra["error_estimate"]:
            return False
    return True


def _read_entry_data(path: Path, size: int) -> bytes | None:
    """The bytes of the regular file ``path`` if it holds exactly ``size`` bytes, else None: no symlink is followed,
    a FIFO never blocks the open (O_NONBLOCK), a device or /dev/zero is never read."""
    flags = os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
    try:
        fd = os.open(path, flags)
    except OSError:
        return None
    with os.fdopen(fd, "rb") as f:
        st = os.fstat(f.fileno())
        if not stat.S_ISREG(st.st_mode) or st.st_size != size:
            return None
        blob = f.read(size + 1)
    return blob if len(blob) == size else None


@dataclass(frozen=True)
class ValuesCache:
    """The cache at ``directory``; ``read``: entries may be used (False under --force: computed again, written)."""

    directory: Path
    sources: str  # hex of lutbake.sources.sources_digest(): what made the entries this run can use
    read: bool = True

    def paths(self, key: str) -> tuple[Path, Path]:
        return self.directory / f"{key}.npy", self.directory / f"{key}.json"

    def load(self, key: str) -> tuple[np.ndarray, dict[str, str]] | None:
        """(values, extra attributes) of entry ``key``, or None when it is missing, partial, corrupt, edited, or not
        regular files of the sizes its JSON declares (module docstring). The caller checks ``extra`` against the
        values (valid_extra)."""
        if not self.read:
            return None
        data_path, meta_path = self.paths(key)
        if bounded.regular_file_problem(meta_path, follow=False):
            return None
        try:
            meta = bounded.load_json(meta_path)
        except (OSError, ValueError, UnicodeDecodeError):
            return None
        if not isinstance(meta, dict) or meta.get("entry_sha256") != entry_digest(meta):
            return None
        size, shape, extra = meta.get("bytes"), meta.get("shape"), meta.get("extra")
        if not (isinstance(size, int) and 0 < size <= bounded.MAX_READ_BYTES and isinstance(extra, dict)):
            return None
        if not all(isinstance(k, str) and isinstance(v, str) and len(v) <= MAX_EXTRA_CHARS for k, v in extra.items()):
            return None
        if (meta.get("format"), meta.get("values_key")) != (FORMAT, key):
            return None
        blob = _read_entry_data(data_path, size)
        if blob is None or meta.get("sha256") != sha256_bytes(blob):
            return None
        try:
            data = np.load(io.BytesIO(blob), allow_pickle=False)
        except (OSError, ValueError, EOFError):
            return None
        if data.dtype != np.float64 or list(data.shape) != shape or not np.all(np.isfinite(data)):
            return None
        return data, dict(extra)

    def store(self, key: str, data: np.ndarray, extra: dict[str, str]) -> None:
        """Write entry ``key`` (the .npy, then the JSON naming its sha256), both atomically."""
        data_path, meta_path = self.paths(key)
        data = np.ascontiguousarray(data, dtype=np.float64)
        size: list[int] = []

        def write(tmp: Path) -> None:
            np.save(tmp, data, allow_pickle=False)
            size.append(os.path.getsize(tmp))

        # the size and sha256 of the bytes this run wrote, not of the file after the rename (another run may have
        # replaced it in between): from its own temporary file (lutbake.io.atomic.atomic_write_hashed)
        digest = atomic_write_hashed(data_path, write)
        meta = {
            "format": FORMAT,
            "values_key": key,
            "sources": self.sources,
            "shape": list(data.shape),
            "bytes": size[0],
            "sha256": digest,
            "extra": {str(k): str(v) for k, v in extra.items()},
            "written": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        }
        meta["entry_sha256"] = entry_digest(meta)
        atomic_write_bytes(meta_path, (json.dumps(meta, indent=1) + "\n").encode("utf-8"))

    def prune(self) -> list[Path]:
        """Remove the entries of other sources (never hit again) and temporary files of killed writers; entries
        of these sources, and anything the cache did not write, stay. Returns the removed paths."""
        removed = remove_stale_temps(self.directory) if self.directory.is_dir() else []
        for meta_path in sorted(self.directory.glob("*.json")):
            if bounded.regular_file_problem(meta_path, follow=False):
                continue  # a FIFO, a symlink, a directory: not an entry this cache wrote
            try:
                meta = bounded.load_json(meta_path)  # size- and depth-bounded: a hostile file is skipped
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
    from .sources import sources_digest

    return ValuesCache(Path(directory), sources_digest().hex(), read=not force)
