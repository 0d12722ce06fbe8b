"""Validation: analytic reductions and invariants of the BRDF terms and the tables built from them.

:mod:`.probe` evaluates the ``@wp.func`` terms at arrays of host inputs (one compiled Warp module);
:mod:`.checks` turns them into named checks with stated tolerances (``run_all()``).
"""

from .checks import CHECKS, CheckResult, run_all
from .probe import BRDF_PAIRS, TERM_NAMES, evaluate_brdfs, evaluate_terms

__all__ = ["BRDF_PAIRS", "CHECKS", "CheckResult", "TERM_NAMES", "evaluate_brdfs", "evaluate_terms", "run_all"]
