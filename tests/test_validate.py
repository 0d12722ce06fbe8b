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


def test_validate_labels_every_number_and_ends_with_a_total(monkeypatch):
    """`lutbake validate`: the measured value and the tolerance each on a labelled line, secondary figures
    (where the worst case is, limits held to another tolerance) on their own lines, never on the PASS line;
    a closing total."""
    from click.testing import CliRunner

    from lutbake.cli import main
    from lutbake.validate import checks, results

    fake = [
        results.check_result(
            "a_check",
            8.7e-6,
            2e-5,
            "max |E + E_ms - 1| over rows r >= 0.1; worst at r=0.2",
            ("rows with r < 0.1: max 3.4e-03",),
        ),
        results.check_result("b_check", 3.0, 1.0, "max |x|"),
    ]
    monkeypatch.setattr(checks, "run_all", lambda names=None: fake)
    r = CliRunner().invoke(main, ["validate"])
    assert r.exit_code == 1
    lines = r.output.splitlines()
    assert lines[0].split() == ["PASS", "a_check"]
    assert lines[1].split()[:2] == ["measured", "8.700e-06"] and "max |E + E_ms - 1|" in lines[1]
    assert lines[2].split()[:2] == ["tolerance", "2.0e-05"]
    assert lines[3].strip() == "worst at r=0.2" and lines[4].strip() == "rows with r < 0.1: max 3.4e-03"
    assert lines[5].split() == ["FAIL", "b_check"]
    assert lines[-1] == "1 passed, 1 failed"


def test_a_check_states_what_its_measured_value_is():
    result = CHECKS["schlick_endpoints"]()
    assert result.what.startswith("the larger of") and len(result.secondary) == 2
    assert all("=" in line for line in result.secondary)
