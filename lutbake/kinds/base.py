"""What a table kind declares: its config keys (with types, defaults and docs), its estimators, and ``plan(spec)``,
which names the kind's axes, channels, reconstruction text, integrand and estimator and hands them to
lutbake.sampling.plan.per_texel_plan. The registry (lutbake.kinds) adds the keys every kind has (``COMMON_KEYS``).
A kind whose output is no (z,) y, x, C table (the environment cube maps, lutbake.kinds.environment) declares
``bake(spec, workers, device)`` instead of a plan: it returns the whole output (lutbake.table.CubeTable).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..io.formats import FORMATS
from ..limits import MAX_SAMPLES, MAX_SEED


@dataclass(frozen=True)
class Key:
    """One config key: its type, default, allowed values (or a range) and a line of documentation."""

    name: str
    type: str  # "str", "int", "float", "bool", "int_pair", "float_range", "float_list", "name"
    default: Any
    doc: str
    choices: dict[str, str] | None = None  # value -> description
    minimum: float | None = None
    maximum: float | None = None
    required: bool = False


@dataclass(frozen=True)
class Kind:
    """A table kind. ``keys``: every key (the registry's common keys first; see ``declare``); ``plan(spec)`` ->
    lutbake.sampling.plan.TexelPlan; ``check(spec)``: cross-key rules, a message or (key, message)."""

    name: str
    description: str
    keys: dict[str, Key]
    plan: Callable[[Any], Any] | None  # None: a kind baked whole (``bake``)
    aliases: tuple[str, ...] = ()
    check: Callable[[Any], str | tuple[str, str] | None] | None = None
    texels: Callable[[Any], int] = lambda o: math.prod(o.get("size", [1]))  # texel count, for config.MAX_TEXELS
    texels_doc: str = "size"  # the keys whose product ``texels`` is, for the error message
    # keys (besides ``name``) that choose only how a computed table is written, never its values: specs differing
    # only in these share one computation in a batch (lutbake.sharing). Not format / dtype where the storage's
    # default tolerance (lutbake.tolerance) steers the estimator.
    layout_keys: tuple[str, ...] = ()
    # a kind baked whole, not texel by texel (``plan`` None): (spec, workers, device) -> lutbake.table.CubeTable
    bake: Callable[..., Any] | None = None
    # what else a table's values depend on, as bytes for its content hash and values key (lutbake.provenance,
    # lutbake.sharing): the digests of the input files a spec names (an environment's sha256)
    inputs: Callable[[Any], bytes] | None = None
    # the files a table writes beside its data file and sidecar: (suffix after the name, what it is), e.g.
    # ("_sh.json", "L2 SH coefficients") (lutbake.preflight.planned_files, lutbake.io.formats.written_files)
    outputs: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Estimation:
    """The estimators a kind offers (name -> description), its default, and what ``samples`` means for it."""

    estimators: dict[str, str]
    default: str
    samples_doc: str
    samples_min: int = 1
    samples_max: int = MAX_SAMPLES


def common_keys(e: Estimation) -> dict[str, Key]:
    """The keys every kind has: name, kind, format, dtype, seed, samples, estimator, tolerance, relative_tolerance,
    accept_over_tolerance."""
    return {
        "name": Key(
            "name",
            "name",
            None,
            "output stem: <out-dir>/<name>.<ext> (ext per format); letters, digits, - and _ only; not CON, PRN, AUX, "
            "NUL, COM0-9, LPT0-9 (Windows reserves them)",
            required=True,
        ),
        "kind": Key("kind", "str", None, "table kind (lutbake list)", required=True),
        "samples": Key("samples", "int", None, e.samples_doc, minimum=e.samples_min, maximum=e.samples_max),
        "dtype": Key(
            "dtype", "str", "float32", "pixel type written", {"float32": "32-bit float", "half": "16-bit float"}
        ),
        "estimator": Key("estimator", "str", e.default, "how the integral is estimated", e.estimators),
        "seed": Key(
            "seed", "int", 0, "scrambling seed of the Sobol' points (QMC estimators)", minimum=0, maximum=MAX_SEED
        ),
        "format": Key("format", "str", "exr", "output file format: <out-dir>/<name>.<ext>", FORMATS),
        "tolerance": Key(
            "tolerance",
            "float",
            None,
            "absolute error target per value, e <= max(tolerance, relative_tolerance |v|) (adaptive estimators); "
            "unset: a quarter of the storage quantum (png16: 3.8e-6; lutbake.tolerance)",
            minimum=0.0,
            maximum=1.0,
        ),
        "relative_tolerance": Key(
            "relative_tolerance",
            "float",
            None,
            "relative error target per value (see tolerance); unset: from the dtype (float32 0, half 1.2e-4)",
            minimum=0.0,
            maximum=1.0,
        ),
        "accept_over_tolerance": Key(
            "accept_over_tolerance",
            "bool",
            None,
            "true: a table whose texels end over their tolerance (status over_tolerance) does not make the bake exit "
            "1; unset: false",
        ),
    }


def declare(
    name: str,
    description: str,
    keys: dict[str, Key],
    plan,
    estimation: Estimation,
    *,
    aliases: tuple[str, ...] = (),
    check=None,
    texels=None,
    layout_keys: tuple[str, ...] = (),
) -> Kind:
    """A Kind with the common keys (``common_keys``) followed by its own ``keys``. ``texels(options)``: the texel
    count (default: the product of ``size``); its docstring names the keys it multiplies (for the error message).
    ``layout_keys``: Kind.layout_keys."""
    all_keys = {**common_keys(estimation), **keys}
    if texels is None:
        return Kind(name, description, all_keys, plan, aliases, check, layout_keys=layout_keys)
    return Kind(name, description, all_keys, plan, aliases, check, texels, texels.__doc__, layout_keys)
