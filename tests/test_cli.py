"""CLI smoke runs: bake, list, inspect, bad input (exit 2, nothing written), python -m lutbake."""

import re
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
    *_, line, closing = r.output.strip().splitlines()
    assert line.startswith("[1/1] ")
    assert "small.exr" in line and "8x16x2" in line and "samples/texel" in line and " s " in line
    assert re.fullmatch(r"1 table: 1 baked, 0 up to date, 0 failed, \d+ s", closing), closing
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


LIST_SUMMARY_MAX_LINES = 40  # the default `lutbake list`: a summary of a few dozen lines


def test_list_is_a_short_summary_that_says_how_to_ask_for_more():
    """`lutbake list` names every kind, preset and format in a few dozen lines and the commands that list each in
    full; the topics hold the rest (the unfiltered list was 616 lines, 53 KB)."""
    from lutbake.config import presets
    from lutbake.io.formats import ALL_FORMATS
    from lutbake.kinds import KINDS

    r = run("list")
    assert r.exit_code == 0, r.output
    assert len(r.output.splitlines()) <= LIST_SUMMARY_MAX_LINES, r.output
    words = set(re.findall(r"[A-Za-z0-9_-]+", r.output))
    assert set(KINDS) | set(presets()) | set(ALL_FORMATS) <= words
    for more in ("lutbake list kinds", "lutbake list presets", "lutbake list formats", "lutbake list keys", "terms"):
        assert more in r.output, more


def test_list_topics_show_kinds_terms_keys_and_formats():
    kinds, terms, keys, formats = (run("list", *t) for t in (["kinds"], ["terms"], ["keys", "dfg"], ["formats"]))
    assert all(r.exit_code == 0 for r in (kinds, terms, keys, formats))
    assert "split_sum" in kinds.output and "ltc" in kinds.output
    for word in ("ggx", "beckmann", "smith_height_correlated", "v_cavity", "schlick", "sobol_vndf"):
        assert word in terms.output
    for word in ("size", "masking", "smith_joint_approx", "layout", "multiscatter_cloth", 'default "exr"'):
        assert word in keys.output, word
    assert "ktx2zst" in formats.output and "babylon_fuzz" in formats.output


def test_list_keys_refuses_a_missing_or_unknown_kind_by_name():
    missing, unknown, extra = run("list", "keys"), run("list", "keys", "dgf"), run("list", "kinds", "dfg")
    assert missing.exit_code == 2 and "lutbake list keys dfg" in missing.output
    assert unknown.exit_code == 2 and "'dgf'" in unknown.output and "dfg" in unknown.output
    assert extra.exit_code == 2 and "keys KIND" in extra.output
    assert "Traceback" not in missing.output + unknown.output + extra.output


def test_list_help_has_examples():
    r = run("list", "--help")
    assert r.exit_code == 0 and "Examples" in r.output and "lutbake list keys dfg" in r.output


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


def test_list_prints_whole_preset_descriptions_and_the_files_each_writes():
    """Issue 39: descriptions were cut at their first comment line, mid-sentence; the files were not named."""
    import tomllib

    from lutbake.config import presets
    from lutbake.io.formats import written_files

    out = " ".join(run("list", "presets").output.split())  # the wrapping undone
    for name, path in presets().items():
        text = path.read_text(encoding="utf-8")
        comment = " ".join(ln.lstrip("#").strip() for ln in text.splitlines()[: _leading_comments(text)])
        assert " ".join(comment.split()) in out, name
        files = [f for t in tomllib.loads(text)["table"] for f in written_files(t["name"], t.get("format", "exr"))]
        assert f"Writes: {', '.join(files)}." in out, name
    assert "filament_dfg.dds, filament_dfg.dds.json" in out and "ltc_ggx_1.dds, ltc_ggx_2.dds" in out


def _leading_comments(text: str) -> int:
    lines = text.splitlines()
    return next((i for i, ln in enumerate(lines) if not ln.startswith("#")), len(lines))


def test_bake_closes_with_the_same_summary_line_on_a_rerun(tmp_path):
    """Issue 39: no totals; now one closing line, first run and rerun alike."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG + CONFIG.replace('"small"', '"other"').replace("samples = 48", "samples = 48\nseed = 1"))
    first = run("bake", str(cfg), "--out-dir", str(tmp_path / "out"))
    again = run("bake", str(cfg), "--out-dir", str(tmp_path / "out"))
    assert re.fullmatch(r"2 tables: 2 baked, 0 up to date, 0 failed, \d+ s", first.output.splitlines()[-1]), (
        first.output
    )
    assert re.fullmatch(r"2 tables: 0 baked, 2 up to date, 0 failed, \d+ s", again.output.splitlines()[-1]), (
        again.output
    )
    assert [ln[:6] for ln in again.output.splitlines()[:2]] == ["[1/2] ", "[2/2] "]


def test_bake_progress_on_a_terminal_shows_done_total_running_and_estimate(tmp_path):
    """--progress (the default on a terminal): a line redrawn in place with tables done / total, the running table,
    the elapsed seconds and, once a table finished, an estimate of the time left."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        "".join(
            CONFIG.replace('"small"', f'"t{i}"').replace("samples = 48", f"samples = 48\nseed = {i}") for i in range(3)
        )
    )
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(tmp_path / "o"), "--progress", "--workers", "1"])
    assert r.exit_code == 0, r.output
    redraws = [s for s in r.output.split("\r") if s.startswith("[")]  # click drops the erase code off a terminal
    assert any(re.match(r"\[0/3\]  running t\d( \+\d)?  \d+ s", s) for s in redraws), redraws
    assert any(re.match(r"\[[12]/3\]  running t\d( \+\d)?  \d+ s, ~\d+ s left", s) for s in redraws), redraws
    plain = run("bake", str(cfg), "--out-dir", str(tmp_path / "p"), "--workers", "1")  # not a terminal: no redraws
    assert "\r" not in plain.output and plain.output.count("samples/texel") == 3
