"""Prefiltered environment: lutbake's exact prefilter (estimator ``auto``: spherical harmonics for the rough mips and
the irradiance cube, the pyramid quadrature for the footprint mip 0) against the importance-sampled prefilter every
peer uses, wall and CPU time, error against a converged reference.

Source: Blender's CC0 ``sunrise.exr`` (Debian blender-data, 1024 x 512, a sun of 33 664), each texel split into
2 x 2 to give the issue's 2048 x 1024 (the same texel-constant function); ``--source`` names another lat-long EXR/HDR.
Output: a 256^2 cube, 9 mips, roughness r = m / 8 (the glTF Sample Viewer / Bevy curve), GGX with n.l weighting,
n = v = r; a 32^2 irradiance cube; and the L2 SH (exact per-texel integrals). Timed: the pyramid, the cube, the
irradiance cube, the SH (their sum is lutbake's time), and the footprint mip 0 alone (the quadrature's share).

Baseline (written here, a Warp kernel): the glTF-IBL-Sampler / cmgen algorithm: Hammersley points, GGX importance
sampling of h (cos^2 theta_h = (1 - u) / (1 + (alpha^2 - 1) u)), l = reflect(-v, h), n = v = r, sum L(l) (n.l) /
sum (n.l) over samples with n.l > 0; the radiance read from the source's box pyramid at the filtered-importance-
sampling level lod = 0.5 log2(Omega_s / Omega_p) + 1 (Krivanek & Colbert 2008; Omega_s = 1 / (N pdf), pdf = D / 4,
Omega_p a level-0 texel's solid angle at the equator), texel-constant, clamped to the pyramid. Mip 0 of both is the
exact area average (lutbake's), so the comparison is of the rough mips.

Error: max and RMS over probe texels (strided, 32 per mip) of |P - P_ref| / P_ref (max over channels), P_ref the
pyramid quadrature (an independent method) at tau / 64, K x 4, order + 2 on those texels. The baseline runs with
filtered importance sampling (as the peers ship it: biased) and without (every sample reads the source: unbiased).
"Equal time": the baseline's sample count whose wall time matches lutbake's; "equal error": the sample count at
which the baseline's RMS error would equal lutbake's, from a / sqrt(N) fitted at 256, 1024, 4096 samples
(meaningful without FIS only).
Run: .venv/bin/python benchmarks/bench_environment.py [--size 256] [--source PATH]
(writes outputs/bench/environment.json)
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import warp as wp  # noqa: E402

from lutbake.environment import curves, latlong, prefilter, sh  # noqa: E402
from lutbake.io.environment import read_latlong  # noqa: E402
from lutbake.runtime.warp_runtime import init_warp  # noqa: E402

OUT = ROOT / "outputs" / "bench"
DEFAULT_SOURCES = (
    Path("/usr/share/blender/datafiles/studiolights/world/sunrise.exr"),
    Path("/tmp/envsrc/x/usr/share/blender/datafiles/studiolights/world/sunrise.exr"),
)
PROBES_PER_MIP = 32
REFERENCE = prefilter.Quality().finer().finer()  # the quadrature at tau / 64, K x 4, order + 2, two sub-texel levels


@wp.func
def radical_inverse(i: int):
    """Van der Corput radical inverse in base 2 (Hammersley's second coordinate)."""
    b = wp.uint32(i)
    b = (b << wp.uint32(16)) | (b >> wp.uint32(16))
    b = ((b & wp.uint32(0x55555555)) << wp.uint32(1)) | ((b & wp.uint32(0xAAAAAAAA)) >> wp.uint32(1))
    b = ((b & wp.uint32(0x33333333)) << wp.uint32(2)) | ((b & wp.uint32(0xCCCCCCCC)) >> wp.uint32(2))
    b = ((b & wp.uint32(0x0F0F0F0F)) << wp.uint32(4)) | ((b & wp.uint32(0xF0F0F0F0)) >> wp.uint32(4))
    b = ((b & wp.uint32(0x00FF00FF)) << wp.uint32(8)) | ((b & wp.uint32(0xFF00FF00)) >> wp.uint32(8))
    return float(b) * 2.3283064365386963e-10


@wp.kernel(enable_backward=False)
def sampled_prefilter(
    dirs: wp.array(dtype=wp.vec3),
    alpha: float,
    n_samples: int,
    mean: wp.array(dtype=wp.vec3d),
    heights: wp.array(dtype=wp.int32),
    offsets: wp.array(dtype=wp.int32),
    levels: int,
    omega_p: float,
    fis: int,
    out: wp.array(dtype=wp.vec3),
):
    t = wp.tid()
    n = dirs[t]
    up = wp.vec3(0.0, 1.0, 0.0)
    if wp.abs(n[1]) > 0.999:
        up = wp.vec3(1.0, 0.0, 0.0)
    tx = wp.normalize(wp.cross(up, n))
    ty = wp.cross(n, tx)
    acc = wp.vec3(0.0)
    wsum = wp.float32(0.0)  # dynamic (a literal is a constant to Warp)
    a2 = alpha * alpha
    for i in range(n_samples):
        u = (float(i) + 0.5) / float(n_samples)
        v = radical_inverse(i)
        cos2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u)
        ct = wp.sqrt(cos2)
        st = wp.sqrt(wp.max(0.0, 1.0 - cos2))
        phi = 2.0 * wp.pi * v
        h = tx * (st * wp.cos(phi)) + ty * (st * wp.sin(phi)) + n * ct
        l = 2.0 * wp.dot(n, h) * h - n
        nl = wp.dot(n, l)
        if nl > 0.0:
            d = a2 / (wp.pi * (cos2 * (a2 - 1.0) + 1.0) * (cos2 * (a2 - 1.0) + 1.0))
            pdf = d * 0.25
            omega_s = 1.0 / (float(n_samples) * pdf)
            lod = wp.clamp(0.5 * wp.log2(omega_s / omega_p) + 1.0, 0.0, float(levels - 1))
            k = int(lod) * fis
            hk = heights[k]
            theta = wp.acos(wp.clamp(l[1], -1.0, 1.0))
            ph = wp.atan2(l[2], l[0])
            row = wp.clamp(int(theta / wp.pi * float(hk)), 0, hk - 1)
            col = wp.clamp(int((ph + wp.pi) / (2.0 * wp.pi) * float(2 * hk)), 0, 2 * hk - 1)
            L = mean[offsets[k] + row * 2 * hk + col]
            acc += wp.vec3(float(L[0]), float(L[1]), float(L[2])) * nl
            wsum += nl
    out[t] = acc / wsum


def sampled(pyr, dirs: np.ndarray, alpha: float, n_samples: int, fis: bool) -> np.ndarray:
    omega_p = 4 * math.pi / (2 * int(pyr.heights[0]) ** 2)
    out = wp.zeros(len(dirs), dtype=wp.vec3, device="cpu")
    wp.launch(
        sampled_prefilter,
        len(dirs),
        [
            wp.array(dirs.astype(np.float32), dtype=wp.vec3, device="cpu"),
            float(alpha),
            int(n_samples),
            wp.array(pyr.mean, dtype=wp.vec3d, device="cpu"),
            wp.array(pyr.heights, dtype=wp.int32, device="cpu"),
            wp.array(pyr.offsets, dtype=wp.int32, device="cpu"),
            pyr.levels,
            omega_p,
            int(fis),
            out,
        ],
        device="cpu",
    )
    return out.numpy().astype(np.float64)


def sampled_cube(pyr, texels, n_samples: int, fis: bool = True) -> tuple[list[np.ndarray], float, float]:
    """The baseline's rough mips (mip 0 not computed), wall and CPU seconds; ``fis``: filtered importance sampling
    (else every sample reads the source, level 0: unbiased, noisier)."""
    t0, c0 = time.perf_counter(), time.process_time()
    mips = [None]
    for m in range(1, len(texels.sizes)):
        s, e = texels.offsets[m], texels.offsets[m + 1]
        mips.append(sampled(pyr, texels.dirs[s:e], texels.alphas[m], n_samples, fis))
    return mips, time.perf_counter() - t0, time.process_time() - c0


def errors(values: dict[int, np.ndarray], ref: dict[int, np.ndarray]) -> dict:
    per_mip = {}
    for m, r in ref.items():
        e = np.max(np.abs(values[m] - r) / r, axis=1)
        per_mip[m] = {"max": float(e.max()), "rms": float(np.sqrt(np.mean(e * e)))}
    all_rms = math.sqrt(np.mean([v["rms"] ** 2 for v in per_mip.values()]))
    return {"per_mip": per_mip, "rms": all_rms, "max": max(v["max"] for v in per_mip.values())}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--source", type=Path, default=None)
    parser.add_argument("--tau", type=float, default=prefilter.Quality().tau)  # the footprint mip's quadrature
    args = parser.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    source = args.source or next((p for p in DEFAULT_SOURCES if p.is_file()), None)
    if source is None:
        result = {"skipped": "no source: apt-get install blender-data (or pass --source a lat-long EXR/HDR)"}
        (OUT / "environment.json").write_text(json.dumps(result, indent=1) + "\n")
        print(result["skipped"])
        return
    init_warp()
    env = read_latlong(source)
    image = env.image
    if image.shape[0] < 1024:  # the 2048 x 1024: each texel split in 2 x 2 (the same function)
        f = 1024 // image.shape[0]
        image = np.repeat(np.repeat(image, f, axis=0), f, axis=1)
    mips = int(math.log2(args.size)) + 1
    rough = [curves.CURVES["linear"].roughness(m, mips) for m in range(mips)]
    quality = prefilter.Quality(tau=args.tau)

    def timed(fn):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        return out, time.perf_counter() - t, time.process_time() - c

    pyr, t_pyr, c_pyr = timed(lambda: latlong.pyramid(image))
    baked, t_cube, c_cube = timed(lambda: prefilter.bake_cube(pyr, args.size, rough, quality=quality, estimate=False))
    irr, t_irr, c_irr = timed(lambda: prefilter.bake_cube(pyr, 32, [1.0], "cosine", quality=quality, estimate=False))
    coefficients, t_sh, c_sh = timed(lambda: sh.project(image))
    wall = t_pyr + t_cube + t_irr + t_sh
    cpu = c_pyr + c_cube + c_irr + c_sh
    # the footprint mip 0 alone (the quadrature's share of the cube)
    _, t_mip0, c_mip0 = timed(lambda: prefilter.bake_cube(pyr, args.size, [0.0], quality=quality, estimate=False))

    texels = prefilter.cube_texels(args.size, baked.lobes, baked.alphas)
    probes = {}
    for m in range(1, mips):
        s, e = texels.offsets[m], texels.offsets[m + 1]
        probes[m] = np.arange(s, e, max(1, (e - s) // PROBES_PER_MIP))
    ref_quality = REFERENCE
    ref = {}
    for m, idx in probes.items():
        o = prefilter.mip_values(pyr, texels, m, idx, ref_quality, "cpu")
        ref[m] = o[:, :3] / o[:, 3:4]
    flat = np.concatenate([x.reshape(-1, 3) for x in baked.mips])
    exact_err = errors({m: flat[idx] for m, idx in probes.items()}, ref)
    estimate = prefilter.error_estimates(pyr, texels, np.concatenate([flat, np.ones((len(flat), 2))], 1), quality)

    def run(n: int, fis: bool) -> dict:
        mips_s, w, c = sampled_cube(pyr, texels, n, fis)
        vals = {m: mips_s[m][idx - texels.offsets[m]] for m, idx in probes.items()}
        return {"samples": n, "wall_s": w, "cpu_s": c, "error": errors(vals, ref)}

    sampled_cube(pyr, texels, 1)  # compile the baseline's kernel outside the timings
    baselines = {}
    for fis in (True, False):
        runs = {n: run(n, fis) for n in (256, 1024, 4096)}
        for n, r in runs.items():
            print(f"sampled fis={fis} N={n}: wall {r['wall_s']:.1f} s, rms {r['error']['rms']:.3g}")
        t_per_sample = runs[4096]["wall_s"] / 4096
        equal_time = run(max(1, int(wall / t_per_sample)), fis)
        # RMS ~ a / sqrt(N) (meaningful where the estimator is unbiased: fis = False); fitted on the three runs
        a = float(np.mean([r["error"]["rms"] * math.sqrt(n) for n, r in runs.items()]))
        equal_error_n = (a / exact_err["rms"]) ** 2
        baselines["fis" if fis else "no_fis"] = {
            "runs": {str(n): r for n, r in runs.items()},
            "equal_time": equal_time,
            "error_ratio_at_equal_time": equal_time["error"]["rms"] / exact_err["rms"],
            "equal_error_samples_projected": equal_error_n,
            "equal_error_wall_s_projected": equal_error_n * t_per_sample,
        }
    result = {
        "source": f"{source} ({env.image.shape[1]} x {env.image.shape[0]}, sha256 {env.sha256})",
        "source_as_baked": f"{image.shape[1]} x {image.shape[0]}",
        "cube": f"{args.size}^2, {mips} mips, r = m / {mips - 1}, ggx_nl, n = v = r",
        "machine_cores": 2,
        "lutbake": {
            "wall_s": wall,
            "cpu_s": cpu,
            "pyramid": {"wall_s": t_pyr, "cpu_s": c_pyr},
            "cube": {"wall_s": t_cube, "cpu_s": c_cube, "methods": baked.methods, "lmax": baked.lmax},
            "mip0_footprint_alone": {"wall_s": t_mip0, "cpu_s": c_mip0},
            "irradiance_32": {"wall_s": t_irr, "cpu_s": c_irr, "methods": irr.methods},
            "sh": {"wall_s": t_sh, "cpu_s": c_sh},
            "quality": {"tau": quality.tau, "k_geo": quality.k_geo, "order": quality.order},
            "error": exact_err,
            "error_estimate_per_mip": estimate,
            "sh_coefficient_0": coefficients[0].tolist(),
        },
        "reference": f"the pyramid quadrature at tau {REFERENCE.tau:g}, K {REFERENCE.k_geo:g}, order "
        f"{REFERENCE.order}, {REFERENCE.extra_levels} extra sub-texel levels, on {PROBES_PER_MIP} strided probe "
        "texels per rough mip",
        "sampled": baselines,
    }
    (OUT / "environment.json").write_text(json.dumps(result, indent=1) + "\n")
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
