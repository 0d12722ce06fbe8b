"""Run a texel plan's tiles on Warp's CPU device from a pool of worker threads.

Warp's CPU launches run one kernel on one core and release the GIL (ctypes), so N threads keep N
cores busy. A tile is a fixed range of texels (independent of the worker count) and every texel is
computed alone, so the output is bit-identical for any number of workers. Progress is reported through a
callback (``Progress``); the command line draws it as a bar (lutbake.cli), the API draws nothing.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .sampling.plan import TexelPlan

TILE_TEXELS = 512
# progress(label, n_texels, cost) -> update(n_done_in_this_tile) or None: called once per table before its tiles run
Progress = Callable[[str, int, float], "Callable[[int], None] | None"]
_PREPARE_LOCK = threading.Lock()  # kernels compile/load one at a time when tables bake in parallel


class Cancelled(Exception):
    """Raised inside execute() when its ``cancel`` event is set: the remaining tiles are not run."""


def default_workers() -> int:
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1))


def tiles(n: int, size: int = TILE_TEXELS) -> list[tuple[int, int]]:
    return [(s, min(s + size, n)) for s in range(0, n, size)]


def execute(
    plan: TexelPlan,
    workers: int | None = None,
    device: str = "cpu",
    progress: Progress | None = None,
    label: str = "",
    cancel: threading.Event | None = None,
) -> np.ndarray:
    """Evaluate every tile of ``plan``; returns float64 data of shape plan.shape.

    ``progress``: a ``Progress`` factory; its update is called in the calling thread after each tile.
    ``cancel``: when set (by another thread), no further tile starts and Cancelled is raised."""
    workers = workers or default_workers()
    with _PREPARE_LOCK:
        plan.prepare(device)
    parts = tiles(plan.n_texels)
    out = np.empty((plan.n_texels, plan.n_channels), dtype=np.float64)
    update = progress(label, plan.n_texels, plan.cost) if progress is not None else None

    def work(bounds):
        s, e = bounds
        if cancel is not None and cancel.is_set():
            raise Cancelled(label)
        out[s:e] = plan.run_tile(s, e, device)
        return e - s

    if workers == 1 or device != "cpu":
        done = map(work, parts)
    else:
        pool = ThreadPoolExecutor(max_workers=workers)
        done = pool.map(work, parts)
    try:
        for n in done:
            if update is not None:
                update(n)
    finally:
        if not (workers == 1 or device != "cpu"):
            pool.shutdown(wait=True)
    return out.reshape(plan.shape)


class Timer:
    def __enter__(self):
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.t0
