"""Bake an environment's half of the split sum (Python API; not yet a config kind or a CLI command): the prefiltered
specular cube (one roughness per mip by the engine's curve), the irradiance cube (E / pi) and the L2 SH of a lat-long
EXR/HDR, written as KTX 2.0, DDS or EXR cubes with lutbake's record (lutbake.io.cubemap) and the SH as JSON.

    from lutbake.commands.environment import bake_environment
    bake_environment("studio.exr", "outputs", "studio", engine="bevy")

``ENGINES``: what each engine loads, as data (curve, files, the shader line that samples them).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import __version__
from ..environment import cube, curves, latlong, prefilter, sh
from ..io.atomic import atomic_write_bytes
from ..io.cubemap import write_cube
from ..io.environment import read_latlong


@dataclass(frozen=True)
class EngineIBL:
    """What an engine's image-based lighting loads: the mip curve, the format, and how its shader reads them."""

    name: str
    curve: str
    format: str
    specular_line: str
    diffuse_line: str
    source: str


ENGINES = {
    "bevy": EngineIBL(
        "bevy",
        "linear",
        "ktx2",
        "radiance_level = perceptual_roughness * f32(textureNumLevels(specular) - 1u); "
        "textureSampleLevel(specular, sampler, R, radiance_level)",
        "irradiance = textureSampleLevel(diffuse, sampler, N, 0.0).rgb (E / pi: times diffuse_color)",
        "bevy crates/bevy_pbr/src/light_probe/environment_map.wgsl (EnvironmentMapLight: specular_map, diffuse_map)",
    ),
    "gltf": EngineIBL(
        "gltf",
        "linear",
        "ktx2",
        "lod = roughness * float(u_MipCount - 1); textureLod(u_GGXEnvSampler, reflection, lod)",
        "texture(u_LambertianEnvSampler, n).rgb (E / pi)",
        "glTF Sample Viewer source/Renderer/shaders/ibl.glsl (the lines as issue 48 quotes them)",
    ),
}
EXTENSIONS = {"ktx2": ".ktx2", "dds": ".dds", "exr": ".exr"}


def record(baked: prefilter.Baked, curve: str, lobe: str, source, env, quality: prefilter.Quality) -> dict:
    """The metadata every file of the bake carries."""
    return {
        "kind": "environment_irradiance" if lobe == "cosine" else "environment_specular",
        "lutbake_version": __version__,
        "face_convention": "gl (OpenGL / KTX / Vulkan face table, lutbake.environment.cube): faces +X -X +Y -Y +Z -Z",
        "orientation": cube.ORIENTATIONS["gl"].doc,
        "source": Path(source).name,
        "source_sha256": env.sha256,
        "source_negative_values_zeroed": env.negatives,
        "source_convention": "lat-long, row 0 = +Y, u = 0.5 + atan2(z, x) / 2pi (lutbake.environment.latlong); "
        "texel-constant radiance",
        "split_sum": "n = v = r",
        "weighting": {"ggx_nl": "D_ggx(h) (n.l) (Karis 2013)", "ggx": "D_ggx(h)", "cosine": "(n.l)+: E / pi"}[lobe],
        "mip_curve": f"{curve}: {curves.CURVES[curve].lod}",
        "roughness": baked.roughness,
        "alpha": baked.alphas,
        "lobes": baked.lobes,
        "mip0": "the exact area average of the source over each texel's footprint"
        if baked.lobes[0] == "footprint"
        else baked.lobes[0],
        "error_estimate_per_mip": baked.errors,
        "error_estimate_method": "max relative |P - P_finer| over <= 96 strided probe texels per mip, P_finer at "
        "tau / 8, K x 2, order + 1, one sub-texel level more (lutbake.environment.prefilter)",
        "quality": {"tau": quality.tau, "k_geo": quality.k_geo, "order": quality.order},
    }


def bake_environment(
    source,
    out_dir,
    name: str,
    engine: str = "bevy",
    size: int = 256,
    irradiance_size: int = 32,
    lobe: str = "ggx_nl",
    dtype: str = "half",
    fmt: str | None = None,
    quality: prefilter.Quality = prefilter.Quality(),
    workers: int | None = None,
) -> dict[str, Path]:
    """Bake and write ``<name>_specular``, ``<name>_diffuse`` (cubes) and ``<name>_sh.json``; returns the paths."""
    target = ENGINES[engine]
    fmt = fmt or target.format
    env = read_latlong(source)
    pyr = latlong.pyramid(env.image)
    mips = int(np.log2(size)) + 1
    rough = [curves.CURVES[target.curve].roughness(m, mips) for m in range(mips)]
    specular = prefilter.bake_cube(pyr, size, rough, lobe, quality, workers)
    diffuse = prefilter.bake_cube(pyr, irradiance_size, [1.0], "cosine", quality, workers)
    out = Path(out_dir)
    ext = EXTENSIONS[fmt]
    paths = {
        "specular": write_cube(
            specular.mips,
            out / f"{name}_specular{ext}",
            record(specular, target.curve, lobe, source, env, quality)
            | {"engine": engine, "shader": target.specular_line},
            fmt,
            dtype,
        ),
        "diffuse": write_cube(
            diffuse.mips,
            out / f"{name}_diffuse{ext}",
            record(diffuse, target.curve, "cosine", source, env, quality)
            | {"engine": engine, "shader": target.diffuse_line},
            fmt,
            dtype,
        ),
    }
    radiance = sh.project(env.image)
    doc = {
        "basis": "real SH, R&H 2001 / three.js order: Y00; Y1-1 y, Y10 z, Y11 x; Y2-2 xy, Y2-1 yz, Y20 3z^2-1, Y21 xz, "
        "Y22 x^2-y^2 (lutbake.environment.sh), on the y-up world direction",
        "integration": "exact per source texel (closed-form theta and phi integrals), texel-constant radiance",
        "source_sha256": env.sha256,
        **{form: convolve.tolist() for form, convolve in ((f, sh.convolve(radiance, f)) for f in sh.FORMS)},
        "forms": sh.FORMS,
    }
    paths["sh"] = out / f"{name}_sh.json"
    atomic_write_bytes(paths["sh"], (json.dumps(doc, indent=1) + "\n").encode())
    return paths
