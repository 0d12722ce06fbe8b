"""The NumPy ``.npy`` format: the table's array (float32 / float16, its shape) with the conventions in a ``.json``
sidecar; written and read here (no pickles)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..table import Table
from ..table import pixels as checked_pixels
from . import bounded
from .atomic import atomic_write_hashed
from .conventions import write_conventions
from .sidecar import LoadedFile, as_table_array, with_sidecar

NPY_MAGIC = b"\x93NUMPY"


def write_npy(table: Table, path, dtype: str = "float32") -> Path:
    pixels = checked_pixels(table, dtype)
    path = Path(path)
    digest = atomic_write_hashed(path, lambda tmp: np.save(tmp, pixels, allow_pickle=False))
    extra = {"dtype": str(pixels.dtype), "shape": list(pixels.shape)}
    write_conventions(table, path, "npy", extra, digests={path.name: digest})
    return path


def read_npy(path: Path) -> LoadedFile:
    arr = bounded.load_npy(path)
    data = as_table_array(arr)
    return with_sidecar(LoadedFile(path, "npy", data, {}, None, {"dtype": str(arr.dtype), "shape": list(arr.shape)}))
