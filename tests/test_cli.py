"""CLI smoke runs: bake, list, inspect, bad input (exit 2, nothing written), python -m lutbake."""

import importlib
import re
import subprocess
import sys
import threading
import time

import pytest
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

    from lutbake.cli.tables import kind_outputs
    from lutbake.config import presets
    from lutbake.io.formats import written_files

    out = " ".join(run("list", "presets").output.split())  # the wrapping undone
    for name, path in presets().items():
        text = path.read_text(encoding="utf-8")
        comment = " ".join(ln.lstrip("#").strip() for ln in text.splitlines()[: _leading_comments(text)])
        assert " ".join(comment.split()) in out, name
        tables = tomllib.loads(text)["table"]
        fmts = [(t["name"], t.get("format", "exr"), t["kind"]) for t in tables]
        files = [f for n, fmt, kind in fmts for f in written_files(n, fmt, kind_outputs(kind), kind)]
        assert f"Writes: {', '.join(files)}." in out, name
    assert "filament_dfg.dds, filament_dfg.dds.json" in out and "ltc_ggx_1.dds, ltc_ggx_2.dds" in out
    assert "ltc_aniso_t0.ktx2, ltc_aniso_t1.ktx2, ltc_aniso_t2.ktx2, ltc_aniso_t0.ktx2.json" in out


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


class FakeClock:
    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def fake_result(name, status="baked", kind="dfg", size=(10, 10)):
    from types import SimpleNamespace

    from lutbake.config import validate_table

    spec = validate_table({"name": name, "kind": kind, "size": list(size)}, "<fake>", 0)
    return SimpleNamespace(
        name=name, spec=spec, status=status, path=f"out/{name}.exr", shape="10x10x2", seconds=1.0, samples=48,
        values_from=None, message="", cache_error=None,
    )  # fmt: skip


def test_time_left_weighs_the_work_not_the_tables_and_skips_the_compile():
    """A synthetic batch: 60 s of kernel compile, then table A (400 texels at 1 evaluation each, 40 s), then B and C
    (100 texels each, not started yet: weighed at A's cost per texel), at 10 evaluations a second. At t = 100 s, A
    done: 20 s are left. Counting tables (elapsed / tables done x tables left) said 200 s."""
    from lutbake.cli.bake import WorkClock

    clock = WorkClock()
    for name, texels in (("a", 400), ("b", 100), ("c", 100)):
        clock.plan(name, texels)
    assert clock.left(30.0) is None  # nothing baked yet: no estimate
    clock.start("a", 400, 400.0, now=60.0)
    clock.advance("a", 200)
    assert clock.left(80.0) == pytest.approx(40.0)  # half of A: 200 of 600 evaluations done in 20 s
    clock.advance("a", 200)
    clock.finish("a")
    assert clock.left(100.0) == pytest.approx(20.0)
    clock.start("b", 100, 300.0, now=100.0)  # B turns out three times as costly per texel: its own cost counts
    clock.advance("b", 50)
    # C, not started, now weighs (400 + 300) / (400 + 100) = 1.4 a texel: 840 planned, 550 done in 55 s
    assert clock.left(115.0) == pytest.approx((115.0 - 60.0) * (840 - 550) / 550)


def test_progress_line_estimates_from_the_work_done(monkeypatch):
    """BatchProgress.line on the timeline above (the clock patched): '~20 s left' at 100 s, where it said '~200'."""
    cli_bake = importlib.import_module("lutbake.cli.bake")  # lutbake.cli.bake the attribute is the command
    fake = FakeClock()
    monkeypatch.setattr(cli_bake.time, "perf_counter", fake)
    display = cli_bake.BatchProgress(terminal=False, t0=0.0)
    display.scheduled([fake_result("a", "pending", size=(20, 20)), *(fake_result(n, "pending") for n in "bc")])
    fake.now = 60.0
    update = display.texels("a", 400, 400.0)
    fake.now = 100.0
    if update is not None:  # the tiles report their texels
        update(400)
    display.done(fake_result("a"))
    assert display.line().endswith("100 s, ~20 s left"), display.line()


class Terminal:
    """A terminal fed one character at a time by any thread (stdout and stderr alike): \\r returns to the line's
    start, ESC[2K clears it, \\n ends it."""

    def __init__(self):
        self.lines, self.line, self.guard = [], "", threading.Lock()

    def echo(self, message="", nl=True, err=False, **_):
        text = str(message) + ("\n" if nl else "")
        i = 0
        while i < len(text):
            with self.guard:
                if text.startswith("\x1b[2K", i):
                    self.line, i = "", i + 4
                    continue
                c = text[i]
                self.line = "" if c == "\r" else self.line
                if c == "\n":
                    self.lines.append(self.line)
                    self.line = ""
                elif c != "\r":
                    self.line += c
            i += 1
            time.sleep(0)  # let the other threads write in between, as a real terminal write allows


def test_finished_lines_are_never_glued_to_the_status_line(monkeypatch):
    """Tables finish on one thread while others start and report tiles (which redraw the status line with \\r):
    every line that ends on the terminal is a whole finished line, never part of the status line."""
    cli_bake = importlib.import_module("lutbake.cli.bake")
    term = Terminal()
    monkeypatch.setattr(cli_bake.click, "echo", term.echo)
    monkeypatch.setattr(cli_bake, "DRAW_INTERVAL", 0.0, raising=False)  # redraw on every tile
    names = [f"t{i}" for i in range(24)]
    display = cli_bake.BatchProgress(terminal=True, t0=time.perf_counter())
    display.scheduled([fake_result(n, "pending") for n in names])

    def worker(part):
        for name in part:
            update = display.texels(name, 100, 100.0)
            for _ in range(5):
                if update is not None:
                    update(20)
                display.draw()
            display.done(fake_result(name))

    threads = [threading.Thread(target=worker, args=(names[i::3],)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    display.close()
    assert len(term.lines) == len(names)
    finished = re.compile(r"\[\d+/24\] out/t\d+\.exr  10x10x2  1\.00 s  48 samples/texel( \(.*\))?")
    glued = [line for line in term.lines if not finished.fullmatch(line)]
    assert not glued, glued[:3]
