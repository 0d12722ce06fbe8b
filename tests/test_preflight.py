"""No late failures, no tracebacks, no terminal escapes (issue 11, items 4-8).

Everything a batch will touch on disk is checked before any kernel runs (exit 2, nothing written); a
config nested 100 000 deep is a ConfigError; a write error says what happened (a full disk by name); a
Ctrl-C during the start-up imports exits 130 quietly; untrusted text is printed escaped."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from lutbake import batch
from lutbake.cli import main

ROOT = Path(__file__).resolve().parents[1]
DFG = '[[table]]\nname = "t"\nkind = "dfg"\nsize = [8, 4]\nsamples = 48\n'


def bake(*args):
    return CliRunner().invoke(main, ["bake", *map(str, args)])


@pytest.fixture
def cfg(tmp_path):
    p = tmp_path / "c.toml"
    p.write_text(DFG)
    return p


@pytest.fixture
def no_kernel(monkeypatch):
    """Fails the test if any table is baked (a plan-time error must come before any kernel)."""

    def boom(*a, **k):
        raise AssertionError("a kernel ran before the error")

    monkeypatch.setattr(batch, "compute", boom)


def refused(r, *fragments):
    assert r.exit_code == 2, (r.exit_code, r.output)
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "Traceback" not in r.output and "error:" in r.output
    for f in fragments:
        assert f in r.output, r.output


@pytest.fixture
def mount(tmp_path):
    """mount(dir, options): a tmpfs there (root with CAP_SYS_ADMIN only, else the test is skipped)."""
    mounted = []

    def do(path: Path, options: str) -> Path:
        path.mkdir(parents=True, exist_ok=True)
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)], capture_output=True)
        if r.returncode != 0:
            pytest.skip(f"cannot mount a tmpfs here: {r.stderr.decode(errors='replace').strip()}")
        mounted.append(path)
        return path

    yield do
    for p in reversed(mounted):
        subprocess.run(["umount", str(p)], capture_output=True)


# ------------------------------------------------------------------ item 6: late failures -> exit 2


def test_out_dir_below_a_file_is_refused_before_any_kernel(cfg, tmp_path, no_kernel):
    (tmp_path / "f").write_text("")
    refused(bake(cfg, "--out-dir", tmp_path / "f" / "sub" / "o"), "is a file, not a directory")


def test_out_dir_that_is_a_dangling_symlink_is_refused(cfg, tmp_path, no_kernel):
    (tmp_path / "o").symlink_to(tmp_path / "gone")
    refused(bake(cfg, "--out-dir", tmp_path / "o"), "dangling symlink")
    (tmp_path / "p").symlink_to(tmp_path / "gone2")
    refused(bake(cfg, "--out-dir", tmp_path / "p" / "deeper"), "dangling symlink")


def test_out_dir_on_a_read_only_mount_is_refused(cfg, tmp_path, mount, no_kernel):
    ro = mount(tmp_path / "ro", "ro,size=64k")
    refused(bake(cfg, "--out-dir", ro / "o"), "read-only file system")
    refused(bake(cfg, "--out-dir", ro), "read-only file system")


def test_an_output_path_that_is_a_directory_is_refused(cfg, tmp_path, no_kernel):
    (tmp_path / "o" / "t.exr").mkdir(parents=True)
    refused(bake(cfg, "--out-dir", tmp_path / "o"), "is a directory")
    (tmp_path / "o" / "t.npy.json").mkdir()  # the sidecar's path: its rename would fail after the bake
    refused(bake(cfg, "--out-dir", tmp_path / "o", "--format", "npy"), "t.npy.json exists and is a directory")


def test_png16_of_a_table_above_one_is_refused_at_plan_time(tmp_path, no_kernel):
    p = tmp_path / "c.toml"
    p.write_text('[[table]]\nname = "lut_charlie"\nkind = "dfg"\nlayout = "charlie"\nsize = [8, 8]\nformat = "png16"\n')
    refused(bake(p, "--out-dir", tmp_path / "o"), "'format'", "png16", "charlie")
    p.write_text(DFG)
    refused(bake(p, "--out-dir", tmp_path / "o", "--format", "png16", "--set", "layout=sheen_albedo"), "png16")
    refused(bake("--preset", "gltf-charlie", "--out-dir", tmp_path / "o", "--format", "png16"), "png16")
    refused(
        bake(p, "--out-dir", tmp_path / "o", "--format", "png16", "--set", "kind=btf", "--set", "samples=4"),
        "png16",
        "btf",
    )
    assert not (tmp_path / "o").exists()


def test_png16_of_a_3d_table_is_refused_at_plan_time(tmp_path, no_kernel):
    p = tmp_path / "s3.toml"
    p.write_text('[[table]]\nname = "s3"\nkind = "specular_3d"\nsize = [8, 8]\nf0_size = 4\nformat = "png16"\n')
    refused(bake(p, "--out-dir", tmp_path / "o"), "'format'", "png16 holds 2D tables only", "4 x 8 x 8")
    assert not (tmp_path / "o").exists()


def test_python_api_makes_the_same_plan_time_checks(cfg, tmp_path, no_kernel):
    import lutbake
    from lutbake.errors import ConfigError

    (tmp_path / "f").write_text("")
    with pytest.raises(ConfigError, match="is a file, not a directory"):
        lutbake.bake([cfg], out_dir=tmp_path / "f" / "o")
    p = tmp_path / "s3.toml"
    p.write_text('[[table]]\nname = "s3"\nkind = "specular_3d"\nsize = [8, 8]\nf0_size = 4\nformat = "png16"\n')
    with pytest.raises(ConfigError, match="png16 holds 2D tables only"):
        lutbake.bake([p], out_dir=tmp_path / "o")


# --------------------------------------------------------- items 4 and 8: --report checked up front


def test_report_under_a_file_is_refused_before_any_kernel(cfg, tmp_path, no_kernel):
    (tmp_path / "f").write_text("")
    refused(bake(cfg, "--out-dir", tmp_path / "o", "--report", tmp_path / "f" / "r.json"), "--report")
    assert not (tmp_path / "o").exists()


def test_report_on_a_read_only_mount_is_refused(cfg, tmp_path, mount, no_kernel):
    ro = mount(tmp_path / "ro", "ro,size=64k")
    refused(bake(cfg, "--out-dir", tmp_path / "o", "--report", ro / "r.json"), "read-only file system")


@pytest.mark.parametrize("fmt, victim", [("exr", "t.exr"), ("npy", "t.npy"), ("npy", "t.npy.json"), ("h", "t.h.json")])
def test_report_that_is_an_output_or_its_sidecar_is_refused(cfg, tmp_path, no_kernel, fmt, victim):
    out = tmp_path / "o"
    refused(bake(cfg, "--out-dir", out, "--format", fmt, "--report", out / victim), "of table 't'")
    refused(
        bake(cfg, "--out-dir", out, "--format", fmt, "--report", tmp_path / "x" / ".." / "o" / victim), "of table 't'"
    )


def test_report_that_is_the_config_is_refused(cfg, tmp_path, no_kernel):
    refused(bake(cfg, "--out-dir", tmp_path / "o", "--report", cfg), "is the config")
    assert cfg.read_text() == DFG


def test_report_on_a_full_disk_is_an_error_not_a_traceback(cfg, tmp_path, mount):
    full = mount(tmp_path / "full", "size=64k")
    fd = os.open(full / "filler", os.O_WRONLY | os.O_CREAT)  # fill it to the last byte
    try:
        while os.write(fd, b"\0" * 4096):
            pass
    except OSError:
        pass
    finally:
        os.close(fd)
    r = bake(cfg, "--out-dir", tmp_path / "o", "--report", full / "r.json")
    assert r.exit_code == 1, r.output
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "Traceback" not in r.output and "cannot write the report" in r.output
    assert "no space left on device" in r.output
    assert (tmp_path / "o" / "t.exr").is_file() and not (full / "r.json").exists()
    assert not [f for f in full.iterdir() if f.name != "filler"]  # no temp file left


# --------------------------------------------------------------------- item 7: ENOSPC names the cause


def test_a_full_disk_names_the_cause(cfg, tmp_path, mount):
    out = mount(tmp_path / "small", "size=16k")
    p = tmp_path / "big.toml"
    p.write_text(DFG.replace("[8, 4]", "[128, 128]").replace("samples = 48", "samples = 16"))
    r = bake(p, "--out-dir", out)
    assert r.exit_code == 1 and "Traceback" not in r.output, r.output
    assert "no space left on device" in r.output, r.output
    assert sorted(f.name for f in out.iterdir()) == []


def test_a_writer_error_without_errno_on_a_full_disk_names_the_cause(cfg, tmp_path, monkeypatch):
    """OpenImageIO says only "File output failed" when the disk is full: the free space tells why."""
    import shutil

    from lutbake.io import exr

    def oiio_fails(path, parts, fmt):
        raise OSError(f"cannot finish writing {path}: File output failed")

    monkeypatch.setattr(exr, "_write_oiio", oiio_fails)
    monkeypatch.setattr(shutil, "disk_usage", lambda p: shutil._ntuple_diskusage(1 << 30, 1 << 30, 4096))
    r = bake(cfg, "--out-dir", tmp_path / "o")
    assert r.exit_code == 1 and "no space left on device (4096 bytes free" in r.output, r.output
    assert "File output failed" in r.output


# ------------------------------------------------------------- item 7: untrusted text, config types

ESCAPES = "\u001b]0;PWNED\u0007\u001b[2J"


def test_escape_sequences_in_keys_and_values_are_printed_escaped(tmp_path):
    p = tmp_path / "c.toml"
    esc = json.dumps(ESCAPES)  # a TOML basic string with \u001b escapes
    for body in (f"{esc} = 1\n", f"ndf = {esc}\n", f"name = {esc}\n"):
        p.write_text(DFG.replace('name = "t"\n', "") + ('name = "t"\n' if "name" not in body else "") + body)
        r = bake(p, "--out-dir", tmp_path / "o")
        refused(r)
        assert "\x1b" not in r.output and "\x07" not in r.output, repr(r.output)
        assert "\\x1b]0;PWNED\\x07\\x1b[2J" in r.output, r.output
    r = bake(p, "--out-dir", tmp_path / "o", "--set", f"{ESCAPES}=1")
    refused(r)
    assert "\x1b" not in r.output
    odd = tmp_path / f"c{ESCAPES}.toml"
    odd.write_text(DFG.replace('"dfg"', '"nope"'))
    r = bake(odd, "--out-dir", tmp_path / "o")
    refused(r)
    assert "\x1b" not in r.output and "\\x1b" in r.output


def test_a_directory_fifo_or_device_as_config_says_what_it_is(tmp_path):
    refused(bake(tmp_path, "--out-dir", tmp_path / "o"), "is a directory, not a config file")
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    refused(bake(fifo, "--out-dir", tmp_path / "o"), "is a FIFO (named pipe), not a config file")
    refused(bake("/dev/zero", "--out-dir", tmp_path / "o"), "is a character device, not a config file")
    refused(bake(tmp_path / "missing.toml", "--out-dir", tmp_path / "o"), "no such config file")
    (tmp_path / "link.toml").symlink_to(tmp_path / "gone.toml")
    refused(bake(tmp_path / "link.toml", "--out-dir", tmp_path / "o"), "dangling symlink")
    big = tmp_path / "big.toml"
    with open(big, "wb") as f:
        f.truncate(1 << 30)  # a sparse 1 GiB file: refused by its size, not read
    refused(bake(big, "--out-dir", tmp_path / "o"), "a config is at most")
    assert not (tmp_path / "o").exists()


# ------------------------------------------------------------------- item 4: deep nesting, Ctrl-C


@pytest.mark.parametrize(
    "text",
    [
        "x = " + "[" * 100_000 + "]" * 100_000 + "\n",
        "x = " + "{a = " * 50_000 + "1" + "}" * 50_000 + "\n",
        "[[table]]\n" + ".".join(["k"] * 20_000) + " = 1\n",
        ".".join(["k"] * 20_000) + " = 1\n",
        DFG + "size = " + "[" * 3000 + "]" * 3000 + "\n",
    ],
    ids=["array-100000", "inline-table-50000", "dotted-key-20000-in-table", "dotted-key-20000", "size-3000"],
)
def test_deeply_nested_toml_is_a_config_error(tmp_path, text, no_kernel):
    p = tmp_path / "deep.toml"
    p.write_text(text)
    refused(bake(p, "--out-dir", tmp_path / "o"))


def test_deeply_nested_set_value_is_a_config_error(cfg, tmp_path, no_kernel):
    refused(bake(cfg, "--out-dir", tmp_path / "o", "--set", "size=" + "[" * 60_000), "--set")
    refused(bake(cfg, "--out-dir", tmp_path / "o", "--set", "size=" + "[" * 3000 + "]" * 3000), "'size'")


@pytest.mark.parametrize("module", ["numpy", "warp", "click"])
def test_ctrl_c_during_start_up_imports_exits_130_quietly(cfg, tmp_path, module):
    """A real SIGINT delivered the moment ``module`` starts importing (a meta-path hook sends it)."""
    hook = (
        "import os, signal, sys, runpy\n"
        "class Hook:\n"
        "    def find_spec(self, name, path=None, target=None):\n"
        f"        if name == {module!r}:\n"
        "            sys.meta_path.remove(self)\n"
        "            os.kill(os.getpid(), signal.SIGINT)\n"
        "        return None\n"
        "sys.meta_path.insert(0, Hook())\n"
        "sys.argv = ['lutbake'] + sys.argv[1:]\n"
        "runpy.run_module('lutbake', run_name='__main__')\n"
    )
    p = subprocess.run(
        [sys.executable, "-c", hook, "bake", str(cfg), "--out-dir", str(tmp_path / "o")],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert p.returncode == 130, (p.returncode, p.stderr)
    assert "Traceback" not in p.stderr and "KeyboardInterrupt" not in p.stderr, p.stderr
    assert "interrupted" in p.stderr
    assert not (tmp_path / "o").exists()


def test_entry_point_keeps_exit_codes_and_usage_errors():
    env = {**os.environ, "PYTHONPATH": str(ROOT)}

    def run(*a):
        return subprocess.run(
            [sys.executable, "-m", "lutbake", *a], capture_output=True, text=True, timeout=120, env=env
        )

    assert run("--version").returncode == 0
    r = run("bake", "--workers", "0")
    assert r.returncode == 2 and "Usage:" in r.stderr and "Traceback" not in r.stderr
    r = run("nosuchcommand")
    assert r.returncode == 2 and "No such command" in r.stderr


def test_entry_point_ends_with_the_atexit_hooks_the_flushes_and_the_threads_of_a_normal_exit(cfg, tmp_path):
    """lutbake._entry skips the interpreter's teardown (issue 13) but nothing a user sees of it: atexit hooks run,
    buffered output reaches a pipe, a bake's lines and status stay, a thread still running is waited for, and a
    closed stdout is no error."""
    code = (
        "import atexit, sys, threading, time\n"
        "atexit.register(lambda: print('hook ran'))\n"
        "if sys.argv[1] == 'thread':\n"
        "    threading.Thread(target=lambda: (time.sleep(0.5), print('thread finished'))).start()\n"
        "sys.argv = ['lutbake'] + sys.argv[2:]\n"
        "from lutbake._entry import main\n"
        "main()\n"
    )

    def run(*a, **kw):
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        kw = {"capture_output": True, **kw}
        return subprocess.run([sys.executable, "-c", code, *a], text=True, timeout=300, env=env, **kw)

    r = run("-", "bake", str(cfg), "--out-dir", str(tmp_path / "o"))
    assert r.returncode == 0 and r.stdout.splitlines()[-1] == "hook ran", (r.stdout, r.stderr)
    assert "t.exr" in r.stdout and r.stderr == "" and (tmp_path / "o" / "t.exr").is_file()
    r = run("-", "bake", str(tmp_path / "missing.toml"))
    assert r.returncode == 2 and "no such config file" in r.stderr and r.stdout == "hook ran\n"
    r = run("thread", "--version")
    # the thread is joined before the atexit hooks run (where --version's line falls depends on the machine's load)
    lines = r.stdout.splitlines()
    assert r.returncode == 0 and lines[-1] == "hook ran" and "lutbake, version 0.1.0" in lines, r.stdout
    assert "thread finished" in lines[:-1], r.stdout
    r = run("-", "--version", capture_output=False, stderr=subprocess.PIPE, preexec_fn=lambda: os.close(1))
    assert r.returncode == 0 and r.stderr == "", r.stderr  # no stdout at all (sys.stdout is None)


def test_probe_directory_survives_a_concurrent_run_making_and_removing_the_directory(tmp_path, monkeypatch):
    """Two runs probing one new --out-dir: the other run's mkdir wins the race (FileExistsError here), then its
    rmdir removes the directory under this probe (FileNotFoundError at mkstemp): both are retried, not errors."""
    import tempfile

    from lutbake import preflight

    out = tmp_path / "out"
    real_mkdir, real_mkstemp, calls = os.mkdir, tempfile.mkstemp, []

    def other_run_first(d, *a):
        real_mkdir(d)  # the other run made it a moment before
        real_mkdir(d, *a)

    def other_run_removes(*a, **k):
        calls.append(1)
        if len(calls) == 1:
            os.rmdir(out)  # the other run's probe cleans up
        return real_mkstemp(*a, **k)

    monkeypatch.setattr(preflight.os, "mkdir", other_run_first)
    monkeypatch.setattr(preflight.tempfile, "mkstemp", other_run_removes)
    assert preflight.probe_directory(out) is None
    assert len(calls) == 2


def test_a_directory_another_run_made_and_removed_meanwhile_is_no_error(tmp_path, monkeypatch):
    """Issue 46, item 1 (concurrent runs into one new --out-dir): the other run's probe makes the directory and removes
    it again while this run looks at it: between its exists() and access() ('is not writable (permission denied)'),
    and between its mkdir and ours ('File exists' for a directory gone again). Both are looked at again, not errors."""
    from lutbake import preflight

    out = tmp_path / "out"
    out.mkdir()  # the other run's probe made it
    real_access, real_mkdir, seen = os.access, os.mkdir, []

    def removed_meanwhile(path, mode):
        if not seen:
            seen.append(path)
            os.rmdir(out)  # ... and removes it now
        return real_access(path, mode)

    monkeypatch.setattr(preflight.os, "access", removed_meanwhile)
    assert preflight.directory_problem(out) is None
    monkeypatch.setattr(preflight.os, "access", real_access)

    def made_and_removed(d, *a):
        if not seen[1:]:
            seen.append(d)
            raise FileExistsError(17, "File exists", str(d))  # it was there an instant ago, gone by now
        real_mkdir(d, *a)

    monkeypatch.setattr(preflight.os, "mkdir", made_and_removed)
    assert preflight.probe_directory(out) is None
    assert len(seen) == 2 and not out.exists()


@pytest.mark.parametrize(
    "config_name, table, fmt, claimed",
    [("u.exr", "u", "exr", "its output"), ("t.npy.json", "t", "npy", "its sidecar of t.npy"), ("t.h", "t", "h", "")],
)
def test_a_config_that_a_table_would_overwrite_is_refused(tmp_path, no_kernel, config_name, table, fmt, claimed):
    """Issue 46, item 4: a config saved as ``u.exr`` (table u's output) or ``t.npy.json`` (table t's sidecar) was
    replaced by its own bake, exit 0. Every input is in the registry's check: exit 2, the file named, nothing
    written."""
    cfg = tmp_path / config_name
    text = f'[[table]]\nname = "{table}"\nkind = "dfg"\nsize = [4, 4]\nsamples = 48\nformat = "{fmt}"\n'
    cfg.write_text(text)
    refused(bake(cfg, "--out-dir", tmp_path), claimed, f"is the config {cfg}", "would overwrite it")
    refused(bake(cfg, "--out-dir", tmp_path / "x" / ".."), f"is the config {cfg}")
    assert cfg.read_text() == text and sorted(f.name for f in tmp_path.iterdir()) == [config_name]


def test_an_output_or_report_that_is_the_cache_directory_is_refused(cfg, tmp_path, no_kernel):
    """Issue 46, item 4: the --cache directory is an input too (its entries as well)."""
    out = tmp_path / "o"
    refused(bake(cfg, "--out-dir", out, "--cache", out / "t.exr"), "its output", "is the --cache directory")
    refused(bake(cfg, "--out-dir", out, "--cache", out / "c", "--report", out / "c"), "is the --cache directory")
    assert not out.exists()


# ------------------------------------------------------------ issue 46, item 6: --cache and the OS path limits


def test_a_cache_that_cannot_be_written_is_refused_like_the_out_dir(cfg, tmp_path, mount, no_kernel):
    """Issue 46, item 6: a --cache below a file, a dangling symlink, a symlink loop or on a read-only file system
    was accepted and every entry silently unwritten; now exit 2, one line, before any kernel."""
    out = tmp_path / "o"
    (tmp_path / "f").write_text("")
    (tmp_path / "dangling").symlink_to(tmp_path / "gone")
    (tmp_path / "loop").symlink_to(tmp_path / "loop")
    refused(bake(cfg, "--out-dir", out, "--cache", tmp_path / "f" / "c"), "--cache", "is a file, not a directory")
    refused(bake(cfg, "--out-dir", out, "--cache", tmp_path / "dangling"), "--cache", "dangling symlink")
    refused(bake(cfg, "--out-dir", out, "--cache", tmp_path / "loop"), "--cache", "symlink loop")
    refused(bake(cfg, "--out-dir", tmp_path / "loop"), "--out-dir", "symlink loop")
    ro = mount(tmp_path / "ro", "ro,size=64k")
    refused(bake(cfg, "--out-dir", out, "--cache", ro / "c"), "--cache", "read-only file system")
    assert not out.exists()


def test_a_cache_write_that_fails_anyway_is_said_once(tmp_path, monkeypatch):
    """Issue 46, item 6: a cache write that fails during the run (the disk fills, the mount turns read-only) is said
    once on the terminal, however many entries fail; the tables are baked (exit 0)."""
    import errno

    from lutbake import values_cache

    def read_only(self, key, data, extra):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(self.directory / f"{key}.npy"))

    monkeypatch.setattr(values_cache.ValuesCache, "store", read_only)
    p = tmp_path / "c.toml"
    p.write_text(DFG + DFG.replace('"t"', '"u"').replace("48", "75"))  # two values keys: two failed entries
    r = bake(p, "--out-dir", tmp_path / "o", "--cache", tmp_path / "cache")
    assert r.exit_code == 0, r.output
    assert r.output.count("values cache") == 1 and "read-only file system" in r.output, r.output


def long_dir(base: Path, length: int) -> Path:
    """A directory path below ``base`` exactly ``length`` characters long (components of at most 200)."""
    path = str(base)
    while len(path) < length:
        room = length - len(path) - 1
        path += "/" + "d" * (min(200, room) if room - min(200, room) != 1 else 199)
    assert len(path) == length
    return Path(path)


def test_an_out_dir_near_path_max_is_refused_before_any_kernel(cfg, tmp_path, no_kernel):
    """Issue 46, item 6: an --out-dir whose outputs fit PATH_MAX but not the temporary name of a sidecar
    (.t.npy.json.<pid>.<8 hex>.tmp.json) passed preflight and failed after the bake (exit 1); a longer one gave an
    OSError traceback in preflight. Both: exit 2, one line, no traceback."""
    path_max = os.pathconf(tmp_path, "PC_PATH_MAX")
    temp = len(f"/.t.npy.json.{os.getpid()}.01234567.tmp.json")
    near = long_dir(tmp_path, path_max - temp)  # + the temporary sidecar name + NUL: one byte over
    assert len(str(near / "t.npy.json")) + 1 < path_max
    refused(bake(cfg, "--out-dir", near, "--format", "npy"), "PATH_MAX", ".tmp.json")
    refused(bake(cfg, "--out-dir", long_dir(tmp_path, path_max + 150)), "PATH_MAX")
    refused(bake(cfg, "--out-dir", tmp_path / "o", "--cache", long_dir(tmp_path, path_max + 10)), "--cache", "PATH_MAX")
    assert sorted(f.name for f in tmp_path.iterdir()) == ["c.toml"]


def test_an_out_dir_name_over_name_max_is_refused_without_a_traceback(cfg, tmp_path, no_kernel):
    """A directory name longer than NAME_MAX: an OSError traceback in preflight (ENAMETOOLONG), now exit 2."""
    name_max = os.pathconf(tmp_path, "PC_NAME_MAX")
    refused(bake(cfg, "--out-dir", tmp_path / ("n" * (name_max + 1)) / "o"), "NAME_MAX")
    refused(bake(cfg, "--out-dir", tmp_path / "o", "--cache", tmp_path / ("n" * (name_max + 1))), "--cache", "NAME_MAX")
