"""A thread-safe memo of per-texel results: one computation per key, shared by the threads of a process.

Used where a texel's result is a pure function of its key and several tiles or tables ask for it: the LTC fits of
tables that share texels (lutbake.ltc.fit.MEMO) and kind dielectric_avg's averages, which OpenPBR's tiles also need
for their mirror rows (lutbake.kinds.dielectric). A key another thread is computing is waited for, not computed
again, so two workers never duplicate a texel, and the stored bits are the computing thread's: the results do not
depend on which thread computes them, nor on the worker count.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np


class RowMemo:
    """Rows per key: ``run(keys, compute)`` returns, for each part of compute's tuple, the rows of every key stacked
    in key order; ``compute(indices)`` -> a tuple of arrays, each with one row per index (into ``keys``), is called for
    the keys no thread has. Least recently stored entries are dropped beyond ``capacity``."""

    def __init__(self, capacity: int = 1 << 16):
        self.capacity = capacity
        self._lock = threading.Lock()
        self._done: OrderedDict[bytes, tuple] = OrderedDict()
        self._pending: dict[bytes, threading.Event] = {}
        self.hits = 0
        self.misses = 0

    def clear(self) -> None:
        with self._lock:
            self._done.clear()
            self.hits = self.misses = 0

    def run(self, keys: list[bytes], compute) -> tuple[np.ndarray, ...]:
        """The rows of every key: stored ones, ``compute(indices)`` for those no thread has, waiting for those another
        thread is computing (computed here if that thread failed)."""
        rows: list[tuple | None] = [None] * len(keys)
        todo = list(range(len(keys)))
        while todo:
            mine, theirs = [], {}
            claim = threading.Event()  # one event for every key this pass claims: set once their rows are stored
            with self._lock:
                for i in todo:
                    k = keys[i]
                    if k in self._done:
                        rows[i] = self._done[k]
                        self.hits += 1
                    elif k in self._pending:  # another thread's, or a repeat of a key claimed here: waited for
                        theirs[i] = self._pending[k]
                    else:
                        self._pending[k] = claim
                        mine.append(i)
            if mine:
                self._compute(keys, mine, claim, compute, rows)
            for event in {id(e): e for e in theirs.values() if e is not claim}.values():
                event.wait()
            todo = list(theirs)  # now stored (or released by a failed thread: claimed again)
        return tuple(np.stack([r[p] for r in rows]) for p in range(len(rows[0]))) if rows else ()

    def _compute(self, keys, mine, claim, compute, rows) -> None:
        try:
            parts = compute(np.array(mine))
        except BaseException:
            self._release(keys, mine, claim)
            raise
        # each stored row a view of its own copy of the parts (one copy per part, not one per row)
        parts = [np.array(p, copy=True) for p in parts]
        with self._lock:
            for j, i in enumerate(mine):
                rows[i] = tuple(p[j] for p in parts)
                self._done[keys[i]] = rows[i]
            self.misses += len(mine)
            while len(self._done) > self.capacity:
                self._done.popitem(last=False)
        self._release(keys, mine, claim)

    def _release(self, keys, mine, claim) -> None:
        with self._lock:
            for i in mine:
                del self._pending[keys[i]]
        claim.set()
