"""Plugins: your own BRDF terms, registered as records of lutbake's families (lutbake.registry) and baked by every
kind that takes them, with the same estimators, error estimates and tolerances as lutbake's own.

A plugin is a Python file (a config's ``plugins = ["my_brdf.py"]``, relative to the config; ``lutbake.load_plugin``
from Python), a module of yours, or an installed package's entry point in the group ``lutbake.plugins``. It defines
``@wp.func`` terms and registers them by name:

    import warp as wp
    import lutbake

    @wp.func
    def F_schlick4(f0: float, c: float):
        m = wp.clamp(1.0 - c, 0.0, 1.0)
        return f0 + (1.0 - f0) * m * m * m * m

    lutbake.register_fresnel("schlick4", F_schlick4, linear_in_f0=True, description="f0 + (1 - f0)(1 - c)^4")

Then ``fresnel = "schlick4"`` in a dfg or specular_3d table. A record's source (the plugin's text) enters the
content hash of every table that uses it (edit it, the next run rebakes; leave it, the run skips), the output's
``lutbake:plugins`` names the plugin, the record, its functions and the text's sha256 (``lutbake inspect``), and a
Dask bake ships the text to its workers. A plugin that fails to import, registers a name lutbake or another plugin
holds, or whose terms do not compile is refused before any work, naming its file and line (a ConfigError).

The signatures (float = float32 in the kernels; n = +z in the shading frame):
- ``register_fresnel(name, F)``: ``F(f0, c)`` with c = v.h; ``linear_in_f0=True`` when F = f0 + (1 - f0) Fc(c) (the
  dfg kind factors f0 out then; ``Fc(c)`` may be given, else F(0, c) is used).
- ``register_ndf(name, D, Lambda)``: ``D(h: vec3, alpha)`` normalised so that ∫ D(m)(n.m) dω = 1, ``Lambda(NoX,
  alpha)`` its Smith Lambda (None: V-cavity masking only); optionally its polar CDF pair ``tan2_from_u(u: float64,
  alpha: float64)`` / ``u_from_tan2(tan2: float64, alpha: float64)`` (the inverse CDF and CDF of D(m)(n.m) in
  tan^2 theta_m), which lets the Gauss-Legendre panels follow the lobe and the NDF-sampling estimators sample it;
  without it the panels run in theta_h.
- ``register_diffuse(name, Fd)``: ``Fd(rho, NoL, NoV, LoV, sigma)`` (with ``with_f0=True``: ``..., sigma, f0)``), the
  BRDF value (the cosine is not in it), for the diffuse, diffuse_3d and btf kinds (``model = name``).
- ``register_brdf(name, f_cos)``: a whole cosine-weighted BRDF ``f_cos(v: vec3, l: vec3, x) = f(l, v) (n.l)``, its
  parameter x the table's roughness (``roughness``: "alpha", "perceptual" (x = r, alpha = r^2) or "none"), for the ltc
  kind (``lobe = name``: its LTC, magnitude and average direction fitted as lutbake's own lobes').
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib
import importlib.metadata
import inspect
import linecache
import re
import sys
import threading
import traceback
from pathlib import Path

from .errors import ConfigError
from .records import DIFFUSE, FRESNEL, LTC_LOBE, NDF
from .registry import _PLUGIN_LOADER, FAMILIES, Plugin, Record, RegistryError

ENTRY_POINT_GROUP = "lutbake.plugins"
_STATE = threading.local()  # .plugin: the plugin whose code is running (load_plugin, entry points)
_LOAD_LOCK = threading.RLock()
_LOADED: dict[str, Plugin] = {}  # path (or module name) -> the plugin loaded from it last
_ENTRY_POINTS_LOADED = False


class PluginError(ConfigError):
    """A plugin that cannot be used: its file (or module), the line, and why."""

    def __init__(self, where: str, line: int | None, message: str):
        super().__init__(where, None, message=(f"line {line}: " if line else "") + message)
        self.line = line


# --------------------------------------------------------------------------------------------- registering records


def _caller_plugin(func) -> tuple[Plugin, int | None]:
    """The plugin registering now (load_plugin / an entry point), or the module that defines ``func`` (a record
    registered from your own code), and the line of the register call in it."""
    plugin = getattr(_STATE, "plugin", None)
    if plugin is None:
        module = getattr(getattr(func, "func", func), "__module__", None) or "__main__"
        path = inspect.getsourcefile(getattr(func, "func", func)) or module
        text = "".join(linecache.getlines(path)) or Path(path).read_text(encoding="utf-8")
        plugin = Plugin(path, text, module)
    line = None
    for frame in inspect.stack()[2:]:
        if frame.filename == plugin.path:
            line = frame.lineno
            break
    return plugin, line


def _add(family, func, name: str, description: str, citation: str, aliases, fields: dict) -> Record:
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,63}", name):
        raise RegistryError(f"{family.name} name {name!r}: 1-64 letters, digits or '_', starting with a letter")
    if not isinstance(description, str) or not description.strip():
        raise RegistryError(f"{family.name} {name!r}: give a one-line description")
    plugin, line = _caller_plugin(func)
    record = Record(family.name, name, description.strip(), citation, tuple(aliases), fields, plugin, line)
    family.add(record)
    added = _STATE.__dict__.get("added")
    if added is not None:
        added.append(record)
    return record


def _need_func(what: str, f):
    import warp as wp

    if not isinstance(f, wp.Function):
        raise RegistryError(f"{what} must be a @wp.func, not {type(f).__name__}")
    return f


def register_fresnel(
    name: str, F, *, description: str, citation: str = "", aliases=(), linear_in_f0: bool = False, Fc=None
) -> Record:
    """A Fresnel term ``F(f0: float, c: float) -> float`` (c = v.h) for the dfg (``linear_in_f0``) and specular_3d
    kinds' ``fresnel`` key. ``Fc(c)``: the f0-free part of a term linear in f0 (default F(0, c))."""
    fields = {"F": _need_func("F", F), "param": "f0", "linear_in_f0": bool(linear_in_f0)}
    if Fc is not None:
        fields["Fc"] = _need_func("Fc", Fc)
    return _add(FRESNEL, F, name, description, citation, aliases, fields)


def register_ndf(
    name: str,
    D,
    Lambda=None,
    *,
    description: str,
    citation: str = "",
    aliases=(),
    tan2_from_u=None,
    u_from_tan2=None,
) -> Record:
    """A normal distribution ``D(h: vec3, alpha: float)`` with its Smith ``Lambda(NoX: float, alpha: float)`` (None:
    masking = "v_cavity" only) and optionally its polar CDF pair (module docstring) for the dfg, albedo, albedo_avg
    and specular_3d kinds' ``ndf`` key."""
    from .terms.distributions import Distribution, theta_cdf

    if (tan2_from_u is None) != (u_from_tan2 is None):
        raise RegistryError(f"ndf {name!r}: give both tan2_from_u and u_from_tan2, or neither")
    sampler = tan2_from_u is not None
    if sampler:
        t2u, u2t, pdf = _need_func("tan2_from_u", tan2_from_u), _need_func("u_from_tan2", u_from_tan2), None
    else:
        t2u, u2t, pdf = theta_cdf()
    lam = None if Lambda is None else _need_func("Lambda", Lambda)
    d = Distribution(name, _need_func("D", D), lam, t2u, u2t, polar_pdf=pdf)
    # the terms beside their Distribution, as lutbake's NDF records carry them (lutbake.records)
    terms = {"D": d.D, "Lambda": lam, "tan2_from_u": t2u, "u_from_tan2": u2t}
    fields = {"obj": d, **terms, "smith": lam is not None, "vndf": False, "sampler": sampler}
    return _add(NDF, D, name, description, citation, aliases, fields)


def register_diffuse(
    name: str, Fd, *, description: str, citation: str = "", aliases=(), with_f0: bool = False, f0_factor: str = "1"
) -> Record:
    """A diffuse BRDF ``Fd(rho, NoL, NoV, LoV, sigma[, f0]) -> float`` for the diffuse, diffuse_3d and btf kinds'
    ``model`` key; ``f0_factor``: how its albedo scales with f0 (lutbake:f0_factor), "1" when it does not read f0."""
    fields = {"Fd": _need_func("Fd", Fd), "with_f0": bool(with_f0), "f0_factor": f0_factor}
    return _add(DIFFUSE, Fd, name, description, citation, aliases, fields)


ROUGHNESS = ("alpha", "perceptual", "none")


def register_brdf(
    name: str, f_cos, *, description: str, citation: str = "", aliases=(), roughness: str = "alpha"
) -> Record:
    """A whole cosine-weighted BRDF ``f_cos(v: vec3, l: vec3, x: float) -> float`` = f(l, v)(n.l) for the ltc kind's
    ``lobe`` key; x is the table's roughness (``roughness``: "alpha", "perceptual" (x = r) or "none")."""
    from .ltc.lobes import custom_lobe

    if roughness not in ROUGHNESS:
        raise RegistryError(f"roughness {roughness!r}: one of {', '.join(ROUGHNESS)}")
    plugin, _ = _caller_plugin(f_cos)
    lobe = custom_lobe(name, _need_func("f_cos", f_cos), roughness, plugin.sha256)
    return _add(LTC_LOBE, f_cos, name, description, citation, aliases, {"obj": lobe, "f_cos": f_cos})


# ---------------------------------------------------------------------------------------------- loading plugins


@contextlib.contextmanager
def _running(plugin: Plugin):
    """Records registered inside belong to ``plugin``; yields the list they are added to. If the block raises, they
    are unregistered again: a plugin that fails leaves no record."""
    outer = getattr(_STATE, "plugin", None), _STATE.__dict__.get("added")
    added: list[Record] = []
    _STATE.plugin, _STATE.added = plugin, added
    try:
        yield added
    except BaseException:
        for record in added:
            FAMILIES[record.family].remove(record)
        raise
    finally:
        _STATE.plugin, _STATE.added = outer


def _module_name(path: str, sha: str) -> str:
    stem = re.sub(r"\W", "_", Path(path).stem)[:40]
    return f"lutbake_plugin_{stem}_{sha[:12]}"


def _failure_line(path: str, e: BaseException) -> int | None:
    if isinstance(e, SyntaxError) and e.filename == path:
        return e.lineno
    lines = [f.lineno for f in traceback.extract_tb(e.__traceback__) if f.filename == path]
    return lines[-1] if lines else None


def _execute(plugin: Plugin) -> list[Record]:
    """Run a plugin's text as the module ``plugin.module`` (its source served from the text, so what runs and
    compiles is what was hashed) and compile its terms; the records it registers. PluginError naming the line on any
    failure; nothing stays registered then."""
    lines = plugin.text.splitlines(True)
    linecache.cache[plugin.path] = (len(plugin.text), None, lines, plugin.path)  # mtime None: never reloaded
    module = type(sys)(plugin.module)
    module.__file__ = plugin.path
    sys.modules[plugin.module] = module
    with _running(plugin) as added:
        try:
            exec(compile(plugin.text, plugin.path, "exec"), module.__dict__)  # noqa: S102 (the user's own plugin)
        except RegistryError as e:
            raise PluginError(plugin.path, _failure_line(plugin.path, e), str(e)) from None
        except Exception as e:
            where = _failure_line(plugin.path, e)
            raise PluginError(plugin.path, where, f"cannot be imported: {type(e).__name__}: {e}") from None
        if not added:
            raise PluginError(plugin.path, None, "registers nothing (call lutbake.register_fresnel, register_ndf, ...)")
        compile_records(added)
    return added


def load_plugin(path) -> list[Record]:
    """Load a plugin file (again when its text changed): run it, register its records, compile its terms. Returns
    its records. PluginError (a ConfigError) names the file and line of any failure; nothing is registered then."""
    path = Path(path).expanduser().resolve()
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise PluginError(str(path), None, f"cannot be read: {getattr(e, 'strerror', None) or e}") from None
    with _LOAD_LOCK:
        held = _LOADED.get(str(path))
        if held is not None and held.text == text:
            return [r for fam in (FRESNEL, NDF, DIFFUSE, LTC_LOBE) for r in fam if r.plugin == held]
        sha = hashlib.sha256(text.encode()).hexdigest()
        plugin = Plugin(str(path), text, _module_name(str(path), sha))
        records = _execute(plugin)
        _LOADED[str(path)] = plugin
        return records


def _ship_loader(plugin: Plugin) -> None:
    """lutbake.registry's hook: a plugin's record unpickled where its text is not loaded (a Dask worker)."""
    with _LOAD_LOCK:
        held = _LOADED.get(plugin.path)
        if held is None or held.text != plugin.text:
            _execute(plugin) if plugin.module.startswith("lutbake_plugin_") else _import_module(plugin)
            _LOADED[plugin.path] = plugin


_PLUGIN_LOADER[:] = [_ship_loader]


def _import_module(plugin: Plugin) -> None:
    with _running(plugin):
        if plugin.module in sys.modules:
            importlib.reload(sys.modules[plugin.module])
        else:
            importlib.import_module(plugin.module)


def load_entry_points() -> list[Record]:
    """Load the installed packages' plugins (entry-point group ``lutbake.plugins``) once per process."""
    global _ENTRY_POINTS_LOADED
    with _LOAD_LOCK:
        if _ENTRY_POINTS_LOADED:
            return []
        _ENTRY_POINTS_LOADED = True
        records = []
        for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
            module = ep.value.split(":")[0]
            spec = importlib.util.find_spec(module)
            origin = spec.origin if spec is not None and spec.origin else f"module {module}"
            text = Path(origin).read_text(encoding="utf-8") if Path(origin).is_file() else ""
            plugin = Plugin(origin, text, module)
            with _running(plugin) as added:
                try:
                    ep.load()
                except RegistryError as e:
                    raise PluginError(f"entry point {ep.name} ({origin})", _failure_line(origin, e), str(e)) from None
                except Exception as e:
                    raise PluginError(
                        f"entry point {ep.name} ({origin})",
                        _failure_line(origin, e),
                        f"cannot be imported: {type(e).__name__}: {e}",
                    ) from None
                compile_records(added)
            _LOADED[origin] = plugin
            records += added
        return records


# ------------------------------------------------------------------------------------------ compiling before work


def compile_records(records: list[Record]) -> None:
    """Compile a probe kernel calling each record's terms (Warp's type checks and code generation), so a term that
    does not compile is refused before any table is planned: PluginError with the file and line of its def."""
    from .runtime.warp_runtime import init_warp

    wp = init_warp()
    for record in records:
        kernel = _probe(wp, record)
        try:
            wp.load_module(kernel.module, device="cpu")
        except Exception as e:
            line, why = _compile_error(record, e)
            raise PluginError(
                record.plugin.path, line, f"{record.family} {record.name!r} does not compile: {why}"
            ) from None


def _compile_error(record: Record, e: Exception) -> tuple[int | None, str]:
    """(the plugin's line Warp's code generation failed at, its last words): Warp names each function it was
    parsing as "at FILE:LINE", outermost first; the last in the plugin's file is the offending statement (else the
    def of the record's first function)."""
    text = str(e).strip().strip("'\"").replace("\\n", "\n")
    lines = re.findall(re.escape(record.plugin.path) + r":(\d+)", text)
    if lines:
        line = int(lines[-1])
    else:
        func = _first_function(record)
        line = inspect.getsourcelines(func.func)[1] + 1 if func is not None else record.line
    why = text.split(";")[-1].strip().splitlines()
    return line, (why[-1] if why else type(e).__name__)


def _first_function(record: Record):
    import warp as wp

    for key in ("F", "D", "Fd", "f_cos"):
        f = record.fields.get(key)
        if isinstance(f, wp.Function):
            return f
    obj = record.fields.get("obj")
    return getattr(obj, "D", None) or getattr(obj, "f_cos", None)


def _probe(wp, record: Record):
    """A kernel that calls every term of ``record`` once (never launched: loading it compiles them), built with
    lutbake's module options (lutbake.runtime.warp_runtime.unique_kernel)."""
    from .runtime.warp_runtime import unique_kernel

    fam = record.family
    if fam == "fresnel":
        F = record["F"]
        Fc = record.get("Fc") or F

        with_fc = record.get("Fc") is not None

        @unique_kernel
        def probe(out: wp.array(dtype=float)):
            out[0] = F(0.5, 0.5)
            if wp.static(with_fc):
                out[0] = out[0] + Fc(0.5)

        return probe
    if fam == "ndf":
        d = record.obj
        D, t2u, u2t = d.D, d.tan2_from_u, d.u_from_tan2
        with_lambda = d.Lambda is not None
        Lam = d.Lambda if with_lambda else d.D  # not called without a Lambda

        @unique_kernel
        def probe(out: wp.array(dtype=float)):
            out[0] = D(wp.vec3(0.0, 0.0, 1.0), 0.5) + float(t2u(wp.float64(0.5), wp.float64(0.5)))
            out[0] = out[0] + float(u2t(wp.float64(0.5), wp.float64(0.5)))
            if wp.static(with_lambda):
                out[0] = out[0] + Lam(0.5, 0.5)

        return probe
    if fam == "diffuse":
        Fd = record["Fd"]
        with_f0 = record.fields["with_f0"]

        @unique_kernel
        def probe(out: wp.array(dtype=float)):
            if wp.static(with_f0):
                out[0] = Fd(1.0, 0.5, 0.5, 0.25, 0.5, 0.04)
            else:
                out[0] = Fd(1.0, 0.5, 0.5, 0.25, 0.5)

        return probe
    f_cos = record.obj.f_cos

    @unique_kernel
    def probe(out: wp.array(dtype=float)):
        out[0] = f_cos(wp.vec3(0.0, 0.0, 1.0), wp.vec3(0.0, 0.0, 1.0), 0.5)

    return probe
