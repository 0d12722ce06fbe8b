"""``make bench`` (cluster part): the Dask executor against the thread executor, and a scaling projection.

1. **Overhead.** The batch of ``make luts`` (configs/*.toml and the engine presets) baked with --force on
   the thread executor (every core) and on ``--scheduler local:2`` (a LocalCluster of 2 worker processes,
   its start-up included), alternating, ``--rounds`` times: wall times, their ratio (target <= 1.15 on a
   2-core machine), tiles, and bytes moved per tile (task arguments to the workers, float64 results back,
   error-estimate inputs), and the CPU seconds of all processes (client + workers: a measure of the
   overhead that other load on the machine does not distort). Every file of the Dask bake is compared
   with the thread bake (pixels and every
   lutbake:* attribute).
2. **Scaling on paper** for the largest table of the batch (the 1024^2 glTF DFG, ``lut_ggx``), from what
   the Dask bake measured: W = the CPU seconds of its n tile launches on the workers (thread CPU time, so
   other load on this machine does not inflate it), S = its serial wall time outside the tiles (the
   client's plan, the error-estimate task, the write), C = the client process's CPU seconds (client,
   scheduler, nannies, writes) per tile of the batch (an upper bound on the serial cost of one tile),
   B = bytes per tile over the network (arguments, result, share of the error-estimate input) at an
   assumed 1 Gbit/s. Projected wall on N workers of a running cluster, conservatively additive:
       T(N) = S + C n + B n / BANDWIDTH + W / N,   serial fraction = (T(N) - W / N) / T(N).

Writes outputs/bench/cluster.json and prints a summary.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np
import warp as wp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lutbake import batch  # noqa: E402
from lutbake.config import load_configs, preset_path  # noqa: E402
from lutbake.io.exr import read_exr  # noqa: E402
from lutbake.io.integrity import sidecar_path  # noqa: E402
from lutbake.pipeline import plan_of  # noqa: E402
from lutbake.runtime import cluster  # noqa: E402
from lutbake.runtime.executor import default_workers  # noqa: E402

OUT = ROOT / "outputs" / "bench"
PRESETS = ("filament", "filament-corrected", "gltf", "gltf-charlie", "gltf-sheen-e", "blender-eevee", "unreal")
LARGEST = "lut_ggx"  # the 1024 x 1024 glTF DFG (preset gltf)
BANDWIDTH = 125e6  # bytes/s: an assumed 1 Gbit/s network between client and workers
WORKERS = (1, 8, 64)
TARGET_RATIO = 1.15


class TimedRunner(cluster.DaskRunner):
    """A DaskRunner that also records each table's tile-phase and error-estimate wall times."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.phase: dict[str, float] = {}
        self.estimate: dict[str, float] = {}

    def execute(self, source, plan, device, **kw):
        t0 = time.perf_counter()
        try:
            return super().execute(source, plan, device, **kw)
        finally:
            self.phase[source.name] = time.perf_counter() - t0

    def estimate_error(self, source, data, device):
        t0 = time.perf_counter()
        try:
            return super().estimate_error(source, data, device)
        finally:
            self.estimate[source.name] = time.perf_counter() - t0


WRITES: dict[str, float] = {}


def timed_write(table, *a, **kw):
    t0 = time.perf_counter()
    try:
        return REAL_WRITE(table, *a, **kw)
    finally:
        WRITES[table.name] = time.perf_counter() - t0


REAL_WRITE = batch.write_table
batch.write_table = timed_write  # the batch writes through lutbake.batch.write_table


def specs():
    paths = [preset_path(p) for p in PRESETS] + sorted((ROOT / "configs").glob("*.toml"))
    return load_configs(paths)


def cpu_seconds() -> float:
    """User + system CPU seconds of this process (all its threads); also run on each Dask worker."""
    t = os.times()
    return t.user + t.system


def thread_run(out: Path) -> tuple[float, float, list]:
    t0, c0 = time.perf_counter(), cpu_seconds()
    jobs = batch.schedule(specs(), out, force=True)
    assert batch.run(jobs, default_workers()) is None
    return time.perf_counter() - t0, cpu_seconds() - c0, jobs


def dask_run(out: Path, scheduler: str) -> tuple[float, float, float, list, TimedRunner, float]:
    """Wall, client CPU and workers' CPU seconds (start-up included) of the batch on ``scheduler``."""
    t0, c0 = time.perf_counter(), cpu_seconds()
    jobs = batch.schedule(specs(), out, force=True)
    real = cluster.DaskRunner
    cluster.DaskRunner = TimedRunner  # session() builds its runner from the module attribute
    try:
        with cluster.session(scheduler) as runner:
            started = time.perf_counter() - t0
            assert batch.run(jobs, len(jobs), runner=runner) is None
            cpu_workers = sum(runner.client.run(cpu_seconds).values())
    finally:
        cluster.DaskRunner = real
    return time.perf_counter() - t0, cpu_seconds() - c0, cpu_workers, jobs, runner, started


def identical(a: list, b: list) -> bool:
    same = True
    for ja, jb in zip(a, b):
        assert ja.name == jb.name and ja.status == jb.status == "baked", (ja.name, ja.message, jb.message)
        if ja.path.suffix == ".exr":
            (da, aa), (db, ab) = read_exr(ja.path), read_exr(jb.path)
            # data_hash is the file's own checksum (it covers OpenImageIO's DateTime too): not part of the contract
            same &= bool(np.array_equal(da, db)) and {k: v for k, v in aa.items() if k != "data_hash"} == {
                k: v for k, v in ab.items() if k != "data_hash"
            }
        else:  # npy / png16 / dds / ktx2 / h: the bytes (no timestamps), and the sidecar if any
            same &= ja.path.read_bytes() == jb.path.read_bytes()
            side_a, side_b = sidecar_path(ja.path), sidecar_path(jb.path)
            if side_a.exists():
                same &= side_a.read_bytes() == side_b.read_bytes()
    return same


def main(argv=None):
    import logging

    wp.config.log_level = logging.WARNING  # no banner or module-load lines in the summary
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=1, help="thread / local:2 alternations (default 1)")
    ap.add_argument("--scheduler", default="local:2")
    args = ap.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    rounds = []
    for r in range(args.rounds):
        t_thread, cpu_thread, jobs_t = thread_run(OUT / "cluster_thread")
        t_dask, cpu_client, cpu_workers, jobs_d, runner, started = dask_run(OUT / "cluster_dask", args.scheduler)
        cpu_dask = cpu_client + cpu_workers
        same = identical(jobs_t, jobs_d)
        st = runner.stats
        rounds.append(
            {
                "thread_seconds": t_thread,
                "dask_seconds": t_dask,
                "ratio": t_dask / t_thread,
                "thread_cpu_seconds": cpu_thread,
                "dask_cpu_seconds": cpu_dask,
                "cpu_ratio": cpu_dask / cpu_thread,
                "dask_client_cpu_seconds": cpu_client,
                "dask_workers_cpu_seconds": cpu_workers,
                "load_average_after": os.getloadavg()[0],
                "cluster_start_seconds": started,
                "identical_files": same,
                "tiles": st.tiles,
                "bytes_to_workers_per_tile": st.bytes_to_workers / st.tiles,
                "bytes_from_workers_per_tile": st.bytes_from_workers / st.tiles,
                "bytes_estimate_inputs_per_tile": st.bytes_estimate_inputs / st.tiles,
                "worker_seconds": st.worker_seconds,
            }
        )
        print(
            f"round {r}: thread {t_thread:.1f} s, {args.scheduler} {t_dask:.1f} s (start {started:.1f} s): "
            f"ratio {t_dask / t_thread:.3f}; CPU {cpu_thread:.1f} s vs {cpu_dask:.1f} s (client + workers): "
            f"ratio {cpu_dask / cpu_thread:.3f}; {st.tiles} tiles, {st.bytes_to_workers / st.tiles:.0f} B to and "
            f"{st.bytes_from_workers / st.tiles:.0f} B from the workers per tile "
            f"(+ {st.bytes_estimate_inputs / st.tiles:.0f}"
            f" B of error-estimate inputs); identical files: {same}"
        )
    # the projection, from the last Dask round
    job = next(j for j in jobs_d if j.name == LARGEST)
    tiles = [(n, c) for name, n, c in runner.stats.tile_seconds if name == LARGEST]
    n = len(tiles)
    W = sum(c for _, c in tiles)  # CPU seconds of its tile launches
    t0 = time.perf_counter()
    plan_of(job.spec)
    S_parts = {
        "client_plan": time.perf_counter() - t0,
        "error_estimate_task": runner.estimate[LARGEST],
        "write": WRITES[LARGEST],
    }
    S = sum(S_parts.values())
    C = cpu_client / runner.stats.tiles  # client + scheduler CPU per tile of the batch (an upper bound)
    spec = job.spec
    texels = sum(t for t, _ in tiles)
    n_channels = int(job.shape.split("x")[-1])
    # per tile: its arguments, its float64 result, and its share of the table shipped for the error estimate
    B = runner.stats.bytes_to_workers / runner.stats.tiles + 2 * 8 * n_channels * texels / n
    proj = {}
    for N in WORKERS:
        serial = S + C * n + B * n / BANDWIDTH
        T = serial + W / N
        proj[N] = {"seconds": T, "serial_fraction": serial / T}
    report = {
        "machine": {"cpus": os.cpu_count(), "load_average": os.getloadavg(), "python": platform.python_version()},
        "batch": {"tables": len(jobs_d), "presets": PRESETS, "configs": "configs/*.toml", "scheduler": args.scheduler},
        "rounds": rounds,
        "median_ratio": float(np.median([r["ratio"] for r in rounds])),
        "median_cpu_ratio": float(np.median([r["cpu_ratio"] for r in rounds])),
        "target_ratio": TARGET_RATIO,
        "largest_table": {
            "name": LARGEST,
            "spec": spec.toml(),
            "texels": texels,
            "tiles": n,
            "W_sum_tile_cpu_seconds": W,
            "S_serial_seconds": S,
            "S_parts": S_parts,
            "C_client_scheduler_cpu_seconds_per_tile": C,
            "B_bytes_per_tile": B,
            "bandwidth_assumed_bytes_per_s": BANDWIDTH,
            "projection": proj,
            "model": "T(N) = S + C n + B n / BANDWIDTH + W / N; serial fraction = (T - W/N) / T",
        },
    }
    path = OUT / "cluster.json"
    path.write_text(json.dumps(report, indent=2) + "\n")
    print(
        f"median wall ratio {args.scheduler} / thread: {report['median_ratio']:.3f} (target <= {TARGET_RATIO}); "
        f"CPU-seconds ratio {report['median_cpu_ratio']:.3f}; load average {os.getloadavg()[0]:.1f} on "
        f"{os.cpu_count()} cores"
    )
    print(
        f"{LARGEST}: {n} tiles, W = {W:.1f} CPU s of tile launches ({W / n * 1e3:.1f} ms per tile), S = {S:.2f} s "
        f"serial ({', '.join(f'{k} {v:.2f} s' for k, v in S_parts.items())}), C = {C * 1e3:.2f} ms client + "
        f"scheduler CPU per tile, B = {B / 1024:.1f} KiB per tile"
    )
    for N, p in proj.items():
        print(f"  projected on {N:>2} workers: {p['seconds']:7.2f} s, serial fraction {p['serial_fraction']:.3f}")
    print(path)


if __name__ == "__main__":
    main()
