"""Run a plan's tiles on Warp's CPU device from a pool of worker threads.

Warp's CPU launches run one kernel on one core and release the GIL (ctypes), so N threads keep N
cores busy. A tile is a fixed range of texels (independent of the worker count) and every texel is
computed alone, so the output is bit-identical for any number of workers.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .tables.base import Plan

TILE_TEXELS = 512
PROGRESS_MIN_EVALS = 1.5e7  # about a second of work on two busy cores: show a bar above it
_PREPARE_LOCK = threading.Lock()  # kernels compile/load one at a time when tables bake in parallel


class Cancelled(Exception):
    """Raised inside execute() when its ``cancel`` event is set: the remaining tiles are not run."""


def default_workers() -> int:
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1))


def tiles(n: int, size: int = TILE_TEXELS) -> list[tuple[int, int]]:
    return [(s, min(s + size, n)) for s in range(0, n, size)]


def execute(
    plan: Plan,
    workers: int | None = None,
    device: str = "cpu",
    progress: bool | None = None,
    label: str = "",
    cancel: threading.Event | None = None,
) -> np.ndarray:
    """Evaluate every tile of ``plan``; returns float64 data of shape plan.shape.

    ``cancel``: when set (by another thread), no further tile starts and Cancelled is raised."""
    import click

    workers = workers or default_workers()
    with _PREPARE_LOCK:
        plan.prepare(device)
    parts = tiles(plan.n_texels)
    out = np.empty((plan.n_texels, plan.n_channels), dtype=np.float64)
    if progress is None:
        progress = sys.stderr.isatty() and plan.cost > PROGRESS_MIN_EVALS

    def work(bounds):
        s, e = bounds
        if cancel is not None and cancel.is_set():
            raise Cancelled(label)
        out[s:e] = plan.run_tile(s, e, device)
        return e - s

    with click.progressbar(
        length=plan.n_texels, label=label, file=sys.stderr if progress else open(os.devnull, "w"), show_eta=True
    ) as bar:
        if workers == 1 or device != "cpu":
            for b in parts:
                bar.update(work(b))
        else:
            with ThreadPoolExecutor(max_workers=workers) as pool:
                for n in pool.map(work, parts):
                    bar.update(n)
    return out.reshape(plan.shape)


class Timer:
    def __enter__(self):
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.t0
