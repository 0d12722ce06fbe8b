"""Checks of everything a batch will touch on disk, made before any kernel runs (issue 11): what used to fail
after the bake (an out-dir below a file, on a read-only mount or behind a dangling symlink; a --report that
cannot be written or would overwrite an output, its sidecar or a config) is a ConfigError, exit 2, nothing
written. (The config files' own checks, made before they are parsed, are lutbake.config_file's.)"""

from __future__ import annotations

import errno
import os
import tempfile
from pathlib import Path

from .config_file import encoding_problem
from .errors import ConfigError
from .io.bounded import what_is
from .textsafe import shorten


def directory_problem(path, attempts: int = 3) -> str | None:
    """Why lutbake cannot create files in directory ``path`` (made if missing, as mkdir -p would), or None:
    a dangling symlink, a symlink loop, a file on the way, a read-only file system, no write permission. A directory
    another run's probe made and removed while this one looked is looked at again (``attempts`` times)."""
    path = Path(path)
    for _ in range(attempts):
        problem = _directory_problem_once(path)
        if problem != _VANISHED:
            return problem
    return None  # made and removed under us every time: the probe (probe_directory) tries it for real


_VANISHED = "vanished"  # the directory looked at was removed meanwhile (another run's probe): look again


def _directory_problem_once(path: Path) -> str | None:
    probe = path
    while not probe.exists():
        if os.path.islink(probe):
            where = "" if probe == path else f"{probe} "
            target = os.readlink(probe)
            if _stat_errno(probe) == errno.ELOOP:
                return f"{where}is a symlink loop (to {target!r})"
            return f"{where}is a dangling symlink (to {target!r})"
        if probe.parent == probe:
            break
        probe = probe.parent
    if not probe.is_dir():
        if not os.path.lexists(probe):
            return _VANISHED
        return "exists and is not a directory" if probe == path else f"{probe} is a file, not a directory"
    if not os.access(probe, os.W_OK | os.X_OK):
        if not os.path.lexists(probe):
            return _VANISHED
        where = "" if probe == path else f" ({probe})"
        try:
            if os.statvfs(probe).f_flag & os.ST_RDONLY:
                return f"is on a read-only file system{where}"
        except OSError:
            pass
        return f"is not writable{where} (permission denied)"
    return None


def _stat_errno(path) -> int:
    try:
        os.stat(path)
    except OSError as e:
        return e.errno or 0
    return 0


def _real_key(path) -> str:
    return "real:" + os.path.normcase(os.path.realpath(path))


def _same(a: Path, b: Path) -> bool:
    return _real_key(a) == _real_key(b)


def probe_directory(path, attempts=3) -> str | None:
    """Why no file can be created in directory ``path``, found by trying: create it (mkdir -p), create and remove a
    temporary file in it, then remove the directories this probe made, or None. Catches what permission bits do not
    tell (root on /proc or /sys, a read-only bind mount, a full inode table). Two runs probing one new directory at
    once race: a directory the other made first is used, not an error, and a directory it removed under this probe
    is tried again (``attempts`` times)."""
    path = Path(path)
    for attempt in range(attempts):
        made = []
        try:
            missing = []
            probe = path
            while not os.path.lexists(probe) and probe.parent != probe:
                missing.append(probe)
                probe = probe.parent
            for d in reversed(missing):
                try:
                    os.mkdir(d)
                    made.append(d)
                except FileExistsError:
                    if not os.path.lexists(d):  # another run's probe made it and removed it since: try again
                        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), str(d)) from None
                    if not os.path.isdir(d):
                        raise
            fd, tmp = tempfile.mkstemp(prefix=".lutbake-probe.", dir=path)
            os.close(fd)
            os.unlink(tmp)
            return None
        except OSError as e:
            if isinstance(e, FileNotFoundError) and attempt < attempts - 1:
                continue
            from .io.oserror import os_error_text

            return f"cannot create files there: {os_error_text(e)}"
        finally:
            for d in reversed(made):
                try:
                    os.rmdir(d)
                except OSError:
                    pass
    return None


def check_out_dir(out_dir) -> None:
    """``--out-dir`` names a directory lutbake can create files in (tried, and left as it was): exit 2 before any
    kernel runs, not a failed write after the bake."""
    _check_directory("--out-dir", out_dir)


def check_cache(cache_dir) -> None:
    """``--cache DIR`` is checked as ``--out-dir`` is (a read-only file system, below a file, a dangling symlink or a
    symlink loop, too long): exit 2 before any kernel, not every entry silently unwritten."""
    if cache_dir is not None:
        _check_directory("--cache", cache_dir)


def _check_directory(option: str, directory) -> None:
    try:
        problem = (
            encoding_problem(directory)
            or length_problem([Path(directory) / PROBE_NAME])
            or directory_problem(directory)
            or probe_directory(directory)
        )
    except OSError as e:  # whatever the checks above did not foresee: one line, not a traceback
        from .io.oserror import os_error_text

        problem = f"cannot be used: {os_error_text(e)}"
    if problem:
        raise ConfigError(option, option.lstrip("-"), shorten(str(directory)), message=problem)


PROBE_NAME = ".lutbake-probe.XXXXXXXX"  # as long as probe_directory's temporary file (mkstemp: 8 random characters)
DEFAULT_PATH_MAX, DEFAULT_NAME_MAX = 4096, 255  # Linux's, where os.pathconf tells none


def path_limits(path) -> tuple[int, int]:
    """(PATH_MAX, NAME_MAX) in bytes (PATH_MAX counts the final NUL) of the file system ``path`` is or will be on:
    os.pathconf of its nearest existing ancestor."""
    probe = Path(path)
    while not os.path.isdir(probe) and probe.parent != probe:  # isdir: False, not an error, for a too-long path
        probe = probe.parent
    limits = []
    for name, default in (("PC_PATH_MAX", DEFAULT_PATH_MAX), ("PC_NAME_MAX", DEFAULT_NAME_MAX)):
        try:
            value = os.pathconf(probe, name)
        except (OSError, ValueError, AttributeError):  # no such limit, no os.pathconf (Windows)
            value = None
        limits.append(value if value and value > 0 else default)
    return limits[0], limits[1]


def length_problem(paths) -> str | None:
    """Why one of ``paths`` (files a run will create, as it will spell them) cannot be created: a name over NAME_MAX
    or a path over PATH_MAX (os.pathconf, path_limits), or None."""
    for p in paths:
        path_max, name_max = path_limits(Path(p).parent)
        raw = os.fsencode(str(p))
        if len(raw) + 1 > path_max:
            return (
                f"the path {shorten(str(p))} this run would create is {len(raw)} bytes long; the file system takes "
                f"at most {path_max - 1} (PATH_MAX): choose a shorter path"
            )
        for part in Path(p).parts:
            if len(os.fsencode(part)) > name_max:
                return (
                    f"the file name {shorten(part)} this run would create is {len(os.fsencode(part))} bytes long; "
                    f"the file system takes at most {name_max} (NAME_MAX)"
                )
    return None


def created_paths(jobs, cache_dir=None, report=None) -> list[tuple[str, object, list[Path]]]:
    """(option, its value, the paths it makes this run create): every planned file of the pending tables (data,
    second texture, sidecar) and the temporary sibling each is written to first (lutbake.io.atomic.temp_name), the
    cache entries and their temporary files, the report and its temporary file."""
    from .io.atomic import temp_name

    def with_temps(paths):
        return [q for p in paths for q in (p, p.with_name(temp_name(p.name)))]

    groups = []
    pending = [j for j in jobs if j.status == "pending"]
    for job in pending:
        groups.append(("--out-dir", job.path.parent, with_temps([p for p, _ in planned_files(job)])))
    if cache_dir is not None:
        groups.append(("--cache", cache_dir, with_temps(cache_entries(pending, cache_dir))))
    if report is not None:
        groups.append(("--report", report, with_temps([Path(report)])))
    return groups


def check_path_lengths(jobs, cache_dir=None, report=None) -> None:
    """The longest path this run will create (created_paths: temporary names, sidecars, cache entries, the report)
    within the OS limits (length_problem): exit 2 before any kernel, not a failed rename after the bake."""
    for option, value, paths in created_paths(jobs, cache_dir, report):
        problem = length_problem(sorted(paths, key=lambda p: -len(os.fsencode(str(p)))))
        if problem:
            raise ConfigError(option, option.lstrip("-"), shorten(str(value)), message=problem)


# a file set's later members (lutbake.io.file_sets: at most MAX_LOBES x 3 files)
ORDINALS = ("second", "third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth")


def planned_files(job) -> list[tuple[Path, str]]:
    """Every file the bake of ``job`` writes, with what it is: the data file, the other files of a file set (ltc_dds's
    ``<name>_2.dds``, an ltc_aniso table's ``<name>_t1.ktx2``: lutbake.io.file_sets), the files its kind writes beside
    them (an irradiance cube's ``<name>_sh.json``: Kind.outputs), and the ``.json`` sidecar of each (EXR carries its
    metadata in its header). The one registry of output paths: collisions, ``--report`` and the preview/error-map
    guards all read it."""
    from .config import kind_of
    from .io.file_sets import set_files
    from .io.integrity import sidecar_path

    fmt = job.spec.options.get("format", "exr")
    files = [(job.path, "output")]
    others = (set_files(job.name, job.spec.kind, fmt, job.spec.options) or [])[1:]
    files += [(job.path.with_name(name), f"{ORDINALS[k]} texture") for k, name in enumerate(others)]
    files += [(job.path.with_name(job.name + suffix), what) for suffix, what in kind_of(job.spec).outputs]
    # an EXR writes none, but <name>.exr.json is where readers look for one: it is claimed too
    files += [(sidecar_path(p), f"sidecar of {p.name}") for p, _ in list(files)]
    return files


def path_key(path) -> str:
    """One key for every spelling of a file: the real parent directory, and the name with case folded (``D.exr``
    and ``d.exr`` are one file on macOS, Windows and a case-insensitive mount)."""
    path = Path(path)
    parent = os.path.realpath(path.parent)
    return os.path.join(os.path.normcase(parent), path.name.casefold())


def _name_error(job, message: str) -> ConfigError:
    """A ConfigError blaming table ``job``'s name (the file it writes) in its config."""
    return ConfigError(job.spec.source, "name", job.name, table=job.name, message=message)


def check_collisions(jobs) -> None:
    """No two tables of a batch write one file (data, second texture or sidecar), including names that differ
    only in case: an ltc_dds table ``foo`` writes ``foo_1.dds``, as a dds table ``foo_1`` does."""
    owners: dict[str, tuple] = {}
    for job in jobs:
        for p, what in planned_files(job):
            key = path_key(p)
            if key in owners and owners[key][0] is not job:
                other, other_path, other_what = owners[key]
                same = "" if other_path.name == p.name else f" ({other_path.name} and {p.name} differ only in case)"
                raise _name_error(
                    job,
                    f"its {what} {p} is also the {other_what} of table '{other.name}' "
                    f"({other.spec.source}){same}: the two tables would overwrite each other; rename one",
                )
            owners[key] = (job, p, what)


def check_outputs(jobs) -> None:
    """No two tables write one file (check_collisions). Every file a table writes (planned_files) must be a regular
    file or absent (a directory or device there fails the rename after the bake); a ``png16`` output must be a 2D
    table (PNG has no depth: the table's shape comes from its plan, lutbake.batch.Job.plan, built once and baked
    later; building it runs no kernel)."""
    check_collisions(jobs)
    for job in jobs:
        if job.status == "pending" and job.spec.options.get("format") == "png16":
            shape = job.plan().shape
            if len(shape) > 3:
                raise ConfigError(
                    job.spec.source,
                    "format",
                    "png16",
                    "exr, npy, dds, ktx2, h",
                    f"png16 holds 2D tables only; this table is {' x '.join(map(str, shape[:-1]))} texels",
                    table=job.name,
                )
        for p, _ in planned_files(job):
            if os.path.lexists(p) and not p.is_symlink() and not p.is_file():
                raise ConfigError(
                    job.spec.source,
                    "name",
                    job.name,
                    table=job.name,
                    message=f"its output {p} exists and is {what_is(os.lstat(p).st_mode)}",
                )


def _is(a, b) -> bool:
    """``a`` and ``b`` name one file: the same real path, or one name in one real directory (case folded)."""
    return _same(a, b) or path_key(a) == path_key(b)


def input_claims(jobs, configs=(), cache_dir=None) -> list[tuple[Path, str]]:
    """Every path a run reads or keeps that no table may write, with what it is: each config (a preset's file too),
    the --cache directory and the cache entries this run may write (one per pending values key,
    lutbake.values_cache)."""
    claims = [(Path(c), f"the config {c}") for c in configs]
    if cache_dir is not None:
        claims.append((Path(cache_dir), f"the --cache directory {cache_dir}"))
        claims += [(e, f"a --cache entry in {cache_dir}") for e in cache_entries(jobs, cache_dir)]
    return claims


def cache_entries(jobs, cache_dir) -> list[Path]:
    """The files of the cache entries this run may write in ``cache_dir``: one .npy and one .json per values key of
    the pending tables (lutbake.values_cache.ValuesCache.paths); a cube (a kind baked whole) has none."""
    from .config import kind_of

    keys = sorted({j.values_key for j in jobs if j.status == "pending" and j.values_key and not kind_of(j.spec).bake})
    return [Path(cache_dir) / f"{key}{ext}" for key in keys for ext in (".npy", ".json")]


def check_inputs(jobs, configs=(), cache_dir=None) -> None:
    """No file a table writes (planned_files: an output, a second texture, a sidecar) is a config, the --cache
    directory or a cache entry (input_claims): the bake would overwrite its own input. ConfigError naming both."""
    claims = {}
    for c, claim in input_claims(jobs, configs, cache_dir):  # each spelling of the file: _is, looked up in one step
        claims.setdefault(_real_key(c), claim)
        claims.setdefault(path_key(c), claim)
    for job in jobs:
        for p, what in planned_files(job):
            claim = claims.get(_real_key(p)) or claims.get(path_key(p))
            if claim is not None:
                raise _name_error(
                    job,
                    f"its {what} ({shorten(str(p))}) is {shorten(claim)}; the bake would overwrite it: "
                    "rename the table or that file, or choose another --out-dir",
                )


def check_report(report, jobs, configs=(), cache_dir=None) -> None:
    """``--report`` must be creatable and must not be any file a table writes (planned_files: an output, a second
    texture, a sidecar), a config, the --cache directory or a cache entry (input_claims)."""
    if report is None:
        return
    report = Path(report)
    problem = encoding_problem(report)
    if problem:
        raise ConfigError("--report", "report", shorten(str(report)), message=problem)
    if os.path.lexists(report) and not report.is_file():
        what = (
            "is a directory"
            if report.is_dir()
            else (
                "is a dangling symlink" if not report.exists() else f"exists and is {what_is(os.stat(report).st_mode)}"
            )
        )
        raise ConfigError("--report", "report", str(report), message=what)
    for job in jobs:
        for p, what in planned_files(job):
            if _same(report, p) or path_key(report) == path_key(p):
                raise ConfigError(
                    "--report",
                    "report",
                    str(report),
                    table=job.name,
                    message=f"is the {what} of table '{job.name}'; the report would overwrite it",
                )
    for c, claim in input_claims(jobs, configs, cache_dir):
        if _is(report, c):
            raise ConfigError("--report", "report", str(report), message=f"is {claim}; it would be overwritten")
    problem = directory_problem(report.parent)
    if problem:
        raise ConfigError("--report", "report", str(report), message=f"cannot be written: {report.parent}: {problem}")


def input_files(path) -> list[Path]:
    """The files reading ``path`` touches: itself, its sidecars, the data file a sidecar names, the other files of a
    file set (an ltc_dds pair's other texture, lutbake.io.file_sets) (what ``preview -o`` / ``audit --error-map`` must
    never overwrite)."""
    from .io.file_sets import members
    from .io.readers import sidecar_candidates

    path = Path(path)
    files = [path, *sidecar_candidates(path)]
    for other in members(path):
        if other != path:
            files += [other, *sidecar_candidates(other)]
    if path.name.endswith(".json"):
        files.append(path.with_name(path.name[: -len(".json")]))
    return files


def check_image_output(out, inputs=(), force: bool = False, option: str = "--out") -> None:
    """A PNG that ``preview`` / ``audit --error-map`` will write: not one of ``inputs`` (the table, its sidecars, a
    config: input_files), not a directory or device, ending in ``.png`` unless ``force``, and in a directory that
    takes files (tried). ConfigError, before any figure is drawn."""
    if out is None:
        return
    out = Path(out)
    shown = shorten(str(out))
    problem = encoding_problem(out)
    if problem:
        raise ConfigError(option, option.lstrip("-"), shown, message=problem)
    for p in inputs:
        if p is not None and (_same(out, p) or path_key(out) == path_key(p)):
            raise ConfigError(
                option,
                option.lstrip("-"),
                shown,
                message=f"is an input of this command ({shorten(str(p))}); it would be overwritten with a PNG",
            )
    if os.path.lexists(out) and not out.is_file():
        what = what_is(os.stat(out).st_mode) if out.exists() else "a dangling symlink"
        raise ConfigError(option, option.lstrip("-"), shown, message=f"exists and is {what}")
    if out.suffix.lower() in (".toml", ".json"):  # a config or a sidecar, even with --force
        raise ConfigError(
            option, option.lstrip("-"), shown, message="names a config or sidecar; write the PNG elsewhere"
        )
    if out.suffix.lower() != ".png" and not force:
        raise ConfigError(
            option,
            option.lstrip("-"),
            shown,
            message="does not end in .png; this writes a PNG image (--force writes it under this name anyway)",
        )
    problem = directory_problem(out.parent) or probe_directory(out.parent)
    if problem:
        raise ConfigError(option, option.lstrip("-"), shown, message=f"{shorten(str(out.parent))} {problem}")
