"""What a Dask worker process knows about itself (lutbake.runtime.cluster runs it there): Warp started quietly, the
identity that must equal the client's for bit-identical tiles, and ``worker_info`` for lutbake.runtime.cluster_probe.
Imports nothing of the cluster, so the probe and the cluster both import it."""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import threading

_WORKER_LOCK = threading.Lock()
_WARP_READY = False


@contextlib.contextmanager
def _stderr_to_devnull():
    """Silence file descriptor 2 (C code prints there, e.g. Warp's "CUDA driver not found" line)."""
    import sys

    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


def init_warp_quietly() -> None:
    """wp.init() once per process without the banner, the module-load lines or the no-CUDA-driver warning
    (worker processes share the client's terminal)."""
    global _WARP_READY
    if _WARP_READY:
        return
    with _WORKER_LOCK:
        if _WARP_READY:
            return
        import warp as wp

        wp.config.log_level = logging.WARNING
        with _stderr_to_devnull():
            wp.init()
        _WARP_READY = True


def identity() -> dict[str, str]:
    """What must be equal on client and worker for a tile to have the same bits: the lutbake version and
    kernel sources digest (both enter every content hash), and the Warp, numpy and scipy versions (code
    generation, texel grids, Sobol' points)."""
    import numpy
    import scipy
    import warp

    from .. import __version__
    from ..sources import sources_digest

    return {
        "lutbake": __version__,
        "kernel_sources": sources_digest().hex()[:16],
        "warp": warp.config.version,
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
    }


def identity_token(ident: dict[str, str]) -> str:
    return hashlib.sha256(json.dumps(ident, sort_keys=True).encode()).hexdigest()[:16]


def worker_info() -> dict:
    """identity() plus this process's CUDA devices and pid (called on a worker by lutbake.runtime.cluster_probe)."""
    from .devices import cuda_device_count, cuda_free_bytes

    init_warp_quietly()
    n = cuda_device_count()
    return {**identity(), "cuda_devices": n, "cuda_free_bytes": cuda_free_bytes() if n else 0, "pid": os.getpid()}
