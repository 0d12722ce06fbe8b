"""Nothing wrong survives a rerun (issue 11, items 1-3; issue 12, item 3).

- the corruption sweep: every output format (exr, npy, png16, dds, ktx2, h) corrupted every way (zero bytes,
  truncated, 100 bytes short, a flipped byte at the start / middle / end, junk appended, another config's
  data in its place; the sidecar emptied, garbled or removed) is baked again on the next run, never skipped,
  and the rebake restores the exact bytes. ``python tests/test_integrity.py`` prints the counts.
- fault injection: a writer SIGKILLed after every step of writing an output (temp written, renamed; sidecar
  temp written, renamed) over another config's output; the next run of either config ends with that
  config's exact bytes, and a skip happens only where the output on disk is that config's.
- a full disk between the data and the sidecar; stale temp files of dead writers; one sidecar per file.
"""

from __future__ import annotations

import errno
import json
import os
import pickle
import shutil
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lutbake import api, batch  # noqa: E402
from lutbake.config import load_configs  # noqa: E402
from lutbake.io import atomic, conventions  # noqa: E402
from lutbake.io.formats import EXTENSIONS  # noqa: E402
from lutbake.io.integrity import sha256_file, sidecar_path, verified_attributes  # noqa: E402

FORMATS = ("exr", "npy", "png16", "dds", "ktx2", "h")
DATA_MODES = (
    "zero_bytes",
    "truncated_half",
    "short_by_100",
    "flip_first",
    "flip_middle",
    "flip_last",
    "junk_appended",
    "foreign_data",
)
SIDECAR_MODES = ("sidecar_zero_bytes", "sidecar_garbled_value", "sidecar_removed")
CASES = [(f, m) for f in FORMATS for m in DATA_MODES] + [(f, m) for f in FORMATS if f != "exr" for m in SIDECAR_MODES]


def config_text(samples: int, fmt: str) -> str:
    return f'[[table]]\nname = "t"\nkind = "dfg"\nsize = [8, 4]\nsamples = {samples}\nformat = "{fmt}"\n'


def spec_for(tmp: Path, samples: int, fmt: str):
    p = tmp / f"c_{fmt}_{samples}.toml"
    p.write_text(config_text(samples, fmt))
    (spec,) = load_configs([p])
    return spec


def same_output(p: Path, q: Path) -> bool:
    """Byte-identical, except an EXR's capDate (OpenImageIO stamps the time) and so its data_hash."""
    if p.suffix != ".exr":
        return p.read_bytes() == q.read_bytes()
    from lutbake.io.exr import read_exr

    (dp, ap), (dq, aq) = read_exr(p), read_exr(q)
    ap.pop("data_hash"), aq.pop("data_hash")
    return dp.tobytes() == dq.tobytes() and ap == aq


def bake_into(spec, out: Path) -> batch.Job:
    (job,) = batch.schedule([spec], out, force=True)
    batch.run([job], workers=1, progress=None)
    assert job.status == "baked", job.message
    return job


def bake_pristine(tmp: Path) -> dict:
    """fmt -> (spec A, spec B, dir of A's output, dir of B's output): A and B differ in samples."""
    made = {}
    for fmt in FORMATS:
        a, b = spec_for(tmp, 48, fmt), spec_for(tmp, 64, fmt)
        bake_into(a, tmp / fmt / "a")
        bake_into(b, tmp / fmt / "b")
        made[fmt] = (a, b, tmp / fmt / "a", tmp / fmt / "b")
    return made


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    return bake_pristine(tmp_path_factory.mktemp("pristine"))


def corrupt(out: Path, fmt: str, mode: str, foreign: Path) -> None:
    data = out / f"t{EXTENSIONS[fmt]}"
    raw = data.read_bytes()
    side = sidecar_path(data)
    if mode == "zero_bytes":
        data.write_bytes(b"")
    elif mode == "truncated_half":
        data.write_bytes(raw[: len(raw) // 2])
    elif mode == "short_by_100":
        data.write_bytes(raw[:-100])
    elif mode.startswith("flip_"):
        i = {"flip_first": 0, "flip_middle": len(raw) // 2, "flip_last": len(raw) - 1}[mode]
        data.write_bytes(raw[:i] + bytes([raw[i] ^ 0x5A]) + raw[i + 1 :])
    elif mode == "junk_appended":
        data.write_bytes(raw + b"\x00junk" * 4)
    elif mode == "foreign_data":  # another config's output in its place, this config's sidecar left
        shutil.copyfile(foreign / data.name, data)
    elif mode == "sidecar_zero_bytes":
        side.write_bytes(b"")
    elif mode == "sidecar_garbled_value":  # valid JSON, one character of a convention changed
        doc = json.loads(side.read_text())
        doc["lutbake"]["reconstruction"] = "X" + doc["lutbake"]["reconstruction"][1:]
        side.write_text(json.dumps(doc, indent=1))
    elif mode == "sidecar_removed":
        side.unlink()
    else:
        raise AssertionError(mode)


def sweep_case(pristine, fmt: str, mode: str, work: Path) -> tuple[bool, bool]:
    """(the corrupted output was skipped, the rerun restored the exact bytes)."""
    a, _, dir_a, dir_b = pristine[fmt]
    out = work / f"{fmt}_{mode}"
    shutil.copytree(dir_a, out)
    corrupt(out, fmt, mode, dir_b)
    (job,) = batch.schedule([a], out)
    if job.status == "skipped":
        return True, False
    batch.run([job], workers=1, progress=None)
    name = f"t{EXTENSIONS[fmt]}"
    restored = (
        job.status == "baked"
        and same_output(out / name, dir_a / name)
        and batch.schedule([a], out)[0].status == "skipped"
    )
    return False, restored


@pytest.mark.parametrize("fmt, mode", CASES, ids=[f"{f}-{m}" for f, m in CASES])
def test_a_corrupted_output_is_rebaked_not_skipped(pristine, tmp_path, fmt, mode):
    skipped, restored = sweep_case(pristine, fmt, mode, tmp_path)
    assert not skipped, f"{fmt} {mode}: a corrupted output was skipped as up to date"
    assert restored, f"{fmt} {mode}: the rerun did not restore the exact bytes"


@pytest.mark.parametrize("fmt", FORMATS)
def test_an_intact_output_is_verified_and_skipped(pristine, tmp_path, fmt):
    a, _, dir_a, _ = pristine[fmt]
    shutil.copytree(dir_a, tmp_path / "o")
    (job,) = batch.schedule([a], tmp_path / "o")
    assert job.status == "skipped"
    attrs = verified_attributes(tmp_path / "o" / f"t{EXTENSIONS[fmt]}")
    assert attrs["content_hash"] == batch.content_hash(a)


@pytest.mark.parametrize("chunk", [1, 7, 97, 128, 129, 1000, 4096])
def test_exr_hash_does_not_depend_on_the_chunk_size(pristine, tmp_path, monkeypatch, chunk):
    """The EXR is hashed in chunks (a 1 GiB table is never read at once): any chunking gives one answer."""
    from lutbake.io import integrity

    _, _, dir_a, _ = pristine["exr"]
    good = dir_a / "t.exr"
    raw = good.read_bytes()
    flipped = tmp_path / "t.exr"
    i = raw.index(b"lutbake:data_hash") + 30  # inside the recorded digits
    flipped.write_bytes(raw[:i] + bytes([raw[i] ^ 1]) + raw[i + 1 :])
    monkeypatch.setattr(integrity, "CHUNK", chunk)
    assert integrity.exr_intact(good) and not integrity.exr_intact(flipped)
    assert integrity._scan_exr(good)[0] == integrity.sha256_bytes(
        raw.replace(raw[raw.index(b"lutbake:data_hash") + 29 :][:64], integrity.PLACEHOLDER)
    )


def test_every_file_of_a_multi_file_output_is_verified(tmp_path):
    """ltc_dds writes <name>_1.dds and <name>_2.dds under one sidecar: a change to either is caught."""
    from lutbake.io.integrity import read_sidecar, write_sidecar

    first, second = tmp_path / "t_1.dds", tmp_path / "t_2.dds"
    second.write_bytes(b"second texture")
    first.write_bytes(b"first texture")
    digests = {f.name: sha256_file(f) for f in (first, second)}
    write_sidecar(first, "ltc_dds", {"content_hash": "h"}, digests, {"files": [first.name, second.name]})
    assert read_sidecar(first)["files_sha256"] == {second.name: sha256_file(second)}
    second.write_bytes(b"second textur!")
    assert read_sidecar(first) is None
    second.unlink()
    assert read_sidecar(first) is None


# ------------------------------------------------------------------------------ fault injection

KILLER = textwrap.dedent("""
    import os, pickle, signal, sys
    from lutbake.io import atomic
    from lutbake.io.formats import write_table
    table_file, out_dir, fmt, kill_at = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    steps = []
    def step(name):
        steps.append(name)
        if len(steps) == kill_at:
            os.kill(os.getpid(), signal.SIGKILL)
    real_fsync, real_replace = atomic._fsync_file, os.replace
    def fsync(path):
        real_fsync(path)
        step("temp written " + os.path.basename(path))
    def replace(src, dst):
        real_replace(src, dst)
        step("renamed " + os.path.basename(dst))
    atomic._fsync_file, os.replace = fsync, replace
    with open(table_file, "rb") as f:
        table = pickle.load(f)
    write_table(table, out_dir, fmt)
    print("|".join(steps))
""")


def write_killed(table, out: Path, fmt: str, kill_at: int, tmp: Path) -> subprocess.CompletedProcess:
    tf = tmp / f"table_{fmt}.pkl"
    tf.write_bytes(pickle.dumps(table))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-c", KILLER, str(tf), str(out), fmt, str(kill_at)],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.parametrize("fmt", ["npy", "exr", "ktx2"])
def test_a_writer_killed_at_every_step_leaves_nothing_a_rerun_trusts(pristine, tmp_path, fmt):
    """B's writer is SIGKILLed after each step of writing over A's output; then A's next run, and B's,
    must each end with their own exact bytes, skipping only where the unit on disk is theirs. One writer is killed
    per step; each rerun starts from a copy of what it left."""
    a, b, dir_a, dir_b = pristine[fmt]
    name = f"t{EXTENSIONS[fmt]}"
    table_b, _, _ = api.bake_table(b, workers=1)
    full = write_killed(table_b, tmp_path / "probe", fmt, 0, tmp_path)  # 0: never killed; lists the steps
    assert full.returncode == 0, full.stderr
    steps = full.stdout.strip().split("|")
    assert len(steps) == (2 if fmt == "exr" else 4), steps
    for kill_at in range(1, len(steps) + 1):
        killed = tmp_path / f"killed{kill_at}"  # A's output, B's writer killed over it: each rerun gets a copy
        shutil.copytree(dir_a, killed)
        p = write_killed(table_b, killed, fmt, kill_at, tmp_path)
        assert p.returncode == -signal.SIGKILL, (kill_at, p.stdout, p.stderr)
        for rerun, theirs in ((a, dir_a), (b, dir_b)):
            out = tmp_path / f"k{kill_at}_{rerun.options['samples']}"
            shutil.copytree(killed, out)
            (job,) = batch.schedule([rerun], out)
            if job.status == "skipped":  # a skip is right only if the output on disk is this config's
                assert same_output(out / name, theirs / name), f"{fmt}: killed after '{steps[kill_at - 1]}'"
            batch.run([job], workers=1, progress=None)
            assert same_output(out / name, theirs / name), (kill_at, steps[kill_at - 1])
            assert batch.schedule([rerun], out)[0].status == "skipped"
            assert not [f for f in out.iterdir() if atomic.TEMP_RE.fullmatch(f.name)], "stale temp files left"
        if fmt != "exr" and steps[kill_at - 1].startswith("renamed t."):
            # the decisive instant: B's data renamed, A's sidecar still there: A's rerun must not skip
            assert batch.schedule([a], killed)[0].status == "pending"


def test_a_full_disk_between_data_and_sidecar_makes_the_next_run_rebake(pristine, tmp_path, monkeypatch):
    """The issue's ENOSPC case: B's data replaced A's, B's sidecar could not be written."""
    a, b, dir_a, _ = pristine["npy"]
    out = tmp_path / "o"
    shutil.copytree(dir_a, out)

    def full_disk(*args, **kw):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(sidecar_path(out / "t.npy")))

    with monkeypatch.context() as m:
        m.setattr(conventions, "write_sidecar", full_disk)
        (job,) = batch.schedule([b], out)
        batch.run([job], workers=1, progress=None)
    assert job.status == "failed" and "no space left on device" in job.message, job.message
    (again,) = batch.schedule([a], out)
    assert again.status == "pending", "A's sidecar over B's data was trusted"
    batch.run([again], workers=1, progress=None)
    assert same_output(out / "t.npy", dir_a / "t.npy")


# ------------------------------------------------------------------------------- stale temp files


def test_stale_temp_files_of_dead_writers_are_removed(pristine, tmp_path):
    a, _, dir_a, _ = pristine["exr"]
    out = tmp_path / "o"
    shutil.copytree(dir_a, out)
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead_pid = int(dead.stdout)  # exited: no such process any more (unless the pid was reused at once)
    if atomic.pid_alive(dead_pid):
        pytest.skip("the pid was reused")
    stale = [out / f".t.exr.{dead_pid}.0123abcd.tmp.exr", out / f".report.json.{dead_pid}.89abcdef.tmp.json"]
    live = out / f".t.exr.{os.getpid()}.0123abcd.tmp.exr"  # a writer still running: kept
    mine = [out / "notes.tmp", out / f".t.exr.{dead_pid}.tmp.exr", out / "keep.exr"]  # not lutbake's pattern
    for f in stale + [live] + mine:
        f.write_bytes(b"partial")
    jobs = batch.schedule([a], out)
    assert jobs[0].status == "skipped"
    batch.run(jobs, workers=1, progress=None)
    assert not any(f.exists() for f in stale)
    assert live.exists() and all(f.exists() for f in mine)


def test_killed_writer_temp_file_is_removed_by_the_next_run(pristine, tmp_path):
    a, b, dir_a, _ = pristine["exr"]
    out = tmp_path / "o"
    shutil.copytree(dir_a, out)
    table_b, _, _ = api.bake_table(b, workers=1)
    p = write_killed(table_b, out, "exr", 1, tmp_path)  # killed with its temp file written, not renamed
    assert p.returncode == -signal.SIGKILL
    left = [f for f in out.iterdir() if atomic.TEMP_RE.fullmatch(f.name)]
    assert len(left) == 1
    jobs = batch.schedule([a], out)
    batch.run(jobs, workers=1, progress=None)
    assert jobs[0].status == "skipped" and not left[0].exists()


# --------------------------------------------------------------------- one sidecar per output file


def test_npy_and_h_of_one_table_keep_two_sidecars_and_both_skip(tmp_path):
    from click.testing import CliRunner

    from lutbake.cli import main

    cfg = tmp_path / "c.toml"
    cfg.write_text(config_text(48, "npy"))
    out = tmp_path / "o"
    for fmt in ("npy", "h"):
        r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(out), "--format", fmt])
        assert r.exit_code == 0, r.output
    assert (out / "t.npy.json").is_file() and (out / "t.h.json").is_file()
    assert json.loads((out / "t.npy.json").read_text())["file"] == "t.npy"
    assert json.loads((out / "t.h.json").read_text())["file"] == "t.h"
    for fmt, ext in (("npy", "npy"), ("h", "h"), ("npy", "npy")):
        r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(out), "--format", fmt])
        assert r.exit_code == 0 and f"skipped {out / ('t.' + ext)} (up to date)" in r.output, r.output


def test_alternating_ktx2_and_png16_does_not_rebake(tmp_path):
    from click.testing import CliRunner

    from lutbake.cli import main

    cfg = tmp_path / "c.toml"
    cfg.write_text(config_text(48, "ktx2"))
    out = tmp_path / "o"
    outputs = []
    for fmt in ("ktx2", "png16", "ktx2", "png16"):
        r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(out), "--format", fmt])
        assert r.exit_code == 0, r.output
        outputs.append(r.output)
    assert "skipped" not in outputs[0] + outputs[1]
    assert "(up to date)" in outputs[2] and "(up to date)" in outputs[3]


def test_a_legacy_shared_sidecar_is_replaced(pristine, tmp_path):
    a, _, dir_a, _ = pristine["npy"]
    out = tmp_path / "o"
    shutil.copytree(dir_a, out)
    legacy = out / "t.json"  # the pre-issue-11 <stem>.json of this file
    legacy.write_text(json.dumps({"file": "t.npy", "format": "npy", "lutbake": {"content_hash": "x"}}))
    (job,) = batch.schedule([a], out, force=True)
    batch.run([job], workers=1, progress=None)
    assert not legacy.exists() and sidecar_path(out / "t.npy").is_file()


# ------------------------------------------------------------------- concurrent runs into one out-dir

RACE_NAMES = ("t", "u")
RACE_SAMPLES = (48, 75)
WINDOW_S = 0.002  # test-only widening of every write's instant between a rename and what follows it


def race_configs(tmp: Path, fmt: str) -> dict[int, Path]:
    """Two configs with the same table names (RACE_NAMES) and different samples: samples -> config path."""
    made = {}
    for s in RACE_SAMPLES:
        p = tmp / f"race_{fmt}_{s}.toml"
        p.write_text(
            "".join(
                f'[[table]]\nname = "{n}"\nkind = "dfg"\nsize = [4, 4]\nsamples = {s}\nformat = "{fmt}"\n'
                for n in RACE_NAMES
            )
        )
        made[s] = p
    return made


def widen_the_window(monkeypatch) -> None:
    """Sleep after each rename's directory fsync: on a writer that hashes the file after its rename, another run's
    rename then lands in between (the old bug) on almost every write, not once in a while."""
    import time

    real = atomic._fsync_dir

    def slow(path):
        real(path)
        time.sleep(WINDOW_S)

    monkeypatch.setattr(atomic, "_fsync_dir", slow)


def check_no_wrong_skip(configs: dict[int, Path], out: Path, refs: dict[int, Path]) -> None:
    """Every file a config would skip holds that config's bytes, and every table's pair on disk is one writer's
    (one of the two configs skips it: never a data file of one run beside the sidecar of the other)."""
    skippers = {n: [] for n in RACE_NAMES}
    for s, cfg in configs.items():
        for job in batch.schedule(load_configs([cfg]), out):
            if job.status != "skipped":
                continue
            skippers[job.name].append(s)
            assert same_output(job.path, refs[s] / job.path.name), f"samples = {s}: {job.path.name} is not its table"
            if job.path.suffix != ".exr":
                doc = json.loads(sidecar_path(job.path).read_text())
                assert doc["data_sha256"] == sha256_file(refs[s] / job.path.name)
    assert all(len(v) == 1 for v in skippers.values()), f"a pair of two writers left on disk: {skippers}"


def wrong_vouchers(out: Path, expected: dict[str, bytes]) -> list[str]:
    """The npy outputs whose sidecar, read at this instant, vouches for the data file's bytes (its ``data_sha256``
    is their sha256) while those bytes are not the table of the config its ``content_hash`` names (``expected``:
    content hash -> that table's bytes): a file the next run of that config would skip, holding another's table.
    One read of each file: what a concurrent run scheduling at this moment would see."""
    from lutbake.io.integrity import sha256_bytes

    wrong = []
    for name in RACE_NAMES:
        data = out / f"{name}.npy"
        try:
            doc = json.loads(sidecar_path(data).read_bytes())
            blob = data.read_bytes()
        except (OSError, ValueError):
            continue
        claimed = doc.get("lutbake", {}).get("content_hash")
        if doc.get("data_sha256") == sha256_bytes(blob) and blob != expected.get(claimed):
            wrong.append(name)
    return wrong


@pytest.mark.parametrize("fmt", ["npy", "exr"])
def test_concurrent_bakes_into_one_out_dir_never_leave_a_wrong_file_up_to_date(tmp_path, monkeypatch, fmt):
    """Issue 46, item 1: 12 bakes at once (threads, 3 rounds; EXR 1) of two configs with the same table names into one
    out-dir. A sidecar hashed from the file after its rename named the other run's bytes: the next run of the config
    skipped a file holding the other config's table. Checked while the bakes run (wrong_vouchers, npy) and after
    each round (check_no_wrong_skip). (An EXR is sealed before its rename: checked the same way after each round.)"""
    import threading

    configs = race_configs(tmp_path, fmt)
    refs = {s: tmp_path / f"ref{s}" for s in configs}
    for s, cfg in configs.items():
        api.bake([cfg], refs[s], workers=1)
    expected = {
        batch.content_hash(spec): (refs[s] / f"{spec.name}.npy").read_bytes()
        for s, cfg in configs.items()
        for spec in load_configs([cfg])
        if fmt == "npy"
    }
    widen_the_window(monkeypatch)
    out = tmp_path / "out"
    wrong: list[str] = []
    for _ in range(3 if fmt == "npy" else 1):
        failures, running = [], threading.Event()

        def one(cfg):
            r = api.bake([cfg], out, workers=1, force=True, check=False)
            failures.extend(x.message for x in r if x.status != "baked")

        def watch():  # what a run scheduling at any instant meanwhile would see
            while running.is_set():
                wrong.extend(wrong_vouchers(out, expected) if expected else [])

        threads = [threading.Thread(target=one, args=(configs[RACE_SAMPLES[i % 2]],)) for i in range(12)]
        running.set()
        watcher = threading.Thread(target=watch)
        watcher.start()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        running.clear()
        watcher.join()
        assert not failures, failures
        assert not wrong, f"a sidecar vouched for another config's bytes: {sorted(set(wrong))} ({len(wrong)} times)"
        check_no_wrong_skip(configs, out, refs)


RACER = textwrap.dedent("""
    import os, pickle, sys, time
    from lutbake.io import atomic
    from lutbake.io.formats import write_table
    tables_file, out_dir, rounds, window, go = sys.argv[1:]
    real = atomic._fsync_dir
    def slow(path):
        real(path)
        time.sleep(float(window))
    atomic._fsync_dir = slow
    with open(tables_file, "rb") as f:
        tables = pickle.load(f)
    for k in range(int(rounds)):
        open(f"{go}.{k}.{os.getpid()}", "w").close()  # ready for round k
        deadline = time.monotonic() + 120  # the test died: never outlive it
        while not os.path.exists(f"{go}.{k}"):  # every writer starts the round at once
            if time.monotonic() > deadline or os.getppid() == 1:
                sys.exit("no go signal: the test has gone")
            time.sleep(0.001)
        for table in tables:
            write_table(table, out_dir, "npy")
""")
RACE_ROUNDS = 6


def test_concurrent_processes_writing_one_out_dir_leave_each_pair_whole(tmp_path):
    """Issue 46, item 1, across processes (two `lutbake bake` at once): 6 writer processes, 3 per config, writing both
    tables in 6 rounds started together into one out-dir; after each round every skip is right and every pair on disk
    is one writer's (the out-dir's flock, lutbake.io.atomic.unit_lock)."""
    import time

    configs = race_configs(tmp_path, "npy")
    refs = {s: tmp_path / f"ref{s}" for s in configs}
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    go, out, procs = tmp_path / "go", tmp_path / "out", []
    for s, cfg in configs.items():
        r = api.bake([cfg], refs[s], workers=1)
        tf = tmp_path / f"tables{s}.pkl"
        tf.write_bytes(pickle.dumps([x.table for x in r]))
        args = [sys.executable, "-c", RACER, str(tf), str(out), str(RACE_ROUNDS), str(WINDOW_S), str(go)]
        procs += [subprocess.Popen(args, env=env) for _ in range(3)]
    try:
        for k in range(RACE_ROUNDS + 1):
            while k < RACE_ROUNDS and len(list(tmp_path.glob(f"go.{k}.*"))) < len(procs):
                assert all(p.poll() is None for p in procs), "a writer died"
                time.sleep(0.005)
            if k:  # every writer has finished round k - 1 (and waits for round k)
                if k == RACE_ROUNDS:
                    assert [p.wait(timeout=120) for p in procs] == [0] * len(procs)
                check_no_wrong_skip(configs, out, refs)
            (tmp_path / f"go.{k}").touch()
    finally:  # a failed round leaves no writer behind, waiting for a go that never comes
        for p in procs:
            p.kill()
            p.wait()


# ------------------------------------------------------------------------------- counts, by hand


def main_counts() -> None:
    """``python tests/test_integrity.py``: the corruption sweep's counts."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        made = bake_pristine(d)
        rebaked = skipped = 0
        for fmt, mode in CASES:
            s, ok = sweep_case(made, fmt, mode, d / "work")
            skipped += s
            rebaked += ok
            print(f"{fmt:6} {mode:22} {'SKIPPED' if s else 'rebaked' if ok else 'REBAKED WRONG'}")
        print(f"corrupted outputs rebaked: {rebaked} / {len(CASES)}; skipped as up to date: {skipped}")


if __name__ == "__main__":
    main_counts()
