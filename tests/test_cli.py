"""CLI smoke runs: bake, list, inspect, bad input (exit 2, nothing written), python -m lutbake."""

import subprocess
import sys

from click.testing import CliRunner

from lutbake.cli import main

CONFIG = """
[[table]]
name = "small"
kind = "dfg"
size = [16, 8]
samples = 48
"""


def run(*args):
    return CliRunner().invoke(main, list(args))


def test_bake_prints_one_line_per_table_and_writes_exr(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG)
    r = run("bake", str(cfg), "--out-dir", str(tmp_path / "out"), "--workers", "2")
    assert r.exit_code == 0, r.output
    line = r.output.strip().splitlines()[-1]
    assert "small.exr" in line and "8x16x2" in line and "samples/texel" in line and " s " in line
    assert (tmp_path / "out" / "small.exr").is_file()
    i = run("inspect", str(tmp_path / "out" / "small.exr"))
    assert i.exit_code == 0, i.output
    for word in ("dfg", "NoV", "perceptual_roughness", "scale", "bias", "f0"):
        assert word in i.output


def test_bad_config_exits_2_and_writes_nothing(tmp_path):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(CONFIG.replace('kind = "dfg"', 'kind = "dfg"\nndf = "phong"'))
    good = tmp_path / "good.toml"
    good.write_text(CONFIG.replace('"small"', '"fine"'))
    r = run("bake", str(good), str(cfg), "--out-dir", str(tmp_path / "out"))
    assert r.exit_code == 2
    assert "bad.toml" in r.output and "'ndf'" in r.output and "ggx" in r.output
    assert "Traceback" not in r.output
    assert not (tmp_path / "out").exists()


def test_unknown_preset_and_bad_set_exit_2(tmp_path):
    r = run("bake", "--preset", "nope", "--out-dir", str(tmp_path))
    assert r.exit_code == 2 and "default" in r.output
    r = run("bake", "--preset", "default", "--set", "samples=0", "--out-dir", str(tmp_path))
    assert r.exit_code == 2 and "'samples'" in r.output
    assert not any(tmp_path.iterdir())


def test_list_shows_kinds_terms_and_presets():
    r = run("list")
    assert r.exit_code == 0
    for word in ("dfg", "ggx", "beckmann", "smith_height_correlated", "v_cavity", "schlick", "default"):
        assert word in r.output


def test_inspect_missing_file_is_a_clear_error(tmp_path):
    r = run("inspect", str(tmp_path / "none.exr"))
    assert r.exit_code != 0 and "none.exr" in r.output


def test_python_m_lutbake_help_has_examples():
    r = subprocess.run([sys.executable, "-m", "lutbake", "bake", "--help"], capture_output=True, text=True)
    assert r.returncode == 0 and "Examples" in r.stdout and "--set" in r.stdout


def test_preview_writes_a_png_for_exr_and_npy(tmp_path):
    import pytest

    pytest.importorskip("matplotlib", reason="lutbake preview needs matplotlib (the plot extra)")
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        CONFIG.replace(
            "size = [16, 8]",
            'size = [16, 8]\nlayout = "multiscatter"\nrow_order = "hi_first"\nroughness_mapping = "texel_offset"',
        )
    )
    out = tmp_path / "out"
    for fmt in ("exr", "npy"):
        r = run("bake", str(cfg), "--out-dir", str(out), "--format", fmt)
        assert r.exit_code == 0, r.output
    for name in ("small.exr", "small.npy"):
        r = run("preview", str(out / name), "-o", str(tmp_path / f"{name}.png"))
        assert r.exit_code == 0, r.output
        assert (tmp_path / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    r = run("preview", str(tmp_path / "none.exr"))
    assert r.exit_code != 0 and "none.exr" in r.output
