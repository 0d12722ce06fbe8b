"""Tile sizes per Warp device: 512-texel tiles on the CPU, whole tables (or device-sized tiles) on CUDA.

A tile is a contiguous range of texels [start, stop) and every texel is integrated alone (one Warp
thread), so how a table is cut changes no bit of a CPU bake; the size only trades launch overhead
against parallelism:

- ``cpu``: CPU_TILE_TEXELS. One Warp CPU launch runs on one core, so a table is cut into many small
  tiles that threads (lutbake.runtime.executor) or Dask workers (lutbake.runtime.cluster) share.
- ``cuda``: one launch covers as many texels as the device can take at once: the whole table, unless
  its integrand evaluations exceed CUDA_TILE_MAX_EVALS (a launch of a few seconds at most, well under a
  desktop GPU's display watchdog, and several tiles of a huge table for a cluster's GPUs to share) or
  its arrays exceed CUDA_MEMORY_FRACTION of the device's free memory. Tiles stay whole multiples of
  CPU_TILE_TEXELS, so a CUDA tile is a union of CPU tiles.

A CUDA bake is not bit-identical to a CPU bake: both evaluate the integrand in float32 and accumulate
in float64, but the GPU's float32 transcendental functions, fused multiply-adds and code generation
differ in the last bits of each sample (docs/cluster.md says how that difference is measured).
"""

from __future__ import annotations

CPU_TILE_TEXELS = 512  # texels per tile on the CPU (lutbake.runtime.executor.TILE_TEXELS)

CUDA_TILE_MAX_EVALS = 1 << 34  # integrand evaluations in one CUDA launch (~1.7e10: about a second on an H100)
CUDA_MEMORY_FRACTION = 0.25  # of the device's free memory, for one launch's per-texel arrays
BYTES_PER_TEXEL_INPUTS = 64  # per-texel kernel inputs (directions, NoV, alpha, f0, order): a generous bound


def tile_texels(
    n_texels: int, evals_per_texel: float, n_channels: int, device: str = "cpu", free_bytes: int | None = None
) -> int:
    """Texels per tile (launch) of a table of ``n_texels`` on ``device``.

    ``evals_per_texel``: integrand evaluations per texel (TexelPlan.cost / n_texels);
    ``free_bytes``: the CUDA device's free memory (default: asked of Warp). Always >= 1; a CPU tile is
    CPU_TILE_TEXELS; a CUDA tile is the whole table or a multiple of CPU_TILE_TEXELS."""
    if n_texels <= 0:
        return 1
    if not str(device).startswith("cuda"):
        return CPU_TILE_TEXELS
    if free_bytes is None:
        free_bytes = cuda_free_bytes(device)
    by_evals = int(CUDA_TILE_MAX_EVALS // max(1.0, float(evals_per_texel)))
    by_memory = int(free_bytes * CUDA_MEMORY_FRACTION) // (8 * n_channels + BYTES_PER_TEXEL_INPUTS)
    size = min(by_evals, by_memory)
    if size >= n_texels:
        return n_texels
    return max(CPU_TILE_TEXELS, size - size % CPU_TILE_TEXELS)


def plan_tile_texels(plan, device: str = "cpu", free_bytes: int | None = None) -> int:
    """tile_texels() of a lutbake.runtime.plan.TexelPlan (on the CPU its own tile_texels where it has one)."""
    if plan.tile_texels and not str(device).startswith("cuda"):
        return plan.tile_texels
    return tile_texels(plan.n_texels, plan.cost / max(1, plan.n_texels), plan.n_channels, device, free_bytes)


def cuda_free_bytes(device: str = "cuda") -> int:
    import warp as wp

    return int(wp.get_device(device).free_memory)


def cuda_device_count() -> int:
    """CUDA devices Warp can use in this process (0 without a driver or a GPU)."""
    import warp as wp

    return int(wp.get_cuda_device_count())
