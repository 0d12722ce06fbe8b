"""Atomic file writes shared by every writer: write a temporary sibling, fsync, rename onto the target.
An interrupted or failed write never leaves a half-written file and never clobbers the old one; the temporary
file of a writer killed outright (SIGKILL) is removed by a later run (remove_stale_temps)."""

from __future__ import annotations

import os
import re
import uuid
from collections.abc import Callable
from pathlib import Path


def _fsync_file(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(path: Path) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return  # not supported on every platform
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write(path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` for a temporary path beside ``path``, then atomically replace ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp{path.suffix}")
    try:
        write(tmp)
        _fsync_file(tmp)
        os.replace(tmp, path)
    except BaseException:
        try:
            tmp.unlink()
        except FileNotFoundError:
            pass
        raise
    _fsync_dir(path.parent)
    return path


def atomic_write_bytes(path, data: bytes) -> Path:
    return atomic_write(path, lambda tmp: Path(tmp).write_bytes(data))


# ``.<name>.<pid>.<8 hex>.tmp<suffix>``: the temporary siblings atomic_write creates (and nothing else)
TEMP_RE = re.compile(r"\.(?P<name>.+)\.(?P<pid>[1-9][0-9]{0,9})\.[0-9a-f]{8}\.tmp(\.[^./]*)?")


def pid_alive(pid: int) -> bool:
    """True if a process ``pid`` exists on this machine (or may: no permission to signal it)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True  # another user's process, or cannot tell: keep its file
    return True


def remove_stale_temps(directory) -> list[Path]:
    """Remove the temporary files that writers killed before their rename (SIGKILL, power loss) left in
    ``directory``: regular files named as atomic_write names them whose writer's pid is no longer alive on
    this machine. Files of live writers, and anything else, are left alone. Returns the removed paths."""
    removed = []
    try:
        entries = list(os.scandir(directory))
    except OSError:
        return removed
    for e in entries:
        m = TEMP_RE.fullmatch(e.name)
        if m is None or not e.is_file(follow_symlinks=False) or pid_alive(int(m.group("pid"))):
            continue
        try:
            os.unlink(e.path)
            removed.append(Path(e.path))
        except OSError:
            pass  # removed by a concurrent run, or not ours to remove
    return removed
