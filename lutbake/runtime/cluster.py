"""Bake on a Dask cluster (``lutbake bake ... --scheduler tcp://HOST:8786`` or ``--scheduler local:N``).

Only tile execution moves. The client (the ``lutbake bake`` process) keeps everything else: config
validation before any work, content hashes and skipping (lutbake.batch), the plan's axes, channels and
provenance, the checks for non-finite values, atomic writes, the report, and SIGINT/SIGTERM (a cancelled
table cancels its futures and writes nothing).

- **A tile task is a pure function of (table spec, tile range)**: ``bake_tile(source, start, stop, device,
  token)``. The client ships how to build the table's plan (lutbake.runtime.plan.PlanSource: the kind's module-level
  ``plan`` function, pickled by reference, bound to the TableSpec, a few hundred bytes of plain data) and the worker
  builds it (``source.build()``, cached per spec and device in each worker process); no kind is looked up by its
  name there, and no closure is pickled. Every texel is integrated alone, so the same tile on any worker, in any
  order, cut in any tile size, gives the same bits: a cluster bake is bit-identical to the local thread executor.
- **Fault tolerance is Dask's**: tile results are gathered by the client as they finish, so a worker
  that dies costs only the tiles it held; the scheduler runs them again elsewhere
  (``distributed.scheduler.allowed-failures`` deaths of one task before it gives up on it; the table
  then fails with the KilledWorker message, the others go on).
- **Refusal before any tile runs**: ``check_workers()`` probes every worker (lutbake.runtime.cluster_probe, sent
  by value so it reaches a worker that cannot import lutbake) and refuses the cluster unless each
  worker has this client's lutbake version and kernel sources digest (the ones in every content hash),
  Warp, numpy and scipy. Every tile carries a token of that identity, so a worker that joins later with
  another one fails its tile with the same message instead of baking different bits.
- **Devices**: ``--device cpu`` runs CLUSTER_TILE_TEXELS-texel tiles on any worker (any cut gives the same
  bits; larger than the thread executor's 512 so that Dask's per-task cost stays small); ``--device cuda``
  runs device-sized tiles (lutbake.runtime.devices) on the workers that have a CUDA device, and refuses a cluster
  with none. A
  table's tiles all run on one kind of device: its bits never depend on which worker took which tile.
- **Local clusters** (``local:N``): a distributed.LocalCluster of N single-threaded worker processes on
  this machine; they ignore SIGINT (Ctrl-C in a terminal reaches the whole process group: the client
  cancels, then closes them), initialise Warp without printing and log nothing of Dask's below CRITICAL.

Python API::

    from lutbake import batch
    from lutbake.runtime import cluster
    with cluster.session("local:2"):            # or "tcp://HOST:8786"
        batch.run(batch.schedule(specs, "outputs"))  # lutbake.bake(...) works the same inside the block
"""

from __future__ import annotations

import contextlib
import logging
import os
import pickle
import queue
import re
import signal
import struct
import threading
import time
import uuid
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError, LutbakeError
from ..limits import BYTES_PER_TEXEL, MAX_TEXELS
from ..textsafe import safe_repr
from .plan import PlanSource, TexelPlan
from .worker import identity, identity_token, init_warp_quietly

SCHEDULER_FORMS = (
    "local:N (a LocalCluster of N worker processes here, N >= 1) or a Dask scheduler address such as tcp://HOST:8786"
)
LOCAL_RE = re.compile(r"^local:(\d+)$")
# scheme://host:port: a host name, an IPv4 address or a bracketed IPv6 address; the port 1-65535 (Dask's 8786
# when left out); checked before anything connects
ADDRESS_RE = re.compile(
    r"^(?P<scheme>tcp|tls|ucx|ws|wss)://(?P<host>\[[0-9A-Fa-f:.]{2,45}\]|[A-Za-z0-9](?:[A-Za-z0-9.-]{0,252}))"
    r"(?::(?P<port>\d{1,5}))?$"
)
DEFAULT_PORT = 8786
MAX_LOCAL_WORKERS = 256
CONNECT_TIMEOUT_S = 30  # the whole handshake with the scheduler, and for its first worker to join
HALF_MADE_CLOSE_S = 2  # closing a Client whose connection failed (it has nothing open: 0.5 ms measured)
REFUSED_HINT = "is a Dask scheduler running there? (dask scheduler --port PORT)"
U64 = struct.Struct("<Q")  # Dask's "Q": the byte counts, frame counts and frame lengths of its TCP framing
HANDSHAKE_MAX_BYTES = 1 << 16  # a Dask handshake is ~60 bytes (three short keys in msgpack); larger is not one
HANDSHAKE_MAX_FRAMES = 16  # it is one frame
HANDSHAKE_KEYS = ("compression", "python")  # distributed.comm.core.Comm.handshake_info (and pickle-protocol)
BANNER_SHOWN = 40  # bytes of a foreign service's first message quoted in the refusal
BANNER_WAIT_S = 0.05  # how long the rest of that message may take to arrive
KNOWN_BANNERS = ((b"SSH-", "an SSH server"), (b"HTTP/", "a web server"), (b"220", "an FTP or mail server"))
TLS_SETTINGS = (
    "distributed.comm.tls.ca-file, .client.cert and .client.key in the Dask config, or the environment variables "
    "DASK_DISTRIBUTED__COMM__TLS__CA_FILE, ...__CLIENT__CERT and ...__CLIENT__KEY"
)
POLL_S = 0.2  # how often a waiting table looks at its cancel event
CLUSTER_TILE_TEXELS = 8192  # CPU tiles of a cluster bake: 16 executor tiles, so Dask's per-task cost stays small
MAX_TABLE_BYTES = MAX_TEXELS * BYTES_PER_TEXEL  # float64 data of the largest table a config allows
PLAN_CACHE_SIZE = 64  # plans kept per worker process (a plan holds its texel grid; a batch has tens of tables)
IDENTITY_KEYS = ("lutbake", "kernel_sources", "warp", "numpy", "scipy")


class WorkerRefused(LutbakeError):
    """A Dask worker cannot bake bit-identical tiles for this client (lutbake missing, another version or
    other kernel sources, another warp / numpy / scipy), or no worker has the device asked for."""


def parse_scheduler(text: str) -> tuple[str, int | str]:
    """``local:N`` -> ("local", N); ``tcp://HOST:PORT`` (tls, ucx, ws, wss) -> ("address", text).
    ConfigError (the CLI exits 2) for anything else."""
    m = LOCAL_RE.match(text)
    if m:
        n = int(m.group(1))
        if not 1 <= n <= MAX_LOCAL_WORKERS:
            raise ConfigError(
                "--scheduler",
                "scheduler",
                text,
                SCHEDULER_FORMS,
                f"a local cluster needs 1 to {MAX_LOCAL_WORKERS} worker processes",
            )
        return "local", n
    m = ADDRESS_RE.match(text)
    if m:
        port = int(m.group("port") or DEFAULT_PORT)
        if not 1 <= port <= 65535:
            raise ConfigError("--scheduler", "scheduler", text, SCHEDULER_FORMS, f"port {port} is not 1-65535")
        if m.group("scheme") == "ucx" and not _ucx_available():
            raise ConfigError(
                "--scheduler",
                "scheduler",
                text,
                SCHEDULER_FORMS,
                "ucx:// needs UCX support for Dask (pip install distributed-ucxx), which is not installed",
            )
        return "address", text
    problem = "is not a scheduler"
    if "://" in text and text.rsplit(":", 1)[-1] == "":
        problem = "has no port after the ':'"
    raise ConfigError("--scheduler", "scheduler", text, SCHEDULER_FORMS, problem)


def check_scheduler(text: str) -> None:
    """What can be checked of ``--scheduler`` before any work: its form (parse_scheduler), and for a tls:// address
    that Dask has TLS settings (tls_context). ConfigError."""
    if parse_scheduler(text)[0] == "address" and text.startswith("tls://"):
        tls_context(text)


def _ucx_available() -> bool:
    import importlib.util

    return any(importlib.util.find_spec(m) is not None for m in ("distributed_ucxx", "ucp", "ucxx"))


def tls_context(address: str):
    """The ssl.SSLContext Dask's TLS settings give a client (distributed.Security), for a ``tls://`` address.
    ConfigError when none are set (Dask itself fails with a TypeError deep in its connector, then hangs) or when
    they cannot be loaded."""
    import ssl

    distributed = _distributed()
    try:
        ctx = distributed.Security().get_connection_args("client")["ssl_context"]
    except (OSError, ssl.SSLError, ValueError, TypeError) as e:
        raise ConfigError(
            "--scheduler", "scheduler", address, None, f"Dask's TLS settings cannot be loaded ({type(e).__name__}: {e})"
        ) from None
    if ctx is None:
        raise ConfigError(
            "--scheduler",
            "scheduler",
            address,
            None,
            f"tls:// needs Dask's TLS settings, and none are set: {TLS_SETTINGS}",
        )
    return ctx


def _recv_exactly(sock, n: int, deadline: float) -> bytes:
    """Up to ``n`` bytes from ``sock`` (fewer when the peer closes); TimeoutError past ``deadline``."""
    data = b""
    while len(data) < n:
        sock.settimeout(max(deadline - time.monotonic(), 0.05))
        chunk = sock.recv(n - len(data))
        if not chunk:
            break
        data += chunk
    return data


def _rest_of_banner(sock) -> bytes:
    """What else of a foreign service's first message has already arrived (up to BANNER_SHOWN bytes, no wait)."""
    try:
        sock.settimeout(BANNER_WAIT_S)
        return sock.recv(BANNER_SHOWN)
    except OSError:  # TimeoutError included: nothing more came
        return b""


def _not_dask(first: bytes, closed: bool = False) -> str:
    """What a service that sent ``first`` instead of a Dask handshake said, and what it looks like."""
    looks = next((f" ({what})" for prefix, what in KNOWN_BANNERS if first.startswith(prefix)), "")
    return f"sent {safe_repr(first[:BANNER_SHOWN])}{looks}{' and closed' if closed else ''}, not a Dask handshake"


def handshake_problem(sock, deadline: float) -> str | None:
    """Why the first message ``sock`` receives is not the handshake a Dask listener writes on accept, or None.
    The framing (distributed.comm.tcp.TCP.read, distributed.protocol.utils.pack_frames_prelude): a uint64 byte
    count, then that many bytes: a uint64 frame count, one uint64 length per frame, the frames; the one frame a
    msgpack map holding HANDSHAKE_KEYS. Checked in bounded memory (HANDSHAKE_MAX_BYTES), where Dask allocates
    whatever the first 8 bytes say (an SSH banner reads as 2.82 EiB). TimeoutError past ``deadline``."""
    head = _recv_exactly(sock, U64.size, deadline)
    if len(head) < U64.size:
        return _not_dask(head, closed=True) if head else "closed the connection without a Dask handshake"
    (total,) = U64.unpack(head)
    if not 2 * U64.size <= total <= HANDSHAKE_MAX_BYTES:
        return _not_dask(head + _rest_of_banner(sock))
    body = _recv_exactly(sock, total, deadline)
    (n_frames,) = U64.unpack_from(body) if len(body) >= U64.size else (0,)
    prelude = U64.size * (1 + n_frames)
    if len(body) < total or not 1 <= n_frames <= HANDSHAKE_MAX_FRAMES or prelude > total:
        return _not_dask(head + body, closed=len(body) < total)
    lengths = struct.unpack_from(f"<{n_frames}Q", body, U64.size)
    if prelude + sum(lengths) != total:
        return _not_dask(head + body)
    try:
        import msgpack  # a dependency of distributed

        message = msgpack.unpackb(body[prelude : prelude + lengths[0]])
    except Exception:  # any malformed msgpack (ExtraData, FormatError, ValueError, ...)
        return _not_dask(head + body)
    if not isinstance(message, dict) or not all(k in message for k in HANDSHAKE_KEYS):
        return _not_dask(head + body)
    return None


def probe_scheduler(address: str, timeout: float | None = None) -> None:
    """Fail fast and bounded before Dask connects: a refused port fails at once, an unreachable host after
    ``timeout`` seconds, and (tcp://, tls://) a port whose first message is not the handshake a Dask scheduler
    sends on accept (distributed.comm.core: the listener writes its handshake first; handshake_problem) at once,
    or after ``timeout`` when it sends nothing. tls:// without Dask's TLS settings is refused before connecting.
    ConfigError, naming the address."""
    import socket
    import ssl

    timeout = CONNECT_TIMEOUT_S if timeout is None else timeout
    m = ADDRESS_RE.match(address)
    if m is None or m.group("scheme") == "ucx":
        return
    scheme, host, port = m.group("scheme"), m.group("host").strip("[]"), int(m.group("port") or DEFAULT_PORT)
    ctx = tls_context(address) if scheme == "tls" else None
    deadline = time.monotonic() + timeout

    def fail(msg):
        raise ConfigError("--scheduler", "scheduler", address, None, msg)

    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except ConnectionRefusedError:
        fail(f"cannot connect: connection refused by {host}:{port}; {REFUSED_HINT}")
    except TimeoutError:
        fail(f"cannot connect: no answer from {host}:{port} within {timeout:g} s")
    except OSError as e:
        fail(f"cannot connect to {host}:{port}: {e.strerror or e}")
    with contextlib.ExitStack() as stack:
        stack.enter_context(sock)
        if scheme not in ("tcp", "tls"):  # websockets: the client speaks first; Dask's timeout bounds them
            return
        try:
            if ctx is not None:
                sock.settimeout(max(deadline - time.monotonic(), 0.05))
                sock = stack.enter_context(ctx.wrap_socket(sock, server_hostname=host))
            problem = handshake_problem(sock, deadline)
        except TimeoutError:
            fail(
                f"{host}:{port} accepted the connection but sent no Dask handshake within {timeout:g} s "
                f"(not a Dask scheduler?)"
            )
        except ssl.SSLError as e:
            fail(f"the TLS handshake with {host}:{port} failed ({e.reason or e}): not a Dask TLS scheduler?")
        except OSError as e:
            fail(f"cannot connect to {host}:{port}: {e.strerror or e}")
        if problem:
            fail(f"{host}:{port} is not a Dask scheduler: it {problem}; {REFUSED_HINT}")


# ---------------------------------------------------------------------------------------------- worker side

_WORKER_LOCK = threading.Lock()
_PLANS: OrderedDict = OrderedDict()
_TOKEN: str | None = None


def _check_token(expect: str) -> None:
    global _TOKEN
    if _TOKEN is None:
        _TOKEN = identity_token(identity())
    if _TOKEN != expect:
        raise WorkerRefused(
            f"worker process {os.getpid()} has lutbake {identity()} and cannot bake bit-identical "
            "tiles for this client; install the client's lutbake, warp, numpy and scipy there"
        )


def worker_plan(source: PlanSource, device: str) -> TexelPlan:
    """The plan ``source`` builds, in this worker process built and its kernels loaded for ``device`` once."""
    key = (source.key, device)
    with _WORKER_LOCK:
        plan = _PLANS.get(key)
        if plan is None:
            plan = source.build()
            plan.prepare(device)
            _PLANS[key] = plan
            while len(_PLANS) > PLAN_CACHE_SIZE:
                _PLANS.popitem(last=False)
        else:
            _PLANS.move_to_end(key)
    return plan


def bake_tile(source: PlanSource, start: int, stop: int, device: str, token: str) -> tuple[np.ndarray, float]:
    """The Dask task: float64 values of texels [start, stop) of ``source``'s table (row-major, (stop - start,
    channels)) and the CPU seconds of this thread while they ran (a Warp CPU launch runs in the calling
    thread, so this is the tile's compute time whatever else loads the host)."""
    init_warp_quietly()
    _check_token(token)
    plan = worker_plan(source, device)
    t0 = time.thread_time()
    data = plan.run_tile(start, stop, device)
    return data, time.thread_time() - t0


def estimate_error_task(source: PlanSource, data: np.ndarray, device: str, token: str) -> tuple:
    """The Dask task of the plan's error estimate (it runs kernels, so it runs where the tiles ran)."""
    init_warp_quietly()
    _check_token(token)
    return worker_plan(source, device).error_estimate(data, device)


def setup_local_worker() -> None:
    """Registered on LocalCluster workers (now and after a restart): ignore SIGINT, initialise Warp, and keep
    Dask's own log lines out of the user's terminal: a local worker shares it, the client reports every failed tile
    itself, and closing the cluster can race a worker's heartbeat into an ERROR traceback (seen once in four CI
    runs: "Failed to communicate with scheduler during heartbeat")."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    for name in [n for n in logging.root.manager.loggerDict if n.startswith("distributed.")] + ["distributed"]:
        logging.getLogger(name).setLevel(logging.CRITICAL)
    init_warp_quietly()


# ---------------------------------------------------------------------------------------------- client side


@dataclass
class Stats:
    """What a runner moved and ran, for ``make bench`` and the tests."""

    tiles: int = 0
    bytes_to_workers: int = 0  # pickled task arguments (plan source, range, device, token)
    bytes_from_workers: int = 0  # tile results (float64 arrays)
    bytes_estimate_inputs: int = 0  # baked tables shipped to a worker for their error estimate
    worker_seconds: float = 0.0  # the tiles' CPU time on the workers, summed
    tile_seconds: list = field(default_factory=list)  # (table, texels, CPU seconds) per tile
    cancelled: int = 0  # tiles cancelled before their result arrived (an interrupt, a failed table)
    lock: threading.Lock = field(default_factory=threading.Lock, repr=False)


class DaskRunner:
    """Runs tables' tiles on the workers of a distributed.Client (see the module docstring)."""

    def __init__(self, client, device: str = "cpu", name: str = ""):
        self.client = client
        self.device = device
        self.name = name or str(getattr(client, "scheduler", "")) or "the Dask cluster"
        self.token: str | None = None
        self.workers: dict[str, dict] = {}
        self.targets: list[str] | None = None  # workers that run this device's tiles (None: any)
        self.cuda_free_bytes: int | None = None
        self.stats = Stats()
        self.tables = 0  # tables submitted: a later table's tiles get a lower Dask priority
        self.on_tile = None  # called in the client as on_tile(table name, start, stop) when a tile arrives

    def check_workers(self) -> dict[str, dict]:
        """Probe every worker; raise WorkerRefused unless all can bake this client's bits (and, for
        ``cuda``, at least one has a GPU). Runs no tile."""
        import cloudpickle

        from . import cluster_probe

        cloudpickle.register_pickle_by_value(cluster_probe)
        infos = self.client.run(cluster_probe.probe, on_error="return")
        here = identity()
        problems = []
        for addr, info in sorted(infos.items()):
            if isinstance(info, BaseException):
                problems.append(f"worker {addr}: the probe failed ({type(info).__name__}: {info})")
            elif "error" in info:
                problems.append(f"worker {addr}: {info['error']}")
            else:
                diff = [f"{k} {info.get(k)} there, {here[k]} here" for k in IDENTITY_KEYS if info.get(k) != here[k]]
                if diff:
                    problems.append(f"worker {addr}: " + "; ".join(diff))
        if not infos:
            problems.append("no worker is connected")
        if problems:
            raise WorkerRefused(
                f"refusing the workers of {self.name}: "
                + " | ".join(problems)
                + ". Every worker needs this client's lutbake (same version and kernel sources), warp, "
                "numpy and scipy: pip install the same lutbake[dask] there and restart the worker. "
                "No tile ran."
            )
        self.workers = infos
        self.token = identity_token(here)
        if self.device.startswith("cuda"):
            gpus = sorted(a for a, i in infos.items() if i["cuda_devices"] > 0)
            if not gpus:
                raise WorkerRefused(
                    f"--device cuda: none of the {len(infos)} workers of {self.name} has a CUDA device "
                    "(Warp reports 0 on each); bake with --device cpu, or start workers on GPU hosts. "
                    "No tile ran."
                )
            self.targets = gpus
            self.cuda_free_bytes = min(infos[a]["cuda_free_bytes"] for a in gpus)
        return infos

    def _submit(self, fn, *args, key: str, priority: int = 0):
        return self.client.submit(
            fn, *args, key=key, workers=self.targets, allow_other_workers=False, pure=False, priority=priority
        )

    def execute(
        self,
        source: PlanSource,
        plan: TexelPlan,
        device: str,
        progress=None,
        label: str = "",
        cancel: threading.Event | None = None,
    ) -> np.ndarray:
        """lutbake.runtime.executor.execute_tiles() on the cluster: float64 (n_texels, plan.tile_width)
        of ``source``'s table, its ``plan`` built on this client (``progress``: an executor.Progress factory, updated
        in the calling thread as tiles arrive)."""
        from .devices import plan_tile_texels
        from .executor import Cancelled, tiles

        if device != self.device:
            raise ValueError(f"this runner bakes on {self.device!r}, not {device!r}")
        cuda = device.startswith("cuda")
        parts = tiles(
            plan.n_texels, plan_tile_texels(plan, device, self.cuda_free_bytes) if cuda else CLUSTER_TILE_TEXELS
        )
        prefix = f"lutbake-{source.name}-{uuid.uuid4().hex[:8]}-{device}"
        with self.stats.lock:
            self.tables += 1
            priority = -self.tables  # tables in submission order: each worker's plan cache stays warm
        futures = {}
        for s, e in parts:
            futures[
                self._submit(bake_tile, source, s, e, device, self.token, key=f"{prefix}-{s}-{e}", priority=priority)
            ] = (s, e)
        sent = len(pickle.dumps((source, 0, plan.n_texels, device, self.token), protocol=5))
        out = np.empty((plan.n_texels, plan.tile_width), dtype=np.float64)
        pending = set(futures)
        finished: queue.Queue = queue.Queue()
        for f in futures:
            f.add_done_callback(finished.put)
        update = progress(label, plan.n_texels, plan.cost) if progress is not None else None
        try:
            while pending:
                if cancel is not None and cancel.is_set():
                    raise Cancelled(label)
                try:
                    f = finished.get(timeout=POLL_S)
                except queue.Empty:
                    continue
                if f not in pending:
                    continue
                pending.discard(f)
                s, e = futures[f]
                data, seconds = f.result()  # a task's exception (a kernel error, KilledWorker) raises here
                out[s:e] = data
                f.release()
                with self.stats.lock:
                    self.stats.tiles += 1
                    self.stats.bytes_to_workers += sent
                    self.stats.bytes_from_workers += data.nbytes
                    self.stats.worker_seconds += seconds
                    self.stats.tile_seconds.append((source.name, e - s, seconds))
                if update is not None:
                    update(e - s)
                if self.on_tile is not None:
                    self.on_tile(source.name, s, e)
        finally:
            if pending:  # cancelled or failed: no tile of this table runs any more
                self.client.cancel(list(pending))
                with self.stats.lock:
                    self.stats.cancelled += len(pending)
        return out

    def estimate_error(self, source: PlanSource, data: np.ndarray, device: str) -> tuple:
        key = f"lutbake-{source.name}-{uuid.uuid4().hex[:8]}-{device}-error-estimate"
        import dask

        # the table travels inside the task (not scattered to one worker, whose death would lose it): the task
        # can then run again elsewhere like a tile; a 1024^2 table is 16 MiB, above Dask's warning threshold
        with dask.config.set({"distributed.admin.large-graph-warning-threshold": MAX_TABLE_BYTES}):
            fut = self._submit(estimate_error_task, source, data, device, self.token, key=key, priority=1)
        with self.stats.lock:
            self.stats.bytes_estimate_inputs += data.nbytes
        return fut.result()


def _distributed():
    try:
        import distributed
    except ImportError:
        raise ConfigError(
            "--scheduler", "scheduler", None, None, "needs Dask's distributed package: pip install 'lutbake[dask]'"
        ) from None
    return distributed


def _half_made_clients(error: BaseException, client_type) -> list:
    """The Clients whose constructor raised ``error``: the ``self`` of its traceback's frames."""
    import traceback

    found: list = []
    for frame, _ in traceback.walk_tb(error.__traceback__):
        obj = frame.f_locals.get("self")
        if isinstance(obj, client_type) and not any(obj is f for f in found):
            found.append(obj)
    return found


def _connect(distributed, address: str):
    """distributed.Client(address); when Dask fails past the probe, the Client it half made is closed here, while
    its event loop runs: left to its __del__ at exit, it waited forever on a loop already gone (the process printed
    its error and never ended)."""
    try:
        return distributed.Client(address, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except Exception as e:
        for client in _half_made_clients(e, distributed.Client):
            with contextlib.suppress(Exception):
                client.close(timeout=HALF_MADE_CLOSE_S)
            client.status = "closed"  # its __del__ closes nothing more
            with contextlib.suppress(Exception):
                client._loop_runner.stop()  # distributed.utils.LoopRunner: the client's IO-loop thread
        raise


@contextlib.contextmanager
def session(scheduler: str, device: str = "cpu"):
    """Connect to ``scheduler`` (``local:N`` starts a LocalCluster), check its workers, and yield the DaskRunner
    that bakes run their tiles on when given it (lutbake.runtime.executor, ``runner=``); closes what it opened.
    Raises ConfigError (bad form, distributed missing, scheduler unreachable) or WorkerRefused before any tile
    runs."""
    form, where = parse_scheduler(scheduler)
    distributed = _distributed()
    cluster = None
    try:
        if form == "local":
            cluster = distributed.LocalCluster(
                n_workers=where,
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",
                silence_logs=logging.ERROR,
            )
            client = distributed.Client(cluster, set_as_default=False)
        else:
            probe_scheduler(where)  # refused: at once; silent: CONNECT_TIMEOUT_S, not Dask's unbounded handshake
            client = _connect(distributed, where)
    except ConfigError:
        raise
    except Exception as e:  # OSError, TimeoutError, or what Dask raises on a handshake the probe passed
        if cluster is not None:
            cluster.close()
        raise ConfigError(
            "--scheduler", "scheduler", scheduler, None, f"cannot connect: {type(e).__name__}: {e}"
        ) from None
    try:
        try:
            client.wait_for_workers(where if form == "local" else 1, timeout=CONNECT_TIMEOUT_S)
        except TimeoutError:
            raise ConfigError(
                "--scheduler",
                "scheduler",
                scheduler,
                None,
                f"no worker joined within {CONNECT_TIMEOUT_S} s (start one: dask worker {scheduler})",
            ) from None
        runner = DaskRunner(client, device, name=scheduler)
        runner.check_workers()
        if form == "local":
            client.register_worker_callbacks(setup=setup_local_worker)
        yield runner
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
