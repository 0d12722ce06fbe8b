"""Writing a matplotlib figure as a PNG the way every picture command does: atomically (lutbake.io.atomic), the
figure closed afterwards, an OSError named by the PNG's path (not its temporary file)."""

from __future__ import annotations

from pathlib import Path


def save_figure(fig, out, dpi: int = 100) -> Path:
    """Write ``fig`` to ``out`` (PNG) atomically and close it; LutbakeError names ``out`` when it cannot be written."""
    import matplotlib.pyplot as plt

    from ..errors import LutbakeError
    from ..io.atomic import atomic_write
    from ..io.oserror import os_error_text
    from ..textsafe import shorten

    out = Path(out)
    try:
        atomic_write(out, lambda tmp: fig.savefig(tmp, format="png", dpi=dpi))
    except OSError as e:  # the directory changed since it was checked: name the PNG, not the temporary file
        e.filename = None
        raise LutbakeError(f"cannot write {shorten(str(out))}: {os_error_text(e, out.parent)}") from None
    finally:
        plt.close(fig)
    return out
