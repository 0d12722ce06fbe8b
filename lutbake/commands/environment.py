"""Bake an environment's half of the split sum from Python, for one engine: the prefiltered specular cube (one
roughness per mip by the engine's curve), the irradiance cube (E / pi) and its L2 SH, written as KTX 2.0, DDS or EXR
cubes with lutbake's record (Filament: the specular cube only, as its KTX 1 with the SH in its key ``sh``). It bakes
the tables of kinds environment_specular and environment_irradiance (lutbake.kinds.environment) with the keys the
engine's records fix (lutbake.layouts: the tables of preset ``<engine>-ibl``), exactly as a config or
``lutbake bake --preset bevy-ibl --environment studio.exr`` does.

    from lutbake.commands.environment import bake_environment
    bake_environment("studio.exr", "outputs", "studio", engine="bevy")
    # -> outputs/studio_specular.ktx2, studio_diffuse.ktx2 (+ their .json sidecars), studio_diffuse_sh.json
"""

from __future__ import annotations

import os
from pathlib import Path

from ..config import validate_table
from ..environment.prefilter import Quality
from ..io.cubemap import write_cube_table
from ..io.formats import output_path
from ..kinds.environment import SH_SUFFIX
from ..layouts import TABLES
from ..pipeline import bake_cube_table

ENGINES = sorted({t.preset.removesuffix("-ibl") for t in TABLES if t.preset.endswith("-ibl")})


def engine_keys(engine: str) -> dict[str, dict]:
    """kind -> the keys ``engine``'s records fix for its environment tables (preset ``<engine>-ibl``)."""
    keys = {t.kind: dict(t.keys) for t in TABLES if t.preset == f"{engine}-ibl" and t.kind.startswith("environment")}
    if not keys:
        raise ValueError(f"engine must be one of {', '.join(ENGINES)}, got {engine!r}")
    return keys


def bake_environment(
    source,
    out_dir,
    name: str,
    engine: str = "bevy",
    size: int = 256,
    irradiance_size: int = 32,
    lobe: str = "ggx_nl",
    dtype: str | None = None,
    fmt: str | None = None,
    quality: Quality = Quality(),
    workers: int | None = None,
    sh_form: str = "radiance",
) -> dict[str, Path]:
    """Bake and write ``<name>_specular``, ``<name>_diffuse`` (cubes) and ``<name>_diffuse_sh.json``; returns the
    paths {"specular", "diffuse", "sh"}; for an engine without an irradiance cube (filament: the SH is the KTX 1's
    key ``sh``) {"specular"}. ``fmt``, ``dtype``: default the engine's (ktx2, dds, exr, ktx1; half, float32,
    r11g11b10f)."""
    if quality.extra_levels:
        raise ValueError("quality.extra_levels is no key of the environment kinds (tau, k_geo, order are)")
    keys = engine_keys(engine)
    common = {
        "environment": os.path.abspath(source),
        **({} if dtype is None else {"dtype": dtype}),
        "tau": quality.tau,
        "k_geo": quality.k_geo,
        "order": quality.order,
    }
    tables = {
        "specular": {
            **keys["environment_specular"],
            **common,
            "name": f"{name}_specular",
            "kind": "environment_specular",
            "size": size,
            "lobe": lobe,
        },
        "diffuse": {
            **keys.get("environment_irradiance", {}),
            **common,
            "name": f"{name}_diffuse",
            "kind": "environment_irradiance",
            "size": irradiance_size,
            "sh_form": sh_form,
        },
    }
    if "environment_irradiance" not in keys:
        del tables["diffuse"]
    paths = {}
    for index, (role, raw) in enumerate(tables.items()):
        if fmt is not None:
            raw["format"] = fmt
        spec = validate_table(raw, "<bake_environment>", index)
        cube, _ = bake_cube_table(spec, workers)
        path = output_path(out_dir, spec.name, spec.options["format"])
        paths[role] = write_cube_table(cube, path, spec.options["format"], spec.options["dtype"])
    if "diffuse" in paths:
        paths["sh"] = Path(out_dir) / f"{name}_diffuse{SH_SUFFIX}"
    return paths
