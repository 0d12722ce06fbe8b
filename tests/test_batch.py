"""Batch runs (issue 7): incremental content-hash skips, --force, --report, one failing table does
not stop the others, Ctrl-C / SIGTERM keep finished tables and write no unfinished one, two
concurrent runs never corrupt a file, and the output is deterministic for any worker count."""

import dataclasses
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake import batch, pipeline, provenance, sources
from lutbake.cli import main
from lutbake.config import load_configs
from lutbake.io.exr import read_exr
from lutbake.kinds import lookup_kind

ROOT = Path(__file__).resolve().parents[1]


def table(name, **kw):
    opts = {"kind": "dfg", "size": [8, 4], "samples": 48, **kw}
    body = "".join(f"{k} = {json.dumps(v)}\n" for k, v in opts.items())
    return f'[[table]]\nname = "{name}"\n{body}'


def write_config(tmp_path, *tables, name="c.toml"):
    p = tmp_path / name
    p.write_text("\n".join(tables))
    return p


def bake(*args):
    return CliRunner().invoke(main, ["bake", *map(str, args)])


def drop_data_hash(attrs):
    return {k: v for k, v in attrs.items() if k != "data_hash"}


def lutbake_header(path):
    return read_exr(path)[1]


@pytest.fixture
def three(tmp_path):
    cfg = write_config(tmp_path, table("a"), table("b", layout="multiscatter"), table("c", ndf="beckmann"))
    return cfg, tmp_path / "out"


def test_rerun_skips_up_to_date_tables_and_force_rebakes(three):
    cfg, out = three
    r = bake(cfg, "--out-dir", out)
    assert r.exit_code == 0, r.output
    assert "skipped" not in r.output
    mtimes = {p.name: p.stat().st_mtime_ns for p in out.glob("*.exr")}
    assert sorted(mtimes) == ["a.exr", "b.exr", "c.exr"]
    specs = load_configs([cfg])
    for s in specs:
        assert lutbake_header(out / f"{s.name}.exr")["content_hash"] == provenance.content_hash(s)

    r = bake(cfg, "--out-dir", out)
    assert r.exit_code == 0, r.output
    for n in "abc":
        assert f"skipped {out / (n + '.exr')} (up to date)" in r.output
    assert {p.name: p.stat().st_mtime_ns for p in out.glob("*.exr")} == mtimes

    r = bake(cfg, "--out-dir", out, "--force")
    assert r.exit_code == 0 and "skipped" not in r.output and r.output.count("samples/texel") == 3


def test_a_one_line_config_change_rebakes_only_that_table(three):
    cfg, out = three
    assert bake(cfg, "--out-dir", out).exit_code == 0
    cfg.write_text(cfg.read_text().replace('ndf = "beckmann"', 'ndf = "beckmann"\nmasking = "v_cavity"'))
    r = bake(cfg, "--out-dir", out)
    assert r.exit_code == 0, r.output
    assert "skipped" in r.output and r.output.count("skipped") == 2
    baked = [line for line in r.output.splitlines() if "samples/texel" in line]
    assert len(baked) == 1 and "c.exr" in baked[0]
    # --set changes the canonical config too
    r = bake(cfg, "--out-dir", out, "--set", "a.dtype=half")
    assert r.output.count("skipped") == 2 and "a.exr" in [ln for ln in r.output.splitlines() if "samples" in ln][0]


def test_content_hash_covers_config_version_and_kernel_sources(monkeypatch, tmp_path):
    (s,) = load_configs([write_config(tmp_path, table("a"))])
    (s2,) = load_configs([write_config(tmp_path, table("a", samples=49), name="d.toml")])
    h = provenance.content_hash(s)
    assert len(h) == 64 and h == provenance.content_hash(s)
    assert provenance.content_hash(s2) != h
    assert provenance.content_hash(s, b"other sources") != h
    monkeypatch.setattr(provenance, "__version__", "9.9.9")
    assert provenance.content_hash(s) != h
    rel = {f.relative_to(sources.PACKAGE).as_posix() for f in sources.source_files()}
    for f in (
        "terms/ndf.py",
        "terms/masking.py",
        "terms/fresnel.py",
        "sampling/hemisphere.py",
        "kinds/dfg.py",
        "integrands/specular.py",
        "axes.py",
        "edge.py",
    ):
        assert f in rel


def test_a_corrupt_or_foreign_output_is_rebaked(three):
    cfg, out = three
    out.mkdir()
    (out / "a.exr").write_bytes(b"not an exr")
    r = bake(cfg, "--out-dir", out)
    assert r.exit_code == 0 and "skipped" not in r.output
    assert lutbake_header(out / "a.exr")["kind"] == "dfg"


def wrap_run_tile(monkeypatch, wrappers):
    """The tables named in ``wrappers`` bake with ``wrappers[name](run_tile)`` as their plan's run_tile."""
    real = pipeline.kind_of

    def lookup(spec):
        kind = real(spec)

        def plan(spec):
            p = kind.plan(spec)
            wrap = wrappers.get(spec.name)
            return p if wrap is None else dataclasses.replace(p, run_tile=wrap(p.run_tile))

        return dataclasses.replace(kind, plan=plan)

    monkeypatch.setattr(pipeline, "kind_of", lookup)


def _sabotage(monkeypatch, how):
    """Make the tables named in ``how`` fail in their run_tile: name -> 'raise' | 'nan' | 'oom'."""

    def failing(mode):
        def wrap(orig):
            def run_tile(s, e, d):
                if mode == "raise":
                    raise RuntimeError("kernel exploded")
                if mode == "oom":
                    raise MemoryError()
                return np.full_like(orig(s, e, d), np.nan)

            return run_tile

        return wrap

    wrap_run_tile(monkeypatch, {name: failing(mode) for name, mode in how.items()})


def test_one_failing_table_does_not_stop_the_others(monkeypatch, tmp_path):
    # distinct seeds: tables that differ only in name would share one computation (lutbake.sharing)
    cfg = write_config(tmp_path, *[table(n, seed=i) for i, n in enumerate(("boom", "good", "nan", "oom", "fine"))])
    out = tmp_path / "out"
    _sabotage(monkeypatch, {"boom": "raise", "nan": "nan", "oom": "oom"})
    rep = tmp_path / "report.json"
    r = bake(cfg, "--out-dir", out, "--workers", "2", "--report", rep)
    assert r.exit_code == 1, r.output
    assert "Traceback" not in r.output
    assert sorted(p.name for p in out.iterdir()) == ["fine.exr", "good.exr"]
    assert "FAILED boom" in r.output and "kernel exploded" in r.output
    assert "FAILED nan" in r.output and "non-finite" in r.output
    assert "FAILED oom" in r.output and "out of memory" in r.output
    assert "3 of 5 tables failed: boom, nan, oom" in r.output
    doc = json.loads(rep.read_text())
    status = {t["name"]: t["status"] for t in doc["tables"]}
    assert status == {"boom": "failed", "good": "baked", "nan": "failed", "oom": "failed", "fine": "baked"}
    assert doc["exit_status"] == 1
    # the next run bakes only the failed tables
    monkeypatch.undo()
    r = bake(cfg, "--out-dir", out)
    assert r.exit_code == 0 and r.output.count("skipped") == 2 and r.output.count("samples/texel") == 3


def test_report_has_every_field(three):
    cfg, out = three
    rep = out / "r.json"
    assert bake(cfg, "--out-dir", out, "--set", "c.estimator=sobol_ndf").exit_code == 0
    cfg2 = write_config(cfg.parent, table("d"), name="d.toml")
    r = bake(cfg, cfg2, "--out-dir", out, "--set", "c.estimator=sobol_ndf", "--report", rep)
    assert r.exit_code == 0
    doc = json.loads(rep.read_text())
    assert doc["counts"] == {"baked": 1, "skipped": 3, "over_tolerance": 0, "failed": 0, "interrupted": 0}
    keys = {"name", "status", "path", "content_hash", "seconds", "cpu_seconds", "values_from", "samples"}
    keys |= {"error_estimate", "message"}
    for t in doc["tables"]:
        assert set(t) == keys
        assert Path(t["path"]).is_file() and len(t["content_hash"]) == 64
        assert t["samples"] in (48, 64) and t["error_estimate"] >= 0 and t["seconds"] >= 0
    assert [t["status"] for t in doc["tables"]] == ["skipped", "skipped", "skipped", "baked"]
    assert doc["tables"][-1]["cpu_seconds"] > 0 and doc["tables"][-1]["values_from"] is None


@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupt_keeps_finished_tables_and_writes_no_unfinished_one(
    monkeypatch, tmp_path, signum, code, terminal_sigint
):
    cfg = write_config(tmp_path, table("first"), table("slow", size=[64, 32]), table("last", seed=1))  # not shared
    out = tmp_path / "out"
    out.mkdir()
    stale = out / "slow.exr"
    stale.write_bytes(b"a good file from an older run")

    def interrupted(orig):
        def run_tile(s, e, d):
            if s == 0:
                os.kill(os.getpid(), signum)  # Ctrl-C / SIGTERM arrives while this table bakes
            time.sleep(0.3)
            return orig(s, e, d)

        return run_tile

    wrap_run_tile(monkeypatch, {"slow": interrupted})
    rep = tmp_path / "r.json"
    handlers = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    r = bake(cfg, "--out-dir", out, "--workers", "1", "--report", rep)
    assert r.exit_code == code, r.output
    assert "Traceback" not in r.output
    assert f"interrupted ({signal.Signals(signum).name}): 2 of 3 tables did not finish: slow, last" in r.output
    assert stale.read_bytes() == b"a good file from an older run"  # never replaced by an unfinished table
    assert sorted(p.name for p in out.iterdir()) == ["first.exr", "slow.exr"]  # no temporary files left
    doc = json.loads(rep.read_text())
    assert [t["status"] for t in doc["tables"]] == ["baked", "interrupted", "interrupted"]
    assert doc["exit_status"] == code and doc["interrupted_by"] == signal.Signals(signum).name
    assert {s: signal.getsignal(s) for s in handlers} == handlers  # the bake's SIGTERM handler is gone again
    # the next run resumes only the tables that did not finish
    monkeypatch.undo()
    r = bake(cfg, "--out-dir", out)
    assert r.exit_code == 0, r.output
    assert f"skipped {out / 'first.exr'} (up to date)" in r.output
    assert r.output.count("samples/texel") == 2


def test_two_concurrent_runs_never_corrupt_a_file(tmp_path):
    cfg = write_config(tmp_path, *[table(f"t{i}", size=[16, 8]) for i in range(4)])
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = [sys.executable, "-m", "lutbake", "bake", str(cfg), "--out-dir", str(out), "--force", "--workers", "1"]
    procs = [
        subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)
    ]
    for p in procs:
        stdout, stderr = p.communicate(timeout=120)
        assert p.returncode == 0, stderr
        assert stdout.count("samples/texel") == 4
    assert sorted(p.name for p in out.iterdir()) == [f"t{i}.exr" for i in range(4)]
    ref = {t.name: t for t, _, _ in (pipeline.bake_table(s, workers=1) for s in load_configs([cfg]))}
    for i in range(4):
        data, attrs = read_exr(out / f"t{i}.exr")
        assert np.array_equal(data, ref[f"t{i}"].data)
        assert attrs["content_hash"] == ref[f"t{i}"].attributes["content_hash"]


def test_same_config_gives_identical_pixels_and_headers_for_any_worker_count(tmp_path):
    cfg = write_config(
        tmp_path,
        table("x", size=[24, 12]),
        table("y", size=[9, 5], estimator="sobol_ndf"),
        table("z", size=[7, 3], texel="endpoint", dtype="half"),
    )
    runs = []
    for k, workers in enumerate(["1", "2", "2"]):
        out = tmp_path / f"out{k}"
        r = bake(cfg, "--out-dir", out, "--workers", workers)
        assert r.exit_code == 0, r.output
        runs.append({n: read_exr(out / f"{n}.exr") for n in "xyz"})
    for other in runs[1:]:
        for n in "xyz":
            assert np.array_equal(runs[0][n][0], other[n][0])
            # every lutbake:* attribute, content_hash included, but data_hash: the sha256 of the file's
            # bytes, which hold OpenImageIO's capDate (the write time; docs/batch.md)
            assert drop_data_hash(runs[0][n][1]) == drop_data_hash(other[n][1])


def test_api_plan_and_run_without_the_cli(tmp_path):
    specs = load_configs([write_config(tmp_path, table("p"), table("q"))])
    jobs = batch.schedule(specs, tmp_path / "o")
    assert [j.status for j in jobs] == ["pending", "pending"]
    seen = []
    assert batch.run(jobs, workers=2, on_done=seen.append) is None
    assert sorted(j.name for j in seen) == ["p", "q"] and all(j.status == "baked" for j in jobs)
    assert batch.exit_status(jobs, None) == 0
    assert [j.status for j in batch.schedule(specs, tmp_path / "o")] == ["skipped", "skipped"]
    assert [j.status for j in batch.schedule(specs, tmp_path / "o", force=True)] == ["pending", "pending"]
    assert lookup_kind("dfg").name == "dfg"


def test_ctrl_c_on_a_real_process(tmp_path):
    """A real `lutbake bake` process gets SIGINT while its second (big) table bakes: exit 130, the
    first table kept, the big one not written, no temporary file left."""
    cfg = write_config(tmp_path, table("first"), table("big", size=[256, 256], samples=432))
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    # a child inherits SIG_IGN for SIGINT from a shell's background job (`make test &`), and Python then
    # installs no KeyboardInterrupt handler: restore the default so the signal is delivered as from a terminal
    p = subprocess.Popen(
        [sys.executable, "-m", "lutbake", "bake", str(cfg), "--out-dir", str(out), "--workers", "1"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.monotonic() + 60
    while not (out / "first.exr").exists() and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    p.send_signal(signal.SIGINT)
    stdout, stderr = p.communicate(timeout=60)
    if p.returncode == 0:  # the machine was fast enough to finish first: nothing to check
        pytest.skip("the bake finished before the signal arrived")
    assert p.returncode == 130, stderr
    assert "Traceback" not in stderr and "did not finish: big" in stderr
    assert sorted(f.name for f in out.iterdir()) == ["first.exr"]


@pytest.mark.parametrize("fmt, ext", [("npy", ".npy"), ("dds", ".dds"), ("ktx2", ".ktx2"), ("h", ".h")])
def test_every_format_is_skipped_when_up_to_date(tmp_path, fmt, ext):
    """Non-EXR outputs carry the content hash in their .json sidecar, so reruns skip them too."""
    cfg = write_config(tmp_path, table("t", format=fmt))
    out = tmp_path / "out"
    first = bake(cfg, "--out-dir", out)
    assert first.exit_code == 0, first.output
    assert (out / f"t{ext}").is_file() and (out / f"t{ext}.json").is_file()
    again = bake(cfg, "--out-dir", out)
    assert again.exit_code == 0 and f"skipped {out / ('t' + ext)} (up to date)" in again.output
    changed = bake(cfg, "--out-dir", out, "--set", "samples=64")
    assert changed.exit_code == 0 and "(up to date)" not in changed.output


def test_modules_load_in_parallel_each_once(monkeypatch):
    """Tables prepare in parallel (no batch-wide lock): two different Warp modules load at the same time, while two
    tables asking for the same module load it one after the other (the second finds it loaded: compiled once)."""
    import threading

    import warp as wp

    from lutbake.runtime import warp_runtime

    spans = []

    def slow_load(module, device=None):
        t0 = time.perf_counter()
        time.sleep(0.3)
        spans.append((module, t0, time.perf_counter()))

    monkeypatch.setattr(wp, "load_module", slow_load)
    monkeypatch.setattr(warp_runtime, "_MODULE_LOCKS", {})
    a, b = object(), object()  # stand-ins for two Warp modules
    threads = [threading.Thread(target=warp_runtime.load_module, args=(m, "cpu")) for m in (a, a, b)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    (a0, a1), (b0,) = [sorted(s[1:] for s in spans if s[0] is m) for m in (a, b)]
    assert warp_runtime.parallel_loads()
    assert a1[0] >= a0[1]  # the same module: one load after the other
    assert b0[0] < max(a0[1], a1[1]) and min(a0[0], a1[0]) < b0[1]  # another module: at the same time


def test_a_kernel_factory_builds_once_whatever_the_threads():
    """warp_runtime.kernel_factory: threads that ask for the same kernels at once get one build's objects (functools'
    cache let each build its own, defining into a Warp module another thread was loading: Warp's KeyError), another
    argument builds its own; and lutbake.ltc.aniso's fit tiles (worker threads) share one set of fit kernels."""
    import threading

    from lutbake.ltc import aniso, fit
    from lutbake.runtime import warp_runtime

    builds, start = [], threading.Barrier(6)

    @warp_runtime.kernel_factory
    def slow_factory(name):
        builds.append(name)
        time.sleep(0.2)  # a build long enough for every thread to ask meanwhile
        return object()

    got = {}

    def ask(i):
        start.wait(5)
        got[i] = slow_factory("a" if i < 5 else "b")

    threads = [threading.Thread(target=ask, args=(i,)) for i in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(builds) == ["a", "b"]
    assert len({id(got[i]) for i in range(5)}) == 1 and got[5] is not got[0]
    assert fit.kernels.__code__ is slow_factory.__code__  # the fit's kernels are built by a kernel_factory
    assert fit.kernels(aniso.LOBES["free"]) is fit.kernels(aniso.LOBES["free"])


def test_a_busy_module_defers_only_the_first_load_of_an_armed_thread(monkeypatch):
    """warp_runtime.defer_if_busy: while another thread loads module a, this thread's first load_module of a raises
    ModuleBusy (it may do other work) instead of waiting; a load outside the context, or a later one inside it, waits
    and then finds a loaded; an idle module loads at once."""
    import threading

    import warp as wp

    from lutbake.runtime import warp_runtime

    loading, release, loads = threading.Event(), threading.Event(), []

    def held_load(module, device=None):
        loads.append(module)
        if module == "a" and len(loads) == 1:
            loading.set()
            release.wait(5)

    monkeypatch.setattr(wp, "load_module", held_load)
    monkeypatch.setattr(warp_runtime, "_MODULE_LOCKS", {})
    first = threading.Thread(target=warp_runtime.load_module, args=("a", "cpu"))
    first.start()
    assert loading.wait(5)
    with warp_runtime.defer_if_busy():
        with pytest.raises(warp_runtime.ModuleBusy):
            warp_runtime.load_module("a")
        warp_runtime.load_module("b")  # no longer armed: a plain load (b is free anyway)
    with warp_runtime.defer_if_busy():
        warp_runtime.load_module("b")  # armed, but b is free: loads
    release.set()
    first.join()
    warp_runtime.load_module("a")  # unarmed: waits for the lock, then loads
    assert loads == ["a", "b", "b", "a"]


def test_a_table_whose_module_is_busy_steps_back_behind_the_next(monkeypatch, tmp_path):
    """batch.run: a group that raises ModuleBusy (its first kernel module compiling in the other table thread) is set
    back once, behind the next group, and baked after it; the last group in the queue never steps back; every table is
    baked once and reported."""
    from lutbake.runtime import warp_runtime

    cfg = write_config(tmp_path, *[table(n, seed=i) for i, n in enumerate(("a", "b", "c"))])
    jobs = batch.schedule(load_configs([cfg]), tmp_path / "out")
    order, tries = [], {}
    real = batch._bake_group

    def fake(group, *args, **kw):
        name = group[0].name
        tries[name] = tries.get(name, 0) + 1
        if name in ("a", "c") and tries[name] == 1:  # a: set back behind b; c: last in the queue, never set back
            armed = getattr(warp_runtime._DEFER, "armed", False)
            assert armed == (name == "a")
            if armed:
                raise warp_runtime.ModuleBusy(name)
        order.append(name)
        return real(group, *args, **kw)

    monkeypatch.setattr(batch, "_bake_group", fake)
    done = []
    assert batch.run(jobs, workers=1, on_done=done.append) is None
    assert order == ["b", "a", "c"] and tries == {"a": 2, "b": 1, "c": 1}
    assert sorted(j.name for j in done) == ["a", "b", "c"] and all(j.status == "baked" for j in jobs)


def test_every_lutbake_kernel_module_compiles_with_lutbakes_options():
    """Every Warp module holding a lutbake kernel (the factories' unique modules and the fixed ones) is built with
    lutbake.runtime.warp_runtime.MODULE_OPTIONS: forward code only, LLVM's leaner inlining (CPU_COMPILER_FLAGS).
    Checks the
    kernels this test makes plus every one the test session made before it."""
    import importlib
    import pkgutil

    import lutbake
    from lutbake.integrands import fresnel
    from lutbake.ltc import fit
    from lutbake.ltc.lobes import LOBES
    from lutbake.records import FRESNEL
    from lutbake.runtime import warp_runtime

    for m in pkgutil.walk_packages(lutbake.__path__, "lutbake."):
        if not m.name.endswith("__main__"):
            importlib.import_module(m.name)
    fresnel._kernel(FRESNEL.lookup("schlick"))
    fit.kernels(LOBES["ggx"])
    from warp._src.context import user_modules

    ours = {
        name: mod
        for name, mod in list(user_modules.items())
        if any(k.func.__module__.startswith("lutbake.") for k in mod.kernels.values())
    }
    assert len(ours) >= 3  # lutbake.validate.probe, lutbake.ltc.fit and fresnel's unique module at least
    for name, mod in ours.items():
        for key, value in warp_runtime.MODULE_OPTIONS.items():
            assert mod.options[key] == value, (name, key)


def test_kernels_are_built_one_thread_at_a_time_but_modules_compile_in_parallel(monkeypatch):
    """warp_runtime.defining: Warp's registries of functions and modules are not thread-safe (on an empty kernel cache,
    two tables of one batch that differed only in masking came out identical), so one table thread at a time builds
    kernels; load_module releases the lock while it compiles, so two modules still compile at the same time."""
    import threading

    import warp as wp

    from lutbake.runtime import warp_runtime

    spans = {"build": [], "load": []}

    def slow_load(module, device=None):
        t0 = time.perf_counter()
        time.sleep(0.3)
        spans["load"].append((t0, time.perf_counter()))

    def prepare(module):
        with warp_runtime.defining():
            t0 = time.perf_counter()
            time.sleep(0.1)  # building the kernel: under the lock
            spans["build"].append((t0, time.perf_counter()))
            warp_runtime.load_module(module, "cpu")  # compiling: lock released
            with warp_runtime.defining():  # nested use (the error estimate inside a bake) does not deadlock
                pass

    monkeypatch.setattr(wp, "load_module", slow_load)
    monkeypatch.setattr(warp_runtime, "_MODULE_LOCKS", {})
    threads = [threading.Thread(target=prepare, args=(m,)) for m in (object(), object())]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    (b0, b1), (l0, l1) = sorted(spans["build"]), sorted(spans["load"])
    assert b1[0] >= b0[1]  # the builds never overlap
    assert l1[0] < l0[1]  # the compiles do
    assert not getattr(warp_runtime._DEFINING, "held", False)


def test_a_thread_waiting_for_anothers_compile_lets_others_build_kernels(monkeypatch):
    """load_module releases warp_runtime.defining while it waits for a module another thread is compiling (not only
    while it compiles): a third thread may build its kernels meanwhile."""
    import threading

    import warp as wp

    from lutbake.runtime import warp_runtime

    compiling, release = threading.Event(), threading.Event()

    def held_load(module, device=None):
        if not compiling.is_set():
            compiling.set()
            release.wait(5)

    def prepare():
        with warp_runtime.defining():
            warp_runtime.load_module("a", "cpu")

    monkeypatch.setattr(wp, "load_module", held_load)
    monkeypatch.setattr(warp_runtime, "_MODULE_LOCKS", {})
    threads = [threading.Thread(target=prepare) for _ in range(2)]  # the first compiles a, the second waits for it
    threads[0].start()
    assert compiling.wait(5)
    threads[1].start()
    time.sleep(0.2)
    try:
        free = warp_runtime._DEFINE.acquire(timeout=1.0)  # a third table's kernel build
        if free:
            warp_runtime._DEFINE.release()
    finally:
        release.set()
        for th in threads:
            th.join(5)
    assert free
