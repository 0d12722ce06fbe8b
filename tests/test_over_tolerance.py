"""A table whose texels end over their tolerance is impossible to miss: status over_tolerance (report.json, the
Python API), an "OVER TOLERANCE" line naming its texels and the worst estimate / tolerance, exit 1 (also when it
is up to date), unless its config sets accept_over_tolerance = true (a validated, documented key)."""

import json

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake import api
from lutbake.axes import Axis
from lutbake.cli import main
from lutbake.errors import ConfigError, TableError
from lutbake.tolerance import over_tolerance

# no order of the adaptive ladder reaches 1e-13 (the float32 terms' rounding alone is 1e-7 |v|)
UNREACHABLE = 1e-13


def config(tmp_path, *extra):
    p = tmp_path / "t.toml"
    lines = ['name = "t"', 'kind = "dfg"', "size = [4, 4]", f"tolerance = {UNREACHABLE}", *extra]
    p.write_text("[[table]]\n" + "\n".join(lines) + "\n")
    return p


def bake(*args):
    return CliRunner().invoke(main, ["bake", *map(str, args)])


def test_over_tolerance_has_its_status_a_line_and_exit_1_unless_accepted(tmp_path):
    cfg, out, rep = config(tmp_path), tmp_path / "out", tmp_path / "r.json"
    r = bake(cfg, "--out-dir", out, "--report", rep)
    assert r.exit_code == 1, r.output
    line = next(x for x in r.output.splitlines() if x.startswith("OVER TOLERANCE t: "))
    assert "16 of 16 texels over tolerance: perceptual_roughness rows 0..3 (0.125..0.875), NoV columns 0..3" in line
    ratio = float(line.split("worst estimate / tolerance ")[1].split(";")[0])
    assert ratio > 1e5 and "exit status 1" in line
    assert "1 over tolerance" in r.output.splitlines()[-1]
    doc = json.loads(rep.read_text())
    (entry,) = doc["tables"]
    assert entry["status"] == "over_tolerance" and doc["counts"]["over_tolerance"] == 1 and doc["exit_status"] == 1
    assert "16 of 16 texels over tolerance" in entry["message"] and (out / "t.exr").is_file()
    again = bake(cfg, "--out-dir", out)  # up to date: the file records it, the exit status stays 1
    assert again.exit_code == 1 and "up to date in" in again.output and "OVER TOLERANCE t: " in again.output
    accepted = bake(config(tmp_path, "accept_over_tolerance = true"), "--out-dir", out, "--report", rep)
    assert accepted.exit_code == 0, accepted.output
    assert "accepted (accept_over_tolerance = true)" in accepted.output
    assert json.loads(rep.read_text())["tables"][0]["status"] == "over_tolerance"


def test_the_python_api_raises_for_a_table_over_tolerance_unless_accepted(tmp_path):
    with pytest.raises(TableError, match="texels over tolerance"):
        api.bake([config(tmp_path)], tmp_path / "out")
    (result,) = api.bake([config(tmp_path, "accept_over_tolerance = true")], tmp_path / "out")
    assert result.status == "over_tolerance" and "accepted" in result.message


def test_accept_over_tolerance_is_a_validated_boolean(tmp_path):
    with pytest.raises(ConfigError, match="accept_over_tolerance") as e:
        api.bake([config(tmp_path, 'accept_over_tolerance = "yes"')], tmp_path / "out")
    assert "true or false" in str(e.value)


def test_over_tolerance_names_the_region_of_the_texels():
    """The bounding box of the texels over tolerance, per axis: indices and axis values; '' when none."""
    axes = [Axis("alpha", "y", 4, 0.0, 1.0), Axis("NoV", "x", 8, 0.0, 1.0)]
    ratios = np.full((4, 8), 0.5)
    assert over_tolerance(ratios, axes) == ""
    ratios[1, 2], ratios[2, 5] = 3.0, 1.5
    assert over_tolerance(ratios, axes) == (
        "2 of 32 texels over tolerance: alpha rows 1..2 (0.375..0.625), NoV columns 2..5 (0.312..0.688); "
        "worst estimate / tolerance 3"
    )
    ratios[0, 0] = np.nan  # a NaN estimate is never within the tolerance
    assert over_tolerance(ratios, axes).startswith("3 of 32 texels over tolerance: alpha rows 0..2")
