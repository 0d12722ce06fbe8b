"""Warp, started quietly. Warp prints a banner and one line per module load (at its INFO log level), and
its native library prints "Warp CUDA warning: Could not find or load the NVIDIA CUDA driver" to the
process' stderr on every machine without a GPU. lutbake's commands and its Python API print their own
lines only, unless asked: ``LUTBAKE_VERBOSE=1`` in the environment (``lutbake --verbose ...``) keeps
everything Warp says.
"""

from __future__ import annotations

import contextlib
import functools
import logging
import os
import sys
import threading

VERBOSE_ENV = "LUTBAKE_VERBOSE"
_LOCK = threading.Lock()
_started = False


def verbose() -> bool:
    """True when LUTBAKE_VERBOSE is set to anything but '', 0, false, no, off."""
    return os.environ.get(VERBOSE_ENV, "").strip().lower() not in ("", "0", "false", "no", "off")


@contextlib.contextmanager
def stderr_silenced():
    """Point file descriptor 2 at /dev/null (native code writes there, not to sys.stderr)."""
    try:
        sys.stderr.flush()
    except (AttributeError, ValueError):
        pass
    saved = os.dup(2)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def init_warp():
    """Import and initialise Warp once per process, quietly unless ``verbose()``; returns the module.
    ``lutbake.terms`` calls it on import: every lutbake kernel is built from its terms, so Warp is started
    (and its log level set) before any lutbake kernel loads, from the CLI and the Python API alike."""
    global _started
    import warp as wp

    loud = verbose()
    wp.config.log_level = logging.INFO if loud else logging.WARNING
    with _LOCK:
        if not _started:
            if loud:
                wp.init()
            else:
                with stderr_silenced():
                    wp.init()
            _started = True
    return wp


# one lock per (Warp module, device): load_module's
_MODULE_LOCKS: dict = {}


def parallel_loads(wp=None) -> bool:
    """Whether this Warp compiles different modules in parallel threads: its own parallel loader
    (``warp.force_load(max_workers=...)``, configured by ``warp.config.load_module_max_workers``) runs the Python
    codegen under Warp's codegen lock and the native compile unlocked. Older releases load one module at a time."""
    wp = wp or init_warp()
    return hasattr(wp.config, "load_module_max_workers")


class ModuleBusy(Exception):
    """Raised by the first load_module of a thread inside ``defer_if_busy()`` when another thread is loading
    (compiling) that module: the caller may do other work first instead of waiting."""


_DEFER = threading.local()


@contextlib.contextmanager
def defer_if_busy():
    """Within it, this thread's first load_module raises ModuleBusy, instead of waiting, if another thread is loading
    that module (later loads wait). lutbake.batch starts a table under it: two tables that need one kernel module
    and start together (filament's two presets, the four metals) would leave a core idle while one of them compiles
    it (~1-3 s on a new machine, the first compile of a thread building Warp's precompiled header); the second table
    is set back behind the next one, whose module compiles meanwhile."""
    _DEFER.armed = True
    try:
        yield
    finally:
        _DEFER.armed = False


_DEFINE = threading.Lock()
_DEFINING = threading.local()


@contextlib.contextmanager
def defining():
    """Hold while a thread builds Warp functions and kernels (a table's ``prepare``): Warp's registries of functions
    and modules are not thread-safe, and two tables building kernels at once could launch each other's variant
    (two dfg tables differing only in masking baked identical on an empty kernel cache). load_module releases it
    while it compiles, so modules still compile on every core."""
    if getattr(_DEFINING, "held", False):
        yield
        return
    with _DEFINE:
        _DEFINING.held = True
        try:
            yield
        finally:
            _DEFINING.held = False


_FACTORY = threading.RLock()


def kernel_factory(build):
    """functools.cache for a function that builds Warp functions or kernels (a kernel factory), safe across threads:
    one thread builds at a time and a second caller of the same arguments gets the first one's objects. Worker threads
    of one table call factories too (lutbake.ltc.aniso's tiles); two of them missing functools' cache at once both
    defined the kernels, adding to a module while the other loaded it (Warp: ``KeyError`` in Module.load)."""
    cached = functools.lru_cache(maxsize=None)(build)

    @functools.wraps(build)
    def built(*args, **kwargs):
        with _FACTORY:
            return cached(*args, **kwargs)

    return built


def load_module(module, device: str = "cpu") -> None:
    """Compile (or load from Warp's kernel cache) a Warp module on ``device`` before worker threads launch its
    kernels. Tables prepare in parallel (lutbake.batch runs two at once on two cores): on a cold kernel cache their
    modules compile on both cores (parallel_loads), one thread per module, so a module two tables need compiles once
    (a table that finds its first module busy may step back: ``defer_if_busy``). A Warp without parallel loading
    compiles one module at a time, whichever table asks."""
    wp = init_warp()
    key = (module, str(device)) if parallel_loads(wp) else None
    with _LOCK:
        lock = _MODULE_LOCKS.setdefault(key, threading.Lock())
    armed = getattr(_DEFER, "armed", False)
    _DEFER.armed = False
    held = getattr(_DEFINING, "held", False)
    if held:  # other threads build kernels while this one compiles or waits for another's compile
        _DEFINING.held = False
        _DEFINE.release()
    try:
        if not lock.acquire(blocking=not armed):
            raise ModuleBusy(getattr(module, "name", str(module)))
        try:
            wp.load_module(module, device=device)
        finally:
            lock.release()
    finally:
        if held:
            _DEFINE.acquire()
            _DEFINING.held = True


# LLVM's inlining budget for lutbake's CPU kernels. Warp's default flags (warp.config.cpu_compiler_flags) raise LLVM's
# inline threshold to 9000 and its cold-call-site threshold to 3000; lutbake's kernels inline whole integrands and
# quadrature ladders into each launch, and at Warp's budget a new machine spends 68 s of CPU compiling the 36 modules
# of `make luts`. At 1000 / 300 it spends 50 s, every table of `make luts` is byte-identical and the kernels run as
# fast (docs/decisions.md, "Compiling Warp kernels"); at LLVM's own defaults (225) the glass and
# average kernels run 1.6-1.7x slower. The flags are part of each module's hash in Warp's kernel cache.
CPU_COMPILER_FLAGS = (
    "-march=native -mllvm=-inline-threshold=1000 -mllvm=-inline-cold-callsite-threshold=300"
    " -mllvm=-slp-recursion-max-depth=4"
)
# the options of every lutbake Warp module: forward code only (no kernel is differentiated), CPU_COMPILER_FLAGS
MODULE_OPTIONS = {"enable_backward": False, "cpu_compiler_flags": CPU_COMPILER_FLAGS}


def unique_kernel(f):
    """``wp.kernel`` for a kernel factory's kernels: a Warp module of its own per variant (``module="unique"``: a
    factory's variants differ in the functions they close over), built with MODULE_OPTIONS. Modules holding several
    fixed kernels set MODULE_OPTIONS with ``wp.set_module_options`` instead."""
    return init_warp().kernel(f, enable_backward=False, module="unique", module_options=MODULE_OPTIONS)
