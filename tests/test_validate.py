"""Every named check of lutbake.validate passes: analytic reductions and invariants of the terms and tables."""

import numpy as np
import pytest

from lutbake.sampling import dielectric_avg
from lutbake.validate import CHECKS, CheckResult, run_all


def lattice_probe(grid):
    """A 4 x 4 lattice of a 2-D grid's texels, its corners among them: the inner-rule probe of the openpbr check's
    plan here, not its 256 strided texels. The probe picks the same inner rule from either (the check's result is
    identical, compared as a whole), at a 16th of the cost."""
    rows, cols = (np.linspace(0, axis.count - 1, 4).round().astype(int) for axis in grid.axes)
    return (rows[:, None] * grid.axes[1].count + cols[None, :]).ravel()


@pytest.mark.parametrize("name", list(CHECKS))
def test_check_passes(name, monkeypatch):
    """Every check passes; openpbr_reflection_ratio_reciprocity's plan probes lattice_probe's texels."""
    if name == "openpbr_reflection_ratio_reciprocity":
        monkeypatch.setattr(dielectric_avg, "probe_indices", lattice_probe)
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
