"""Checks of everything a batch will touch on disk, made before any kernel runs (issue 11): what used to fail
after the bake (an out-dir below a file, on a read-only mount or behind a dangling symlink; a --report that
cannot be written or would overwrite an output, its sidecar or a config) is a ConfigError, exit 2, nothing
written. A config path that is not a regular file says what it is."""

from __future__ import annotations

import os
import re
import stat
from pathlib import Path

from .errors import ConfigError

MAX_CONFIG_BYTES = 1 << 20  # a config is a few KiB; a larger file is not one (and is not read into memory)
_FILE_TYPES = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def _what_is(mode: int) -> str:
    return next((name for test, name in _FILE_TYPES if test(mode)), "not a regular file")


def config_file_problem(path) -> str | None:
    """Why ``path`` cannot be read as a config (says what it is), or None for a regular file of sane size."""
    path = Path(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        if os.path.islink(path):
            return f"is a dangling symlink (to {os.readlink(path)!r}): no such config file"
        return "no such config file"
    except NotADirectoryError:
        return "no such config file (a parent in the path is a file)"
    except OSError as e:
        return f"cannot read: {e.strerror or e}"
    if not stat.S_ISREG(st.st_mode):
        return f"is {_what_is(st.st_mode)}, not a config file"
    if st.st_size > MAX_CONFIG_BYTES:
        return f"is {st.st_size} bytes; a config is at most {MAX_CONFIG_BYTES} bytes (is it a config file?)"
    return None


def directory_problem(path) -> str | None:
    """Why lutbake cannot create files in directory ``path`` (made if missing, as mkdir -p would), or None:
    a dangling symlink, a file on the way, a read-only file system, no write permission."""
    path = Path(path)
    probe = path
    while not probe.exists():
        if os.path.islink(probe):
            target = os.readlink(probe)
            return (
                f"is a dangling symlink (to {target!r})"
                if probe == path
                else f"{probe} is a dangling symlink (to {target!r})"
            )
        if probe.parent == probe:
            break
        probe = probe.parent
    if not probe.is_dir():
        return "exists and is not a directory" if probe == path else f"{probe} is a file, not a directory"
    if not os.access(probe, os.W_OK | os.X_OK):
        where = "" if probe == path else f" ({probe})"
        try:
            if os.statvfs(probe).f_flag & os.ST_RDONLY:
                return f"is on a read-only file system{where}"
        except OSError:
            pass
        return f"is not writable{where} (permission denied)"
    return None


def _same(a: Path, b: Path) -> bool:
    return os.path.normcase(os.path.realpath(a)) == os.path.normcase(os.path.realpath(b))


def check_out_dir(out_dir) -> None:
    problem = directory_problem(out_dir)
    if problem:
        raise ConfigError("--out-dir", "out-dir", str(out_dir), message=problem)


def check_outputs(jobs) -> None:
    """Every output path and sidecar path must be a regular file or absent (a directory or device there fails
    the rename after the bake)."""
    from .io.integrity import sidecar_path

    for job in jobs:
        paths = (job.path,) if job.path.suffix == ".exr" else (job.path, sidecar_path(job.path))
        for p in paths:
            if os.path.lexists(p) and not p.is_symlink() and not p.is_file():
                raise ConfigError(
                    job.spec.source,
                    "name",
                    job.name,
                    table=job.name,
                    message=f"its output {p} exists and is {_what_is(os.lstat(p).st_mode)}",
                )


def check_report(report, jobs, configs=()) -> None:
    """``--report`` must be creatable and must not be an output, an output's sidecar or a config."""
    from .io.integrity import sidecar_path

    if report is None:
        return
    report = Path(report)
    if os.path.lexists(report) and not report.is_file():
        what = (
            "is a directory"
            if report.is_dir()
            else (
                "is a dangling symlink" if not report.exists() else f"exists and is {_what_is(os.stat(report).st_mode)}"
            )
        )
        raise ConfigError("--report", "report", str(report), message=what)
    for job in jobs:
        for p, what in ((job.path, "the output"), (sidecar_path(job.path), "the sidecar")):
            if _same(report, p):
                raise ConfigError(
                    "--report",
                    "report",
                    str(report),
                    table=job.name,
                    message=f"is {what} of table '{job.name}'; the report would overwrite it",
                )
    for c in configs:
        if _same(report, Path(c)):
            raise ConfigError("--report", "report", str(report), message=f"is the config {c}; it would be overwritten")
    problem = directory_problem(report.parent)
    if problem:
        raise ConfigError("--report", "report", str(report), message=f"cannot be written: {report.parent}: {problem}")


MAX_NESTING = 32  # arrays / inline tables inside each other; lutbake's deepest value is a list of numbers
MAX_KEY_PARTS = 32  # parts of one dotted key; tomllib takes quadratic time on long ones (20 000 parts: ~45 s)
_STRINGS = re.compile(r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'')
_COMMENT = re.compile(r"#[^\n]*")


def nesting_problem(text: str) -> str | None:
    """Why ``text`` (TOML) is too deeply nested to be a config, found in one linear pass before parsing it
    (a RecursionError or minutes of parsing otherwise), or None."""
    bare = _COMMENT.sub("", _STRINGS.sub('""', text))
    depth = deepest = 0
    for ch in bare:
        if ch in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif ch in "]}":
            depth = max(depth - 1, 0)
    if deepest > MAX_NESTING:
        return f"arrays or inline tables nested {deepest} deep (at most {MAX_NESTING})"
    for line in bare.splitlines():
        key = line.split("=", 1)[0]
        parts = key.count(".") + 1
        if parts > MAX_KEY_PARTS:
            return f"a dotted key of {parts} parts (at most {MAX_KEY_PARTS})"
    return None
