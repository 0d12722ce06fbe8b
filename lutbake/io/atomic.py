"""Atomic file writes shared by every writer: write a temporary sibling, fsync, rename onto the target.
An interrupted or failed write never leaves a half-written file and never clobbers the old one; the temporary
file of a writer killed outright (SIGKILL) is removed by a later run (remove_stale_temps).

A writer that records the sha256 of what it wrote (a sidecar, a cache entry) takes it from the bytes it renamed
(``atomic_write_hashed``: its own temporary file, hashed before the rename), never from the target after the rename:
another run writing the same path may have replaced it in between. ``unit_lock(path)`` keeps concurrent writers of
one output apart while each writes its data file and then its sidecar (threads of this process by a lock per path,
other processes by an flock on the directory), so the pair on disk is always one writer's.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import threading
import uuid
from collections.abc import Callable
from pathlib import Path

try:
    import fcntl
except ImportError:  # Windows: threads of one process are kept apart, other processes are not (the hashes of
    fcntl = None  # what each run wrote still make a mixed pair a rebake, never a skip)


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


TEMP_HEX = 8  # hex digits of the random part of a temporary name


def temp_name(name: str, pid: int | None = None) -> str:
    """``.<name>.<pid>.<8 hex>.tmp<suffix>``: the temporary sibling atomic_write writes ``name`` to."""
    suffix = Path(name).suffix
    return f".{name}.{os.getpid() if pid is None else pid}.{uuid.uuid4().hex[:TEMP_HEX]}.tmp{suffix}"


def atomic_write(path, write: Callable[[Path], None], before_rename: Callable[[Path], None] | None = None) -> Path:
    """Call ``write(tmp)`` for a temporary path beside ``path``, then atomically replace ``path``
    (``before_rename(tmp)`` is called on the complete, fsynced temporary file just before the rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(temp_name(path.name))
    try:
        write(tmp)
        _fsync_file(tmp)
        if before_rename is not None:
            before_rename(tmp)
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


def _sha256_file(path) -> str:
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def atomic_write_hashed(path, write: Callable[[Path], None]) -> str:
    """atomic_write; returns the sha256 of the bytes it renamed onto ``path``, read from its own temporary file
    (no other writer touches it) before the rename."""
    digest: list[str] = []
    atomic_write(path, write, lambda tmp: digest.append(_sha256_file(tmp)))
    return digest[0]


def atomic_write_bytes_hashed(path, data: bytes) -> str:
    """atomic_write_bytes; returns the sha256 of ``data`` (the bytes in hand, not the file after the rename)."""
    atomic_write_bytes(path, data)
    return hashlib.sha256(data).hexdigest()


# ---------------------------------------------------------------------------------------------- unit lock


class _DirectoryShare:
    """An flock on a directory (no lock file is left there), held by this process while any of its threads writes a
    unit in it: the threads share it (a lock per path keeps them apart), another process waits until none writes."""

    def __init__(self, directory: str):
        self.directory, self.mutex, self.users, self.fd = directory, threading.Lock(), 0, None

    def enter(self) -> None:
        with self.mutex:
            if self.users == 0:
                self.fd = _flock(self.directory)
            self.users += 1

    def leave(self) -> None:
        with self.mutex:
            self.users -= 1
            if self.users == 0 and self.fd is not None:
                os.close(self.fd)  # closing the descriptor releases the flock
                self.fd = None


def _flock(directory: str) -> int | None:
    """A descriptor of ``directory`` holding an exclusive flock, or None where none can be taken (no fcntl, a file
    system without flock): then only this process' threads are kept apart."""
    if fcntl is None:
        return None
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
    except OSError:
        os.close(fd)
        return None
    return fd


_REGISTRY = threading.Lock()
_PATH_LOCKS: dict[str, threading.Lock] = {}
_SHARES: dict[str, _DirectoryShare] = {}


@contextlib.contextmanager
def unit_lock(path):
    """Held while one output unit at ``path`` (its data file or files, then its sidecar) is written: no other
    writer of ``path``, in this process or another one using it, writes between the data's rename and the sidecar's."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    directory = os.path.realpath(path.parent)
    with _REGISTRY:
        mine = _PATH_LOCKS.setdefault(os.path.join(directory, path.name), threading.Lock())
        share = _SHARES.setdefault(directory, _DirectoryShare(directory))
    with mine:
        share.enter()
        try:
            yield
        finally:
            share.leave()


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
