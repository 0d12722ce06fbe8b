"""The declared conventions of ``lutbake audit`` and ``lutbake size``, and their reference: the bake's own pipeline.

``declared_specs(conv_args, recorded)``: the table specs the file is held against: a config (``--config``), a
preset (``--preset``), else the config the file itself records (its EXR header or sidecar: lutbake's own files),
else the ``default`` preset; ``--set`` keys apply on top. ``Reference(conventions)`` evaluates the spec's integral at
arbitrary texels through lutbake.pipeline.compute_at (the kind's plan and the tile executor ``bake`` uses): converged
by adaptive Gauss-Legendre to REFERENCE_TOLERANCE, or by the engines' usual Hammersley estimator.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..axes import Axis
from ..config import TableSpec, load_config, parse_overrides, preset_path, validate_spec, validate_table
from ..errors import ConfigError
from ..pipeline import compute_at
from ..runtime.memo import RowMemo

REFERENCE_TOLERANCE = 1e-7  # the re-bake: adaptive Gauss-Legendre to 1e-7 per value (its estimates bound the error:
# docs/validation.md); a fixed order 12 leaves ~1e-5 at NoV = 1e-4 and would flag a correct table
POINTS = ("nov", "alpha", "rough")
# the reference integrals per (spec, texel), shared by every audit of a process: audits of one engine's files (or of
# one file under several hypotheses) ask for the same conventions at the same texels; a texel's value is a function
# of its spec and point alone (lutbake.pipeline.compute_at: the same for any tiling or worker count)
REFERENCES = RowMemo()


def computed_at(spec: TableSpec, points: dict, workers: int | None) -> np.ndarray:
    """``compute_at(spec, points, workers)``, its rows memoised per texel in REFERENCES."""
    cols = [np.asarray(points[k], np.float64) for k in POINTS]
    base = repr(sorted(spec.options.items())).encode()
    # a texel's key: base + its nov, alpha, rough float64 bytes (one row of the stacked points)
    raw, width = np.stack(cols, axis=1).tobytes(), 8 * len(POINTS)
    keys = [base + raw[i : i + width] for i in range(0, len(raw), width)]
    if not keys:
        return compute_at(spec, points, workers)

    def compute(idx):
        return (compute_at(spec, {k: c[idx] for k, c in zip(POINTS, cols)}, workers),)

    return REFERENCES.run(keys, compute)[0]


def recorded_specs(config_text: str, where: str, overrides=()) -> list[TableSpec]:
    """The specs of the ``[[table]]`` text a lutbake file records (its ``config`` attribute), ``overrides`` applied."""
    try:
        doc = tomllib.loads(config_text)
    except tomllib.TOMLDecodeError as e:
        raise ConfigError(where, "config", message=f"the recorded config is not valid TOML: {e}") from None
    specs = []
    for i, raw in enumerate(doc.get("table") or []):
        raw = dict(raw)
        for table, key, value in overrides:
            if table is None or table == raw.get("name"):
                raw[key] = value
        specs.append(validate_table(raw, where, i))
    if not specs:
        raise ConfigError(where, "config", message="the recorded config holds no [[table]]")
    return specs


def declared_specs(conv_args: dict | None, recorded: dict | None = None, path=None) -> list[TableSpec]:
    """``conv_args`` {"preset", "config", "overrides", "size"}; ``recorded``: the file's lutbake attributes (used
    when neither a preset nor a config is given and they hold a ``config``)."""
    conv_args = conv_args or {}
    ovr = parse_overrides(conv_args.get("overrides") or ())
    if conv_args.get("size") is not None:
        ovr = ovr + [(None, "size", conv_args["size"])]
    if conv_args.get("config"):
        return load_config(Path(conv_args["config"]), ovr)
    if not conv_args.get("preset") and recorded and recorded.get("config"):
        try:
            return recorded_specs(recorded["config"], f"{path} (its recorded config)", ovr)
        except ConfigError:
            if not recorded.get("plugins"):
                raise
            raise ConfigError(
                path,
                "plugins",
                message="baked with a plugin's records (lutbake:plugins; lutbake inspect names them), which this "
                "process has not loaded: give the config that loads them (--config CONFIG); lutbake runs no code a "
                "file names",
            ) from None
    return load_config(preset_path(conv_args.get("preset") or "default"), ovr)


@dataclass
class Conventions:
    """A dfg spec (the file's size) and its axes [y, x]."""

    spec: TableSpec
    axes: list[Axis]
    source: str

    @property
    def options(self) -> dict:
        return dict(self.spec.options)

    @property
    def layout(self) -> str:
        return self.spec.options["layout"]

    @property
    def record(self):
        """The declared layout's record (lutbake.layouts)."""
        from ..layouts import lookup_layout

        return lookup_layout("dfg", self.layout)


def conventions(config=None, preset=None, overrides=(), shape=None, recorded=None, path=None) -> Conventions:
    """The declared dfg conventions (declared_specs' first table); size from ``shape`` (rows, columns)."""
    from ..kinds.dfg import axes_for

    args = {"config": config, "preset": preset, "overrides": overrides}
    spec = declared_specs(args, recorded, path)[0]
    if spec.kind != "dfg":
        raise ConfigError(spec.source, "kind", spec.kind, "dfg", "audit and size compare dfg tables")
    if shape is not None:
        rows, cols = shape
        size = [cols, rows] if spec.options.get("axis_order", "nov_x") == "nov_x" else [rows, cols]
        spec = declared_specs({**args, "size": size}, recorded, path)[0]
    return Conventions(spec, axes_for(spec.options), spec.source)


def _with(spec: TableSpec, **options) -> TableSpec:
    """``spec`` with ``options`` changed, validated as a config's (its records resolved anew)."""
    return validate_spec(TableSpec(spec.name, spec.kind, {**spec.options, **options}, spec.source, spec.index))


class Reference:
    """Converged (and, for the noise estimate, Hammersley) integrals of a dfg spec at arbitrary (NoV, alpha),
    through lutbake.pipeline.compute_at, memoised per texel (computed_at)."""

    def __init__(self, conv: Conventions, workers: int | None = None):
        from ..kinds.dfg import terms_of

        self.layout = conv.layout
        self.record = conv.record
        self.form = terms_of(conv.spec)[0]
        self.converged_spec = _with(
            conv.spec,
            estimator="gauss_legendre",
            samples=None,
            tolerance=REFERENCE_TOLERANCE,
            relative_tolerance=0.0,
            interpolation="off",
        )
        self.workers = workers

    def converged(self, nov: np.ndarray, alpha: np.ndarray, rough: np.ndarray | None = None) -> np.ndarray:
        """Every channel of the layout at (NoV, alpha); ``rough`` (perceptual) feeds an engine diffuse channel
        (default sqrt(alpha))."""
        rough = np.sqrt(alpha) if rough is None else rough
        return computed_at(self.converged_spec, {"nov": nov, "alpha": alpha, "rough": rough}, self.workers)

    def hammersley(self, nov, alpha, samples: int) -> np.ndarray | None:
        """The engines' usual estimator (R, G of the split-sum layout), or None for the sheen layouts."""
        if self.record.terms.ndf is not None or self.form != "microfacet":  # a sheen layout fixes its own NDF
            return None
        base = "multiscatter" if self.record.split_sum == "multiscatter" else "scale_bias"
        spec = _with(
            self.converged_spec,
            layout=base,
            estimator="hammersley_ndf",
            samples=samples,
            seed=0,
            tolerance=None,
            relative_tolerance=None,
        )
        return computed_at(spec, {"nov": nov, "alpha": alpha, "rough": np.sqrt(alpha)}, self.workers)[:, :2]
