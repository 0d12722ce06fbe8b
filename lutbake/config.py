"""TOML batch configs -> validated, frozen table specs.

Every key is checked at load, before any kernel runs; an error names the file, the table, the key,
the bad value and the allowed values (lutbake.errors.ConfigError). Unknown keys are errors.
A config holds one or more ``[[table]]`` entries (docs/config.md lists every key).
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from . import arguments
from .config_file import config_file_problem, nesting_problem
from .errors import ArgumentError, ConfigError, did_you_mean
from .io.formats import FORMAT_KINDS
from .kinds import KINDS, Key, Kind, kind_record, lookup_kind
from .limits import BAKE_PEAK_BYTES_PER_TEXEL, MAX_LIST, MAX_TEXELS  # noqa: F401  (lutbake.config.MAX_TEXELS, as before)
from .registry import Choices, Record
from .textsafe import safe_repr
from .value_bounds import unit_range

NAME_RE = re.compile(r"[A-Za-z0-9_-]{1,128}")  # use fullmatch: "$" would accept a final newline
NAME_RULE = "1-128 letters, digits, '-' or '_' (it names the output file)"
# device names Windows reserves in every directory, whatever the extension ("nul.exr" is the null device):
# Microsoft, "Naming Files, Paths, and Namespaces" (learn.microsoft.com/windows/win32/fileio/naming-a-file)
WINDOWS_RESERVED = frozenset(
    ["CON", "PRN", "AUX", "NUL"] + [f"{port}{i}" for port in ("COM", "LPT") for i in range(10)]
)


def human_bytes(n: int) -> str:
    """1536 -> '1.5 KiB'; exact integer arithmetic, so any size (even 10**400 bytes) prints."""
    units = ("B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB")
    k = 0
    while n >= 1024 ** (k + 1) and k < len(units) - 1:
        k += 1
    if k == len(units) - 1 and n >= 1024 ** (k + 1):
        return f"~2^{n.bit_length() - 1} B"
    return f"{n / 1024**k:.1f} {units[k]}" if k else f"{n} B"


PRESET_DIR = Path(__file__).parent / "presets"


def name_problem(name) -> str | None:
    """Why ``name`` cannot name a table (its output file ``name.<ext>`` on every system), or None. The one check of
    a name: config keys ``name`` (lutbake.config._check_value) and every TableSpec (its constructor). The letters
    leave out '.', ' ' and path separators: no name climbs out of the out-dir, none ends in the dot or space
    Windows strips; a device name Windows reserves is refused with and without an extension."""
    if not isinstance(name, str):
        return "must be a string"
    stem = name.split(".", 1)[0].rstrip(" ")
    if stem.upper() in WINDOWS_RESERVED:
        return f"{stem!r} is a device name Windows reserves (CON, PRN, AUX, NUL, COM0-9, LPT0-9): no file can have it"
    if not NAME_RE.fullmatch(name):
        return f"must be {NAME_RULE}"
    return None


def _frozen(value):
    """``value`` immutable all the way down: lists and tuples -> tuples, mappings -> read-only mappings."""
    if isinstance(value, (list, tuple)):
        return tuple(_frozen(v) for v in value)
    if isinstance(value, Mapping):
        return MappingProxyType({k: _frozen(v) for k, v in value.items()})
    return value


@dataclass(frozen=True)
class TableSpec:
    """One validated ``[[table]]``: its kind, its options (every key of the kind, defaults filled in),
    where it came from, and its canonical TOML text (written into the EXR). ``records``: the record each name-valued
    option resolved to where the config was read (``kind`` -> the Kind's record, ``ndf`` -> the NDF's, ...,
    lutbake.registry): below the config, code takes objects from these, never looks a name up again."""

    name: str
    kind: str
    options: Mapping[str, Any]
    source: str
    index: int
    records: Mapping[str, Record] = field(default_factory=dict, compare=False)

    def __post_init__(self):
        """Immutable all the way down (a list option is a tuple: ``spec.options["size"][0] = 16384`` raises
        TypeError), and the name checked as a config's is (name_problem): a hand-made spec cannot write outside
        the out-dir. Every other option is checked where a spec enters the API (validate_spec)."""
        source = self.source if isinstance(self.source, str) else "TableSpec"

        def fail(key, value, message):
            raise ConfigError(source, key, value, message=f"TableSpec: {message}")

        problem = name_problem(self.name)
        if problem:
            fail("name", self.name, f"{problem}")
        if not isinstance(self.kind, str):
            fail("kind", self.kind, "must be a string")
        if not isinstance(self.options, Mapping) or not all(isinstance(k, str) for k in self.options):
            fail(None, None, f"options must be a mapping of key names to values, not {safe_repr(self.options)}")
        for key, given in (("name", self.name), ("kind", self.kind)):
            if key in self.options and self.options[key] != given:
                fail(key, self.options[key], f"options hold {key} {safe_repr(self.options[key])}, the spec {given!r}")
        if isinstance(self.source, os.PathLike):
            object.__setattr__(self, "source", os.fspath(self.source))
        if not isinstance(self.source, str) or isinstance(self.index, bool) or not isinstance(self.index, int):
            fail(None, None, "source must be a string (the config's path) and index an integer")
        object.__setattr__(self, "options", _frozen(self.options))
        if not isinstance(self.records, Mapping) or not all(isinstance(r, Record) for r in self.records.values()):
            fail(None, None, "records must map option names to lutbake.registry.Record objects")
        object.__setattr__(self, "records", MappingProxyType(dict(self.records)))

    @property
    def plugins(self) -> list[Record]:
        """The plugins' records this table uses (their sources enter its content hash, lutbake.provenance)."""
        return [r for r in self.records.values() if r.plugin is not None]

    def toml(self) -> str:
        return "[[table]]\n" + "".join(f"{k} = {_toml_value(v)}\n" for k, v in self.options.items() if v is not None)

    def __reduce__(self):  # a mappingproxy does not pickle; lutbake.runtime.cluster ships specs to Dask workers
        return (_table_spec, (self.name, self.kind, dict(self.options), self.source, self.index, dict(self.records)))


def kind_of(spec: TableSpec | str) -> Kind:
    """The Kind of ``spec`` (the record its ``kind`` resolved to where its config was read), or of a kind's name or
    alias as a user typed it (``lutbake list keys``; KeyError lists the valid names): the one place outside
    lutbake.kinds a kind is reached, for every module above config that needs it (its plan function, texel count,
    layout keys, keys)."""
    if isinstance(spec, str):
        return lookup_kind(spec)
    return spec.records["kind"].obj


def _table_spec(name: str, kind: str, options: dict, source: str, index: int, records: dict) -> TableSpec:
    return TableSpec(name, kind, MappingProxyType(options), source, index, records)


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(v)


def presets() -> dict[str, Path]:
    """Preset name -> its TOML file (presets are configs shipped in the package)."""
    return {p.stem: p for p in sorted(PRESET_DIR.glob("*.toml"))}


def preset_path(name: str) -> Path:
    ps = presets()
    if name not in ps:
        raise ConfigError(
            "--preset", None, message=f"unknown preset {safe_repr(name)}{did_you_mean(name, ps)}", allowed=", ".join(ps)
        )
    return ps[name]


def _num(x) -> str:
    return str(x) if isinstance(x, int) else f"{x:g}"


def _check_value(key: Key, value, file, table) -> Any:
    def fail(msg, allowed=None):
        raise ConfigError(file, key.name, value, allowed, msg, table)

    if key.type in ("str", "name"):
        if not isinstance(value, str):
            fail("must be a string", ", ".join(key.choices) if key.choices else None)
        problem = name_problem(value) if key.type == "name" else None
        if problem:
            fail(problem)
        if isinstance(key.choices, Choices):  # a family's records: the name resolved once, here
            if value in key.choices:
                return key.choices.resolve(value).name  # an alias -> the record's name
            fail(
                key.choices.why_not(value) or "is not a known value" + did_you_mean(value, key.choices),
                ", ".join(key.choices),
            )
        if key.choices is not None and value not in key.choices:
            fail("is not a known value" + did_you_mean(value, key.choices), ", ".join(key.choices))
        return value
    if key.type == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            fail("must be an integer")
        if key.minimum is not None and value < key.minimum:
            fail(f"must be >= {_num(key.minimum)}")
        if key.maximum is not None and value > key.maximum:
            fail(f"must be <= {_num(key.maximum)}")
        return value
    if key.type == "bool":
        if not isinstance(value, bool):
            fail("must be true or false", "true, false")
        return value
    if key.type == "int_pair":
        if (
            not isinstance(value, (list, tuple))
            or len(value) != 2
            or any(isinstance(x, bool) or not isinstance(x, int) for x in value)
        ):
            fail("must be a list of two integers, e.g. [128, 128]")
        if any(x < (key.minimum or 1) for x in value):
            fail(f"sizes must be >= {_num(key.minimum or 1)}")
        return list(value)
    if key.type == "float":
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            fail("must be a finite number")
        if key.minimum is not None and value < key.minimum:
            fail(f"must be >= {key.minimum:g}")
        if key.maximum is not None and value > key.maximum:
            fail(f"must be <= {key.maximum:g}")
        return float(value)
    if key.type == "float_range":
        if (
            not isinstance(value, (list, tuple))
            or len(value) != 2
            or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in value)
        ):
            fail("must be a list of two numbers [lo, hi]")
        lo, hi = (float(x) for x in value)
        if not (math.isfinite(lo) and math.isfinite(hi)):
            fail("must be finite")
        if lo < key.minimum or hi > key.maximum or lo > hi:
            fail(f"must satisfy {key.minimum:g} <= lo <= hi <= {key.maximum:g}")
        return [lo, hi]
    if key.type == "float_list":
        if (
            not isinstance(value, (list, tuple))
            or not 1 <= len(value) <= MAX_LIST
            or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in value)
        ):
            fail(f"must be a list of 1 to {MAX_LIST} numbers, e.g. [0.0, 0.25, 0.5]")
        xs = [float(x) for x in value]
        if not all(math.isfinite(x) for x in xs):
            fail("must be finite")
        if any(x < key.minimum or x > key.maximum for x in xs):
            fail(f"every value must satisfy {key.minimum:g} <= value <= {key.maximum:g}")
        if any(b <= a for a, b in zip(xs, xs[1:])):
            fail("must be strictly increasing")
        return xs
    raise AssertionError(key.type)


def validate_table(raw: Mapping[str, Any], file, index: int) -> TableSpec:
    """Validate one ``[[table]]`` mapping against its kind's keys."""
    if not isinstance(raw, Mapping):
        raise ConfigError(file, None, message=f"table #{index + 1} must be a TOML table")
    label = f"#{index + 1}" + (f" ({raw['name']!r})" if isinstance(raw.get("name"), str) else "")
    if "kind" not in raw:
        raise ConfigError(file, "kind", message="is missing", allowed=", ".join(KINDS), table=label)
    if not isinstance(raw["kind"], str):
        raise ConfigError(file, "kind", raw["kind"], ", ".join(KINDS), "must be a string", label)
    try:
        kind = lookup_kind(raw["kind"])
    except KeyError:
        raise ConfigError(
            file,
            "kind",
            raw["kind"],
            ", ".join(KINDS),
            "is not a known table kind" + did_you_mean(raw["kind"], KINDS),
            label,
        ) from None
    unknown = sorted(set(raw) - set(kind.keys), key=str)
    if unknown:
        raise ConfigError(
            file,
            unknown[0],
            raw[unknown[0]],
            ", ".join(kind.keys),
            f"is not a key of kind '{kind.name}'" + did_you_mean(unknown[0], kind.keys),
            label,
        )
    options: dict[str, Any] = {}
    for k in kind.keys.values():
        if k.name in raw:
            options[k.name] = _check_value(k, raw[k.name], file, label)
        elif k.required:
            raise ConfigError(file, k.name, message="is missing", table=label)
        else:
            options[k.name] = list(k.default) if isinstance(k.default, list) else k.default
    options["kind"] = kind.name
    records = {"kind": kind_record(kind.name)}
    records.update(
        (k.name, k.choices.resolve(options[k.name]))
        for k in kind.keys.values()
        if isinstance(k.choices, Choices) and options[k.name] is not None
    )
    spec = TableSpec(options["name"], kind.name, MappingProxyType(options), str(file), index, records)
    texels = kind.texels(options)
    if texels > MAX_TEXELS:
        size_keys = [k for k in options if k == "size" or k.endswith("_size")]  # the key to name: size, else ...
        size_key = "size" if "size" in options else (size_keys[0] if size_keys else "size")
        raise ConfigError(
            file,
            size_key,
            options.get(size_key),
            f"at most {MAX_TEXELS} texels (a bake's peak: about {human_bytes(MAX_TEXELS * BAKE_PEAK_BYTES_PER_TEXEL)})",
            f"{kind.texels_doc} = {texels} texels would need about "
            f"{human_bytes(texels * BAKE_PEAK_BYTES_PER_TEXEL)} of memory at the bake's peak "
            f"({BAKE_PEAK_BYTES_PER_TEXEL} bytes a texel, measured)",
            label,
        )
    if options.get("format") in FORMAT_KINDS and kind.name not in FORMAT_KINDS[options["format"]]:
        fmt = options["format"]
        raise ConfigError(
            file, "format", fmt, None, f"{fmt} holds a {' or '.join(FORMAT_KINDS[fmt])} table only", label
        )
    if options.get("format") == "png16":
        reason = unit_range(spec)
        if reason:
            raise ConfigError(
                file,
                "format",
                "png16",
                "exr, npy, dds, ktx2, h",
                f"png16 stores values in [0, 1] only, and this table's {reason}",
                label,
            )
    if kind.check is not None:
        msg = kind.check(spec)
        if msg:
            key = None
            if isinstance(msg, tuple):  # (key, message)
                key, msg = msg
            raise ConfigError(file, key, options.get(key) if key else None, message=msg, table=label)
    return spec


def validate_spec(spec, function: str = "bake") -> TableSpec:
    """``spec`` checked as its config would be: validate_table of its options (every key, the texel cap, the kind's
    own checks), so a hand-made TableSpec passes the checks a config's does. Raises ConfigError (ArgumentError
    when ``spec`` is no TableSpec; ``function`` names the API function it was given to)."""
    if not isinstance(spec, TableSpec):
        raise ArgumentError(function, "spec", spec, "a TableSpec (lutbake.load_config(path) returns them)")
    raw = {k: v for k, v in spec.options.items() if v is not None}  # None: a default left unset
    raw.update(name=spec.name, kind=spec.kind)
    return validate_table(raw, spec.source, spec.index)


def _overrides(function: str, overrides) -> list[tuple]:
    """``--set`` texts parsed (parse_overrides), tuples kept: the ``overrides`` of load_config / load_configs."""
    items = arguments.overrides_arg(function, overrides)
    return parse_overrides([o for o in items if isinstance(o, str)]) + [o for o in items if not isinstance(o, str)]


def parse_overrides(items: tuple[str, ...] | list[str]) -> list[tuple[str | None, str, Any]]:
    """``--set KEY=VALUE`` (every table) or ``--set NAME.KEY=VALUE`` (one table); VALUE is TOML."""
    out = []
    for item in items:
        if "=" not in item:
            raise ConfigError("--set", item, message="must look like KEY=VALUE or TABLE.KEY=VALUE")
        lhs, rhs = item.split("=", 1)
        table, dot, key = lhs.strip().rpartition(".")
        if dot and not table.strip():
            raise ConfigError(
                "--set", key.strip(), message="an empty table name before the '.' (KEY=VALUE or TABLE.KEY=VALUE)"
            )
        problem = nesting_problem(rhs)
        if problem:
            raise ConfigError("--set", key.strip(), message=f"VALUE: {problem}")
        try:
            doc = tomllib.loads(f"v = {rhs.strip()}")
        except tomllib.TOMLDecodeError:
            if "\n" in rhs.strip() or "=" in rhs:
                raise ConfigError("--set", key.strip(), rhs, message="VALUE is not one TOML value") from None
            doc = {"v": rhs.strip()}  # a bare word: a string
        except RecursionError:
            raise ConfigError("--set", key.strip(), message="VALUE is nested too deeply") from None
        except ValueError as e:  # an integer of more than 4300 digits (sys.int_info.str_digits_check_threshold)
            raise ConfigError("--set", key.strip(), rhs, message=f"VALUE cannot be read: {e}") from None
        if set(doc) != {"v"}:
            raise ConfigError(
                "--set", key.strip(), rhs, message="text after the value (one --set sets one key: give another --set)"
            )
        out.append((table or None, key, doc["v"]))
    return out


ENVIRONMENT_KEY = "environment"  # the key --environment fills (lutbake.kinds.environment)
ENVIRONMENT_OPTION = "--environment"


def environment_override(function: str, environment) -> list[tuple]:
    """``--environment FILE`` as an override of key ``environment`` in every table whose kind has it (the environment
    kinds; a preset names no file of its own): the path made absolute, so it is the file the user named however the
    config's folder resolves it. [] when None."""
    path = arguments.path_arg(function, "environment", environment, optional=True)
    return [] if path is None else [(ENVIRONMENT_KEY, os.path.abspath(path), ENVIRONMENT_OPTION)]


def takes_environment(raw: Mapping) -> bool:
    """Whether a raw [[table]]'s kind (a known one) has the key ``environment``."""
    try:
        return ENVIRONMENT_KEY in lookup_kind(raw.get("kind")).keys
    except (KeyError, TypeError):
        return False


def load_config(path, overrides=(), environment=None) -> list[TableSpec]:
    """Read and validate one TOML config; ``overrides`` (``--set`` texts, or parse_overrides() tuples) are applied
    first. ``environment``: the file key ``environment`` names in every table that has it (``--environment``, the
    environment kinds'). ConfigError for every wrong input (ArgumentError for an argument of the wrong type)."""
    path = arguments.path_arg("load_config", "path", path)
    overrides = _overrides("load_config", overrides)
    fills = environment_override("load_config", environment)
    problem = config_file_problem(path)
    if problem:
        raise ConfigError(path, None, message=problem)
    try:
        text = path.read_text(encoding="utf-8").removeprefix("\ufeff")  # a UTF-8 BOM (Windows editors) is no text
        problem = nesting_problem(text)
        if problem:
            raise ConfigError(path, None, message=f"invalid config: {problem}")
        doc = tomllib.loads(text)
    except RecursionError:
        raise ConfigError(path, None, message="invalid TOML: arrays, tables or dotted keys nested too deeply") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, ValueError) as e:
        raise ConfigError(path, None, message=f"invalid TOML: {e}") from None
    except OSError as e:
        raise ConfigError(path, None, message=f"cannot read: {e.strerror or e}") from None
    extra = sorted(set(doc) - {"table", "plugins"})
    if extra:
        raise ConfigError(path, extra[0], doc[extra[0]], "table, plugins", "is not a top-level key")
    load_plugins(path, doc.get("plugins", []))
    tables = doc.get("table")
    if not isinstance(tables, list) or not tables:
        raise ConfigError(path, "table", message="a config needs at least one [[table]]")
    specs = []
    for i, raw in enumerate(tables):
        if not isinstance(raw, dict):
            raise ConfigError(path, "table", raw, message=f"entry #{i + 1} must be a [[table]]")
        raw = dict(raw)
        origin = {}  # key -> the command-line argument that set it, blamed for its errors
        for table, key, value, *where in overrides:
            if table is None or table == raw.get("name"):
                raw[key] = value
                origin[key] = where[0] if where else f"--set {table + '.' if table else ''}{key}={_toml_value(value)}"
        for key, value, where in fills if takes_environment(raw) else ():
            raw[key], origin[key] = value, where
        try:
            specs.append(validate_table(raw, path, i))
        except ConfigError as e:
            if e.key in origin:
                raise e.blamed(origin[e.key]) from None
            raise
    return specs


def load_plugins(config: Path, paths) -> None:
    """A config's ``plugins = ["my_brdf.py", ...]`` (relative to the config's folder), and the installed packages'
    plugins (entry points), loaded before its tables are checked (lutbake.plugins)."""
    from . import plugins

    plugins.load_entry_points()
    if not isinstance(paths, list) or not all(isinstance(p, str) and p for p in paths) or len(paths) > MAX_LIST:
        raise ConfigError(config, "plugins", paths, "a list of Python files", "must be a list of file paths")
    for p in paths:
        file = (config.parent / p).resolve()
        if not file.is_file():
            raise ConfigError(config, "plugins", p, "a Python file", f"no such file: {file}")
        plugins.load_plugin(file)


def load_configs(paths, overrides=(), environment=None) -> list[TableSpec]:
    """Validate every config before anything runs; table names must be unique across the batch. ``paths``: one path
    (str or Path) or a list of them. ``overrides``: ``--set`` texts, or (table, key, value, blamed argument) tuples
    (``--format``). ``environment``: the file of every environment table (load_config); refused when no table of the
    batch takes one."""
    paths = arguments.configs_arg("load_configs", "paths", paths)
    ovr = _overrides("load_configs", overrides)
    environment_override("load_configs", environment)
    specs: list[TableSpec] = []
    seen: dict[str, str] = {}
    for p in paths:
        for s in load_config(p, ovr, environment):
            if s.name in seen:
                raise ConfigError(
                    s.source,
                    "name",
                    s.name,
                    None,
                    f"duplicate table name (also in {seen[s.name]}): outputs would collide",
                )
            seen[s.name] = s.source
            specs.append(s)
    if environment is not None and not any(ENVIRONMENT_KEY in kind_of(s).keys for s in specs):
        raise ConfigError(
            ENVIRONMENT_OPTION,
            ENVIRONMENT_KEY,
            str(environment),
            "a batch with an environment table (kinds environment_specular, environment_irradiance; presets "
            "bevy-ibl, gltf-ibl)",
            "no table of the batch takes an environment",
        )
    names = {o[0] for o in ovr if o[0] is not None}
    missing = names - set(seen)
    if missing:
        raise ConfigError("--set", sorted(missing)[0], None, ", ".join(seen), "names no table of the batch")
    return specs
