"""The record of one analytic check (lutbake.validate.checks, lutbake.validate.dielectric), its result and the closing
total."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CheckResult:
    """``measured`` is the one number compared with ``tolerance``; ``detail`` says what it is, then (after
    "; ") where it is worst; ``notes`` are secondary figures, each labelled, never compared."""

    name: str
    measured: float
    tolerance: float
    passed: bool
    detail: str
    notes: tuple[str, ...] = ()

    @property
    def what(self) -> str:
        """What ``measured`` is (the first clause of ``detail``)."""
        return self.detail.split("; ")[0]

    @property
    def secondary(self) -> list[str]:
        """Every other figure: the rest of ``detail`` (where the worst case is), then ``notes``."""
        return self.detail.split("; ")[1:] + list(self.notes)

    def lines(self) -> list[str]:
        """The report: status and name, then one labelled line per number."""
        return [
            f"{'PASS' if self.passed else 'FAIL'}  {self.name}",
            f"      measured   {self.measured:.3e}   = {self.what}",
            f"      tolerance  {self.tolerance:.1e}   (pass: measured <= tolerance)",
        ] + [f"      {text}" for text in self.secondary]

    def __str__(self) -> str:
        return "\n".join(self.lines())


@dataclass(frozen=True)
class Check:
    """One entry of the checks' table (lutbake.validate.checks.TABLE): its name (parameters in brackets:
    ``weak_white_furnace[ggx]``) and the zero-argument callable that measures it."""

    name: str
    run: Callable[[], CheckResult]


def check_result(name: str, measured: float, tolerance: float, detail: str, notes: tuple[str, ...] = ()) -> CheckResult:
    """A CheckResult that passes when ``measured`` is finite and <= ``tolerance``."""
    measured = float(measured)
    return CheckResult(
        name, measured, tolerance, bool(np.isfinite(measured) and measured <= tolerance), detail, tuple(notes)
    )


def summary(results: list[CheckResult]) -> str:
    """The closing line of ``lutbake validate``: "37 passed, 0 failed"."""
    passed = sum(r.passed for r in results)
    return f"{passed} passed, {len(results) - passed} failed"
