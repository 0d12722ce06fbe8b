"""Tiles per device (lutbake.runtime.devices): 512-texel CPU tiles, whole tables or device-sized tiles on CUDA.

The sizing logic and the executor's use of it are tested here on the CPU (a fake plan, a stated free
memory). The CUDA bake itself is compared with the CPU bake only where Warp finds a CUDA device; on a
machine without one that test is skipped with the reason."""

import numpy as np
import pytest
import warp as wp

from lutbake.api import bake_table
from lutbake.axes import Axis
from lutbake.config import validate_table
from lutbake.runtime import devices, executor
from lutbake.runtime.devices import CPU_TILE_TEXELS, CUDA_MEMORY_FRACTION, CUDA_TILE_MAX_EVALS, tile_texels
from lutbake.runtime.plan import TexelPlan

GIB = 1 << 30
# A CUDA bake evaluates the same float32 integrand with the GPU's float32 functions and FMA contraction and
# accumulates in float64: per-texel differences are expected at float32 rounding of each sample averaged
# over the samples (~1e-7 for values <= 1). Bounds, not measurements: see docs/cluster.md.
CUDA_VS_CPU_ATOL = 1e-6
CUDA_VS_CPU_RTOL = 1e-5


def test_cpu_tiles_are_512_texels_whatever_the_table():
    for n, evals in [(1, 1), (100, 1e6), (1 << 20, 432), (1 << 26, 1e5)]:
        assert tile_texels(n, evals, 2, "cpu") == CPU_TILE_TEXELS


def test_a_cuda_tile_is_the_whole_table_when_it_fits():
    assert tile_texels(128 * 128, 432, 2, "cuda", free_bytes=8 * GIB) == 128 * 128
    assert tile_texels(1024 * 1024, 432, 2, "cuda", free_bytes=80 * GIB) == 1024 * 1024
    assert tile_texels(100, 1e6, 1, "cuda:1", free_bytes=GIB) == 100


def test_a_cuda_tile_is_capped_by_evaluations_in_whole_cpu_tiles():
    n, evals = 64 * 64**3, 10_000  # BTF 64 sigma x 64^3 at ~1e4 evaluations per texel
    size = tile_texels(n, evals, 1, "cuda", free_bytes=80 * GIB)
    assert size % CPU_TILE_TEXELS == 0 and CPU_TILE_TEXELS <= size < n
    assert size * evals <= CUDA_TILE_MAX_EVALS < (size + CPU_TILE_TEXELS) * evals


def test_a_cuda_tile_is_capped_by_device_memory():
    free = 64 << 20  # 64 MiB free
    size = tile_texels(1 << 24, 1, 4, "cuda", free_bytes=free)
    per_texel = 8 * 4 + devices.BYTES_PER_TEXEL_INPUTS
    assert size % CPU_TILE_TEXELS == 0 and size * per_texel <= free * CUDA_MEMORY_FRACTION
    assert (size + CPU_TILE_TEXELS) * per_texel > free * CUDA_MEMORY_FRACTION


def test_a_cuda_tile_is_never_below_one_cpu_tile():
    assert tile_texels(1 << 20, 1e12, 2, "cuda", free_bytes=GIB) == CPU_TILE_TEXELS


def fake_plan(n_texels: int, evals: int, calls: list) -> TexelPlan:
    def run_tile(start, stop, device):
        calls.append((start, stop, device))
        return np.arange(start, stop, dtype=np.float64)[:, None]

    return TexelPlan(
        axes=[Axis("NoV", "x", n_texels)],
        channels={"c": ""},
        reconstruction="",
        n_texels=n_texels,
        n_channels=1,
        run_tile=run_tile,
        prepare=lambda d: None,
        samples=evals,
        estimator="fake",
        terms={},
        cost=float(n_texels * evals),
    )


def test_the_executor_launches_device_sized_tiles_on_cuda(monkeypatch):
    monkeypatch.setattr(devices, "cuda_free_bytes", lambda device="cuda": 80 * GIB)
    n = 5000
    for device, expect in [("cpu", executor.tiles(n, CPU_TILE_TEXELS)), ("cuda", [(0, n)])]:
        calls = []
        out = executor.execute(fake_plan(n, 432, calls), workers=2, device=device)
        assert sorted(calls) == [(s, e, device) for s, e in expect]
        np.testing.assert_array_equal(out.ravel(), np.arange(n))
    big = CUDA_TILE_MAX_EVALS // 1000 + 1  # texels over one launch's evaluation budget at 1000 evaluations each
    calls = []
    executor.execute(fake_plan(big, 1000, calls), device="cuda")
    assert len(calls) == 2 and calls[0][1] % CPU_TILE_TEXELS == 0 and calls[-1][1] == big


CUDA_CASES = {
    "dfg_gl": {"kind": "dfg", "size": [64, 64]},
    "dfg_vndf": {"kind": "dfg", "size": [64, 64], "estimator": "sobol_vndf", "samples": 1024},
    "btf": {"kind": "btf", "size": [8, 8], "phi_size": 8, "sigma_size": 4},
    "diffuse": {"kind": "diffuse", "size": [32, 32]},
}


@pytest.mark.parametrize("name", sorted(CUDA_CASES))
def test_cuda_bake_equals_the_cpu_bake_within_float32_evaluation(name):
    if wp.get_cuda_device_count() == 0:  # asked here, not at collection: Warp initialises after conftest quiets it
        pytest.skip("no CUDA device (wp.get_cuda_device_count() == 0): the CUDA bake is untested on this machine")
    spec = validate_table({"name": name, **CUDA_CASES[name]}, "<test>", 0)
    cpu = bake_table(spec, workers=2, device="cpu")[0].data.astype(np.float64)
    gpu = bake_table(spec, device="cuda")[0].data.astype(np.float64)
    diff = np.abs(gpu - cpu)
    rel = np.max(diff / np.maximum(np.abs(cpu), 1e-30))
    print(f"{name}: max |cuda - cpu| = {diff.max():.3e}, max relative = {rel:.3e}")
    assert np.all(np.isfinite(gpu))
    np.testing.assert_allclose(gpu, cpu, rtol=CUDA_VS_CPU_RTOL, atol=CUDA_VS_CPU_ATOL)
