"""Smoke test of ``lutbake plot``: the seed's figures are written as PNGs and the fitted-vs-integrated table printed."""

import pytest
from click.testing import CliRunner

from lutbake.cli import main

pytest.importorskip("matplotlib")


def test_plot_writes_pngs_and_the_error_table(tmp_path):
    r = CliRunner().invoke(main, ["plot", "--out-dir", str(tmp_path), "--order", "4"])
    assert r.exit_code == 0, r.output
    pngs = sorted(tmp_path.glob("*.png"))
    assert pngs and all(p.stat().st_size > 1000 and p.read_bytes()[:4] == b"\x89PNG" for p in pngs)
    assert "fitted (Eq. 8) vs integrated (Eq. 4)" in r.output
    rows = [line for line in r.output.splitlines() if line[:2] in ("11", "12", "13", "14", "15")]
    assert len(rows) == 9  # Figures 11a-c, 12a-b, 13, 14a-b, 15


def test_plot_no_png_prints_only_the_table(tmp_path):
    r = CliRunner().invoke(main, ["plot", "--out-dir", str(tmp_path), "--order", "4", "--no-png"])
    assert r.exit_code == 0, r.output
    assert not list(tmp_path.glob("*.png")) and "max err" in r.output
