"""The public Python API: ``bake`` a config (or specs) into tables and files."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import __version__
from .config import TableSpec, load_configs
from .errors import TableError
from .executor import Timer, execute
from .table import Table
from .tables import lookup_kind


@dataclass
class BakeResult:
    spec: TableSpec
    table: Table
    path: Path | None
    seconds: float
    samples: int


def _warp_version() -> str:
    import warp as wp

    return wp.config.version


def bake_table(
    spec: TableSpec, workers: int | None = None, device: str = "cpu", progress: bool | None = None, cancel=None
) -> tuple[Table, float, int]:
    """Bake one spec into a Table (nothing written). Raises TableError if a value is not finite;
    executor.Cancelled if the ``cancel`` event (a threading.Event) is set while it runs."""
    from .batch import content_hash

    plan = lookup_kind(spec.kind).plan(spec)
    with Timer() as t:
        data = execute(plan, workers=workers, device=device, progress=progress, label=spec.name, cancel=cancel)
    if not np.all(np.isfinite(data)):
        bad = int(np.size(data) - np.count_nonzero(np.isfinite(data)))
        raise TableError(f"{spec.source}: table '{spec.name}': {bad} non-finite values; nothing written")
    extra = dict(plan.extra)
    if plan.error_estimate is not None:
        err, how = plan.error_estimate(data.reshape(plan.n_texels, plan.n_channels), device)
        extra.update(error_estimate=f"{err:.3e}", error_estimate_method=how)
    attributes = {
        "terms": json.dumps(plan.terms),
        "estimator": plan.estimator,
        "samples": str(plan.samples),
        "seed": str(spec.options.get("seed", 0)),
        "config": spec.toml(),
        "config_file": Path(spec.source).name,
        "version": __version__,
        "warp_version": _warp_version(),
        **extra,
        "content_hash": content_hash(spec),  # what makes the file current (lutbake.batch)
    }
    table = Table(
        spec.name, spec.kind, data.astype(np.float32), plan.axes, plan.channels, plan.reconstruction, attributes
    )
    return table, t.seconds, plan.samples


def samples_note(spec: TableSpec, effective: int | None) -> str:
    """Why a table integrates ``effective`` samples per texel when its config asked for another number
    ('' when they agree or none was asked): each quadrature rounds the budget to its own grid."""
    from .tables import specular

    asked = spec.options.get("samples")
    if not asked or effective is None or asked == effective:
        return ""
    rule = specular.samples_note(spec.options.get("estimator", ""), asked)
    if rule and specular.effective_samples(spec.options.get("estimator", ""), asked) == effective:
        return rule
    return f"samples = {asked} asked; the {spec.kind} quadrature evaluates {effective} per texel (docs/config.md)"


def bake(
    configs,
    out_dir="outputs",
    overrides=(),
    workers: int | None = None,
    device: str = "cpu",
    write: bool = True,
    progress: bool | None = None,
    on_result=None,
) -> list[BakeResult]:
    """Validate every config, then bake each table and write ``out_dir/<name>.<ext>`` (key ``format``,
    default EXR) atomically.

    ``configs``: paths to TOML files, or TableSpecs. Nothing runs unless every config is valid.
    """
    from .io.formats import write_table

    specs = [c for c in configs if isinstance(c, TableSpec)]
    paths = [c for c in configs if not isinstance(c, TableSpec)]
    specs += load_configs(paths, overrides) if paths else []
    results = []
    for spec in specs:
        table, seconds, samples = bake_table(spec, workers, device, progress)
        path = None
        if write:
            path = write_table(table, out_dir, spec.options.get("format", "exr"), spec.options.get("dtype", "float32"))
        r = BakeResult(spec, table, path, seconds, samples)
        if on_result:
            on_result(r)
        results.append(r)
    return results
