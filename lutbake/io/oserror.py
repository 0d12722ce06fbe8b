"""A write error said in words that name its cause. OpenImageIO reports a full disk as "File output failed"
(no errno); Python's own writers carry the errno (ENOSPC, EROFS, EDQUOT ...) but print it as
"[Errno 28] ...". os_error_text() names the cause either way (issue 11)."""

from __future__ import annotations

import errno
import shutil

LOW_SPACE_BYTES = 1 << 20  # a failed write with less free space than this (plus the data) is a full disk
CAUSES = {
    errno.ENOSPC: "no space left on device",
    errno.EDQUOT: "disk quota exceeded",
    errno.EROFS: "read-only file system",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.EFBIG: "file too large",
    errno.EIO: "input/output error",
}


def os_error_text(e: OSError, directory=None, needed: int = 0) -> str:
    """``e`` as one line naming the cause, e.g. ``no space left on device (12.0 KiB free in out): ...``."""
    cause = CAUSES.get(e.errno) if e.errno else None
    free = None
    if directory is not None:
        try:
            free = shutil.disk_usage(directory).free
        except OSError:
            pass
    if cause is None and e.errno is None and free is not None and free < needed + LOW_SPACE_BYTES:
        cause = "no space left on device"  # the only cause that fits a bare "write failed" on a nearly full disk
    detail = e.strerror if e.errno and e.strerror else str(e)
    if e.filename and str(e.filename) not in detail:
        detail += f": {e.filename}"
    if cause is None:
        return detail
    if cause == "no space left on device" and free is not None:
        cause += f" ({free} bytes free in {directory})"
    return f"{cause}: {detail}"
