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

from .devices import CPU_TILE_TEXELS as TILE_TEXELS
from .devices import plan_tile_texels
from .plan import PlanSource, TexelPlan
from .warp_runtime import defining

# progress(label, n_texels, cost) -> update(n_done_in_this_tile) or None: called once per table before its tiles run
Progress = Callable[[str, int, float], "Callable[[int], None] | None"]


class Cancelled(Exception):
    """Raised inside execute() when its ``cancel`` event is set: the remaining tiles are not run."""


def default_workers() -> int:
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1))


def tiles(n: int, size: int = TILE_TEXELS) -> list[tuple[int, int]]:
    return [(s, min(s + size, n)) for s in range(0, n, size)]


def execute(plan: TexelPlan, **options) -> np.ndarray:
    """Evaluate every tile of ``plan``; returns float64 data of shape plan.shape: execute_tiles (same keyword
    options) without the tiles' aux columns."""
    return execute_tiles(plan, **options)[:, : plan.n_channels].reshape(plan.shape)


def execute_tiles(
    plan: TexelPlan,
    workers: int | None = None,
    device: str = "cpu",
    progress: Progress | None = None,
    label: str = "",
    cancel: threading.Event | None = None,
    source: PlanSource | None = None,
    cpu: list[float] | None = None,
    runner=None,
) -> np.ndarray:
    """Evaluate every tile of ``plan``; returns float64 (n_texels, plan.tile_width): the values, then the aux
    columns (lutbake.runtime.plan.TexelPlan.aux_channels).

    ``progress``: a ``Progress`` factory; its update is called in the calling thread after each tile.
    ``cancel``: when set (by another thread), no further tile starts and Cancelled is raised.
    ``source``: how another process builds ``plan`` (lutbake.runtime.plan.PlanSource); with a ``runner``
    (lutbake.runtime.cluster.DaskRunner, or any object with its ``execute`` and ``estimate_error``) the tiles run there
    instead, as tasks of (source, tile range). Tiles
    are TILE_TEXELS on the CPU, device-sized on CUDA (lutbake.runtime.devices). ``cpu``: a list that receives the
    CPU seconds of the kernels' preparation and of each tile, each measured in the thread that ran it
    (time.thread_time; not for tiles run on a cluster)."""
    if runner is not None and source is not None:
        return runner.execute(source, plan, device, progress=progress, label=label, cancel=cancel)
    workers = workers or default_workers()
    cpu = cpu if cpu is not None else []
    # tables prepare in parallel: one builds its Warp kernels at a time (warp_runtime.defining), their modules
    # compile on every core (warp_runtime.load_module)
    t0 = time.thread_time()
    with defining():
        plan.prepare(device)
    cpu.append(time.thread_time() - t0)
    parts = tiles(plan.n_texels, plan_tile_texels(plan, device))
    out = np.empty((plan.n_texels, plan.tile_width), dtype=np.float64)
    update = progress(label, plan.n_texels, plan.cost) if progress is not None else None

    def work(bounds):
        s, e = bounds
        if cancel is not None and cancel.is_set():
            raise Cancelled(label)
        t0 = time.thread_time()
        out[s:e] = plan.run_tile(s, e, device)
        cpu.append(time.thread_time() - t0)
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
    return out


def estimate_error(
    plan: TexelPlan, data: np.ndarray, device: str = "cpu", source: PlanSource | None = None, runner=None
) -> tuple | None:
    """``plan.error_estimate`` of baked ``data`` (flat float64, (n_texels, tile_width)): (error, method[, where texels
    end over the tolerance]), None if the kind has none; with a ``runner`` (see execute_tiles) it runs on a worker, as
    the tiles did."""
    if plan.error_estimate is None:
        return None
    if runner is not None and source is not None:
        return runner.estimate_error(source, data, device)
    with defining():  # the refined estimator builds its kernels here
        return plan.error_estimate(data, device)


class Timer:
    def __enter__(self):
        self.t0 = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self.t0
