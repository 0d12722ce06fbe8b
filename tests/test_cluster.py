"""Baking on a Dask cluster (lutbake.runtime.cluster): bit-identical to the thread executor, a killed worker costs
only its tiles, mismatched or broken workers are refused before any tile runs, interrupts cancel the
futures and write no unfinished table.

One small LocalCluster (2 single-threaded worker processes) serves the module; small tables."""

import contextlib
import json
import logging
import os
import pickle
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

distributed = pytest.importorskip("distributed")

from lutbake import batch  # noqa: E402
from lutbake.api import bake_table  # noqa: E402
from lutbake.cli import main  # noqa: E402
from lutbake.config import load_configs, preset_path, validate_table  # noqa: E402
from lutbake.io.exr import read_exr  # noqa: E402
from lutbake.kinds import lookup_kind  # noqa: E402
from lutbake.runtime import cluster  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.usefixtures("terminal_sigint")  # the interrupt tests and deadline() need SIGINT
BAKE_DEADLINE_S = 90  # a cluster test that has not finished by then is interrupted (and fails)
TILE = 384  # cluster tiles in these tests: small tables are cut into several, at other cuts than the executor's 512

# several kinds, each cut into more than one TILE-texel tile
SPECS = {
    "dfg_gl": {"kind": "dfg", "size": [40, 24], "samples": 48},
    # adaptive Gauss-Legendre (no samples): its per-texel error estimates travel with the tiles (aux columns)
    "dfg_adaptive": {"kind": "dfg", "size": [48, 32], "tolerance": 1e-5},
    "dfg_vndf": {"kind": "dfg", "size": [32, 20], "estimator": "sobol_vndf", "samples": 64, "seed": 3},
    "btf": {"kind": "btf", "size": [8, 8], "phi_size": 8, "sigma_size": 2, "samples": 2},
    "spec3d": {"kind": "specular_3d", "size": [16, 8], "f0_size": 6, "fresnel": "dielectric_f0", "samples": 48},
    "dielectric": {"kind": "dielectric", "size": [16, 8], "ior_size": 4, "ior_range": [0.7, 1.6]},
}
LTC_PRESET = ("ltc-ggx", ["size=[16,16]", "fit_samples=8"])  # a fit whose tiles straddle its two slices


def spec(name, **kw):
    return validate_table({"name": name, **kw}, "<test>", 0)


@pytest.fixture(scope="module", autouse=True)
def small_tiles():
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(cluster, "CLUSTER_TILE_TEXELS", TILE)
        yield


@pytest.fixture(scope="module")
def client():
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0", silence_logs=logging.ERROR
        ) as lc,
        distributed.Client(lc, set_as_default=False) as c,
    ):
        c.run(cluster.setup_local_worker)
        yield c


@pytest.fixture
def runner(client):
    r = cluster.DaskRunner(client, name="test cluster")
    r.check_workers()
    return r


@contextlib.contextmanager
def deadline(seconds=BAKE_DEADLINE_S):
    """Interrupt the main thread (as Ctrl-C would) if the block runs longer than ``seconds``."""
    import _thread

    timer = threading.Timer(seconds, _thread.interrupt_main)
    timer.start()
    try:
        yield
    finally:
        timer.cancel()


def thread_bake(specs, out) -> dict:
    """{name: (pixels, lutbake:* header)} of the files a local (thread executor) batch writes."""
    jobs = batch.schedule(specs, out, force=True)
    assert batch.run(jobs, workers=2) is None
    return {j.name: read_exr(j.path) for j in jobs}


def without_file_hash(attrs: dict) -> dict:
    return {k: v for k, v in attrs.items() if k != "data_hash"}


def assert_same_files(got: dict, want: dict):
    assert sorted(got) == sorted(want)
    for name, (data, attrs) in want.items():
        assert np.array_equal(got[name][0], data), name
        # every lutbake:* attribute (error estimate, content hash, ...) but data_hash, the file's own checksum,
        # which covers OpenImageIO's DateTime too
        assert without_file_hash(got[name][1]) == without_file_hash(attrs), name


def scheduler_transitions(client) -> int:
    return client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.transition_counter)


def test_table_spec_pickles_to_an_equal_spec():
    s = spec("p", **SPECS["dfg_vndf"])
    t = pickle.loads(pickle.dumps(s))
    assert t == s and t.toml() == s.toml() and type(t.options) is type(s.options)


@pytest.mark.parametrize(
    "text, parsed",
    [
        ("local:2", ("local", 2)),
        ("tcp://farm:8786", ("address", "tcp://farm:8786")),
        ("tls://10.0.0.1:8786", ("address", "tls://10.0.0.1:8786")),
    ],
)
def test_scheduler_forms(text, parsed):
    assert cluster.parse_scheduler(text) == parsed


@pytest.mark.parametrize("text", ["local:0", "local:x", "farm:8786", "tcp://", "local:100000"])
def test_a_bad_scheduler_exits_2_before_any_work(tmp_path, text):
    cfg = tmp_path / "c.toml"
    cfg.write_text('[[table]]\nname = "t"\nkind = "dfg"\nsize = [8, 4]\n')
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(tmp_path / "o"), "--scheduler", text])
    assert r.exit_code == 2, r.output
    assert "--scheduler" in r.output and "local:N" in r.output and not (tmp_path / "o").exists()


def test_cluster_bake_is_bit_identical_to_the_thread_executor(runner):
    specs = [spec(n, **kw) for n, kw in SPECS.items()]
    specs += load_configs([preset_path(LTC_PRESET[0])], LTC_PRESET[1])
    local = {s.name: bake_table(s, workers=2)[0] for s in specs}
    with deadline():
        remote = {s.name: bake_table(s, workers=2, runner=runner)[0] for s in specs}
    for s in specs:
        a, b = local[s.name], remote[s.name]
        assert a.data.shape == b.data.shape and np.array_equal(a.data, b.data), s.name
        assert a.attributes == b.attributes, s.name  # error estimate and content hash included
    texels = [t.data[..., 0].size for t in local.values()]
    assert min(texels) > TILE  # every table was cut into several tiles
    assert runner.stats.tiles == sum(-(-n // TILE) for n in texels)
    # float64 results: each tile's values and its aux columns (an adaptive estimator's per-texel error estimates)
    width = {s.name: lookup_kind(s.kind).plan(s).tile_width for s in specs}
    assert runner.stats.bytes_from_workers == sum(t.data[..., 0].size * width[n] * 8 for n, t in local.items())
    assert runner.stats.cancelled == 0


def test_a_plugins_table_is_shipped_to_the_workers_and_bakes_the_same_bits(runner, tmp_path):
    """The plugin's text travels with the spec's records (lutbake.registry.Record.__reduce__); each worker runs it
    (lutbake.plugins) and bakes the thread executor's bits."""
    import lutbake

    plugin = tmp_path / "schlick4_cluster.py"  # its own name: test_plugins may hold "schlick4" in this process
    text = (Path(__file__).parents[1] / "examples" / "custom_fresnel" / "schlick4.py").read_text()
    plugin.write_text(text.replace('"schlick4"', '"schlick4_cluster"'))
    lutbake.load_plugin(plugin)
    s = validate_table({"name": "p", "kind": "dfg", "size": [16, 8], "fresnel": "schlick4_cluster"}, "<t>", 0)
    local = bake_table(s, workers=2)[0]
    plugin.unlink()  # the workers read the text shipped with the record, not the file
    with deadline():
        remote = bake_table(s, workers=2, runner=runner)[0]
    assert np.array_equal(local.data, remote.data) and local.attributes == remote.attributes


def test_a_killed_worker_costs_only_its_tiles(client, tmp_path):
    """SIGKILL one worker process when the first tile arrives: Dask runs its tiles again on the other
    worker, every table is baked, the files equal an undisturbed thread-executor bake."""
    # distinct seeds: tables that differ only in name would share one computation (lutbake.sharing)
    specs = [spec(f"k{i}", kind="dfg", size=[64, 64], samples=768, seed=i) for i in range(3)]
    per_table = -(-64 * 64 // TILE)
    ref = thread_bake(specs, tmp_path / "ref")
    r = cluster.DaskRunner(client, name="test cluster")
    r.check_workers()
    pids = client.run(os.getpid)
    killed = {}
    lock = threading.Lock()

    def kill_one(name, start, stop):
        with lock:
            if killed:
                return
            processing = {a: ks for a, ks in client.processing().items() if ks}
            victim = sorted(processing)[0]
            killed.update(
                addr=victim, pid=pids[victim], tiles=len(processing[victim]), remaining=3 * per_table - r.stats.tiles
            )
            os.kill(pids[victim], signal.SIGKILL)

    r.on_tile = kill_one
    jobs = batch.schedule(specs, tmp_path / "out")
    with deadline():
        assert batch.run(jobs, workers=len(jobs), runner=r) is None
    assert killed and killed["tiles"] >= 1 and killed["remaining"] > 1  # the kill happened mid-bake, with tiles on it
    assert [j.status for j in jobs] == ["baked"] * 3, [j.message for j in jobs]
    assert r.stats.tiles == 3 * per_table  # every tile delivered once: the finished ones were never recomputed
    assert_same_files({j.name: read_exr(j.path) for j in jobs}, ref)
    client.wait_for_workers(2, timeout=60)  # the nanny restarted it, for the next tests
    assert killed["pid"] not in client.run(os.getpid).values()


@contextlib.contextmanager
def sabotaged(client, code, undo, workers=None):
    client.run(exec, code, {}, workers=workers)
    try:
        yield
    finally:
        client.run(exec, undo, {}, workers=workers)


def test_a_worker_with_another_lutbake_version_is_refused_before_any_tile_runs(client, tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('[[table]]\nname = "t"\nkind = "dfg"\nsize = [8, 4]\nsamples = 48\n')
    address = client.scheduler.address
    victim = sorted(client.scheduler_info()["workers"])[0]
    before = scheduler_transitions(client)
    with sabotaged(
        client,
        "import lutbake; lutbake._real = lutbake.__version__; lutbake.__version__ = '0.0.0+other'",
        "import lutbake; lutbake.__version__ = lutbake._real",
        workers=[victim],
    ):
        r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(tmp_path / "o"), "--scheduler", address])
    assert r.exit_code == 2, r.output
    import lutbake

    assert f"worker {victim}: lutbake 0.0.0+other there, {lutbake.__version__} here" in r.output
    assert "No tile ran" in r.output and not (tmp_path / "o").exists()
    assert scheduler_transitions(client) == before  # no task was ever submitted


def test_a_worker_without_lutbake_is_refused_with_a_clear_message(client):
    victim = sorted(client.scheduler_info()["workers"])[-1]
    with sabotaged(
        client,
        # every lutbake module hidden (the probe imports lutbake.runtime.cluster), then restored
        "import sys; sys._lutbake = {k: v for k, v in sys.modules.items() if k.split('.')[0] == 'lutbake'}; "
        "sys.modules.update(dict.fromkeys(sys._lutbake))",
        "import sys; sys.modules.update(sys._lutbake)",
        workers=[victim],
    ):
        with pytest.raises(cluster.WorkerRefused) as e:
            cluster.DaskRunner(client, name="test cluster").check_workers()
    assert f"worker {victim}: cannot import lutbake (ModuleNotFoundError" in str(e.value)
    assert "pip install the same lutbake[dask]" in str(e.value)
    cluster.DaskRunner(client).check_workers()  # restored


def test_device_cuda_on_workers_without_a_gpu_is_refused(client):
    if any(i["cuda_devices"] for i in cluster.DaskRunner(client).check_workers().values()):
        pytest.skip("these workers have a CUDA device")
    with pytest.raises(cluster.WorkerRefused, match="none of the 2 workers of test cluster has a CUDA device"):
        cluster.DaskRunner(client, "cuda", name="test cluster").check_workers()


@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupt_cancels_the_futures_and_writes_no_unfinished_table(client, monkeypatch, tmp_path, signum, code):
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        '[[table]]\nname = "small"\nkind = "dfg"\nsize = [8, 4]\nsamples = 48\n\n'
        '[[table]]\nname = "slow"\nkind = "dfg"\nsize = [128, 64]\nsamples = 768\n'
    )
    out = tmp_path / "out"
    runners = []
    real = cluster.session

    def hook(name, start, stop):
        if name == "slow" and not runners[0].interrupted:
            runners[0].interrupted = True
            t0 = time.monotonic()
            while not (out / "small.exr").exists() and time.monotonic() - t0 < 30:
                time.sleep(0.02)
            os.kill(os.getpid(), signum)  # Ctrl-C / SIGTERM arrives while "slow" bakes
            time.sleep(0.5)  # the main thread sets the cancel event

    @contextlib.contextmanager
    def session(*a, **kw):
        with real(*a, **kw) as r:
            r.on_tile, r.interrupted = hook, False
            runners.append(r)
            yield r

    monkeypatch.setattr(cluster, "session", session)
    with deadline():
        r = CliRunner().invoke(
            main,
            [
                "bake",
                str(cfg),
                "--out-dir",
                str(out),
                "--scheduler",
                client.scheduler.address,
                "--report",
                str(tmp_path / "r.json"),
            ],
        )
    assert r.exit_code == code, r.output
    assert "Traceback" not in r.output and "did not finish: slow" in r.output
    assert sorted(p.name for p in out.iterdir()) == ["small.exr"]  # no unfinished table, no temporary file
    assert runners[0].stats.cancelled > 0  # the slow table's remaining tiles were cancelled, not run
    doc = json.loads((tmp_path / "r.json").read_text())
    assert [t["status"] for t in doc["tables"]] == ["baked", "interrupted"]


def test_cli_local_cluster_bakes_the_same_files_without_warp_banners(tmp_path):
    """`lutbake bake ... --scheduler local:1` from a shell: same pixels and headers as a thread bake; the
    worker process prints nothing (no Warp banner, no CUDA-driver warning). One worker: each started worker
    process costs a Warp start; test_cluster_bake_is_bit_identical_to_the_thread_executor runs two."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        '[[table]]\nname = "a"\nkind = "dfg"\nsize = [32, 24]\nsamples = 48\n\n'
        '[[table]]\nname = "b"\nkind = "albedo"\nsize = [16, 8]\nsamples = 48\n'
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    p = subprocess.run(
        [sys.executable, "-m", "lutbake", "bake", str(cfg), "--out-dir", str(tmp_path / "d"), "--scheduler", "local:1"],
        env=env,
        capture_output=True,
        text=True,
        timeout=BAKE_DEADLINE_S,
    )
    assert p.returncode == 0, p.stderr
    assert "Warp" not in p.stdout + p.stderr and p.stderr == "", p.stderr
    assert p.stdout.count("samples/texel") == 2
    assert_same_files(
        {n: read_exr(tmp_path / "d" / f"{n}.exr") for n in "ab"}, thread_bake(load_configs([cfg]), tmp_path / "ref")
    )


def test_no_cluster_starts_when_every_table_is_up_to_date(tmp_path, monkeypatch):
    cfg = tmp_path / "c.toml"
    cfg.write_text('[[table]]\nname = "t"\nkind = "dfg"\nsize = [8, 4]\nsamples = 48\n')
    out = tmp_path / "o"
    assert CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(out)]).exit_code == 0

    def no_session(*a, **kw):
        raise AssertionError("a cluster was started for a batch with nothing to bake")

    monkeypatch.setattr(cluster, "session", no_session)
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(out), "--scheduler", "local:2"])
    assert r.exit_code == 0, r.output
    assert f"skipped {out / 't.exr'} (up to date)" in r.output


# ------------------------------------------------------------------- a port that speaks first but is not Dask

U64 = struct.Struct("<Q")
PROBE_BOUND_S = 5  # a refusal of a foreign service: at once (the subprocess: its imports, ~1.5 s, included)


def dask_handshake(message: dict) -> bytes:
    """One message in Dask's TCP framing (distributed.comm.tcp): byte count, frame count, frame length, frame."""
    import msgpack

    frame = msgpack.packb(message)
    body = U64.pack(1) + U64.pack(len(frame)) + frame
    return U64.pack(len(body)) + body


GOOD_HANDSHAKE = dask_handshake({"compression": None, "python": (3, 11, 7), "pickle-protocol": 5})
FOREIGN = {
    "ssh": b"SSH-2.0-OpenSSH_9.6p1 Ubuntu-3ubuntu13\r\n",
    "garbage": bytes(range(256)) * 4,
    "huge_length": U64.pack(1 << 40) + b"\0" * 64,
    "framed_junk": U64.pack(24) + U64.pack(1) + U64.pack(8) + b"notdask!",
    "framed_other_map": dask_handshake({"op": "hello"}),
    "short_then_closed": U64.pack(58) + b"\1\0",
}


@contextlib.contextmanager
def loopback_server(first: bytes, close: bool = False, tls=None, later: bytes | None = None):
    """A server on 127.0.0.1 only, one thread, gone after the block: each connection gets ``first`` (``later``:
    every connection after the first gets that; through TLS when ``tls``, a server SSLContext), then stays open
    (``close``: is closed)."""
    srv = socket.create_server(("127.0.0.1", 0))
    srv.settimeout(0.1)
    stop, conns = threading.Event(), []

    def serve():
        accepted = 0
        while not stop.is_set():
            try:
                c, _ = srv.accept()
            except OSError:
                continue
            conns.append(c)
            accepted += 1
            try:
                c.settimeout(2)
                c = tls.wrap_socket(c, server_side=True) if tls else c
                conns.append(c)
                c.sendall(first if later is None or accepted == 1 else later)
                if close:
                    c.close()
            except OSError:
                pass

    t = threading.Thread(target=serve, daemon=True)
    t.start()
    try:
        yield srv.getsockname()[1]
    finally:
        stop.set()
        t.join(2)
        for c in conns:
            c.close()
        srv.close()


def cli_error_line(args, seconds=PROBE_BOUND_S) -> str:
    t0 = time.perf_counter()
    r = CliRunner().invoke(main, ["bake", *map(str, args)])
    assert r.exit_code == 2 and (r.exception is None or isinstance(r.exception, SystemExit)), (r.output, r.exception)
    lines = [x for x in r.output.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), r.output
    assert time.perf_counter() - t0 < seconds
    return lines[0]


@pytest.mark.parametrize("what", FOREIGN)
def test_a_port_whose_service_is_not_dask_is_refused_in_one_line(tmp_path, monkeypatch, what):
    """Dask read an SSH banner as a frame length ("Unable to allocate 2.82 EiB"), junk as struct.error: a traceback.
    The probe checks the first frame's framing and handshake map first; CONNECT_TIMEOUT_S bounds the old code."""
    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT_S", 2)
    with loopback_server(FOREIGN[what], close=what == "short_then_closed") as port:
        address = f"tcp://127.0.0.1:{port}"
        line = cli_error_line(["--preset", "default", "--out-dir", tmp_path / "o", "--scheduler", address])
    assert address in line and "not a Dask scheduler" in line and not (tmp_path / "o").exists()
    if what == "ssh":
        assert "SSH-2.0-OpenSSH_9.6p1" in line and "an SSH server" in line


@pytest.mark.parametrize("later", [None, FOREIGN["ssh"]], ids=["ssh", "dask_handshake_then_ssh"])
def test_a_foreign_service_ends_the_process_with_exit_2(tmp_path, later):
    """The process never exited after Dask's traceback (a Client half made: its __del__ waits on a dead loop). The
    second server passes the probe, then sends Dask's own connection an SSH banner: Dask fails, the process ends."""
    with loopback_server(FOREIGN["ssh"] if later is None else GOOD_HANDSHAKE, later=later) as port:
        t0 = time.perf_counter()
        p = subprocess.run(
            [sys.executable, "-m", "lutbake", "bake", "--preset", "default", "--out-dir", str(tmp_path / "o")]
            + ["--scheduler", f"tcp://127.0.0.1:{port}"],
            env={**os.environ, "PYTHONPATH": str(ROOT)},
            capture_output=True,
            text=True,
            timeout=20,
        )
    assert p.returncode == 2 and p.stdout == "" and len(p.stderr.splitlines()) == 1, p.stderr
    assert f"127.0.0.1:{port}" in p.stderr and time.perf_counter() - t0 < 2 * PROBE_BOUND_S
    assert ("not a Dask scheduler" if later is None else "cannot connect: MemoryError") in p.stderr


def test_the_probe_passes_a_dask_scheduler_and_its_handshake(client):
    cluster.probe_scheduler(client.scheduler.address, timeout=5)
    with loopback_server(GOOD_HANDSHAKE) as port:
        cluster.probe_scheduler(f"tcp://127.0.0.1:{port}", timeout=5)


NO_TLS = {f"distributed.comm.tls.{k}": None for k in ("ca-file", "client.cert", "client.key")}


def test_tls_without_dask_tls_settings_is_refused_before_connecting(tmp_path):
    """tls:// without TLS settings: Dask's TypeError ("TLS expects a `ssl_context` argument"), then a hang."""
    import dask

    with dask.config.set(NO_TLS), loopback_server(FOREIGN["ssh"]) as port:
        line = cli_error_line(
            ["--preset", "default", "--out-dir", tmp_path / "o", "--scheduler", f"tls://127.0.0.1:{port}"]
        )
    assert "needs Dask's TLS settings" in line and "ca-file" in line and f"127.0.0.1:{port}" in line


@pytest.fixture
def tls_files(tmp_path):
    """A self-signed EC certificate for 127.0.0.1 (openssl) and its key: the CA, the server's and the client's."""
    import shutil

    if shutil.which("openssl") is None:
        pytest.skip("openssl is needed to make a test certificate")
    cert, key = tmp_path / "c.pem", tmp_path / "k.pem"
    subprocess.run(
        ["openssl", "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes"]
        + ["-keyout", str(key), "-out", str(cert), "-days", "2", "-subj", "/CN=127.0.0.1"],
        check=True,
        capture_output=True,
        timeout=20,
    )
    return cert, key


def test_tls_with_settings_checks_the_first_frame_through_tls(tls_files):
    """With Dask's TLS settings the probe speaks TLS: a Dask handshake inside passes, junk inside is refused, and a
    service that is not TLS at all (an SSH banner) fails the TLS handshake: each one ConfigError, at once."""
    import ssl

    import dask

    from lutbake.errors import ConfigError

    cert, key = map(str, tls_files)
    server = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH, cafile=cert)
    server.load_cert_chain(cert, key)
    server.verify_mode = ssl.CERT_REQUIRED
    settings = {"distributed.comm.tls.ca-file": cert, "distributed.comm.tls.client.cert": cert}
    with dask.config.set({**settings, "distributed.comm.tls.client.key": key}):
        with loopback_server(GOOD_HANDSHAKE, tls=server) as port:
            cluster.probe_scheduler(f"tls://127.0.0.1:{port}", timeout=5)
        for first, tls, why in ((FOREIGN["garbage"], server, "not a Dask scheduler"), (FOREIGN["ssh"], None, "TLS")):
            t0 = time.perf_counter()
            with loopback_server(first, tls=tls) as port, pytest.raises(ConfigError, match=why):
                cluster.probe_scheduler(f"tls://127.0.0.1:{port}", timeout=5)
            assert time.perf_counter() - t0 < PROBE_BOUND_S
