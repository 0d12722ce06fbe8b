"""Every named check of lutbake.validate passes: analytic reductions and invariants of the terms and tables."""

import pytest

from lutbake.validate import CHECKS, CheckResult, run_all


@pytest.mark.parametrize("name", list(CHECKS))
def test_check_passes(name):
    result = CHECKS[name]()
    print(result)
    assert isinstance(result, CheckResult) and result.name == name
    assert result.passed, str(result)


def test_run_all_rejects_unknown_names_and_lists_valid_ones():
    with pytest.raises(KeyError, match="weak_white_furnace"):
        run_all(["no_such_check"])
