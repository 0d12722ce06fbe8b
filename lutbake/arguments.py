"""The Python API's arguments checked at its entry (lutbake.bake, bake_table, load_config, load_configs): a wrong
type or value raises lutbake.errors.ArgumentError (a ConfigError) naming the function, the argument and what it
accepts, never a TypeError or KeyError from deep inside, and a str is never iterated character by character."""

from __future__ import annotations

import os
from pathlib import Path

from .errors import ArgumentError

PATH = "a path (str or pathlib.Path)"


def is_path(value) -> bool:
    return isinstance(value, (str, os.PathLike)) and not isinstance(value, bytes)


def path_arg(function: str, argument: str, value, optional: bool = False) -> Path | None:
    """``value`` as a Path (None when ``optional`` and None)."""
    if value is None and optional:
        return None
    if not is_path(value) or isinstance(os.fspath(value), bytes):
        raise ArgumentError(function, argument, value, PATH + (" or None" if optional else ""))
    return Path(value)


def configs_arg(function: str, argument: str, value, item_types: tuple = (), what: str = PATH) -> list:
    """One config or a list / tuple of them: paths (as Paths) or instances of ``item_types`` (``what`` says which)."""
    items = [value] if is_path(value) or isinstance(value, item_types) else value
    accepted = f"{what}, or a list of them"
    if not isinstance(items, (list, tuple)):
        raise ArgumentError(function, argument, value, accepted)
    out = []
    for item in items:
        if isinstance(item, item_types):
            out.append(item)
        elif is_path(item) and not isinstance(os.fspath(item), bytes):
            out.append(Path(item))
        else:
            raise ArgumentError(function, f"{argument} (an entry)", item, accepted)
    return out


def overrides_arg(function: str, value) -> list:
    """``--set`` texts ("KEY=VALUE", "TABLE.KEY=VALUE"; one str alone is one) or (table, key, value[, blamed])
    tuples as lutbake.config.parse_overrides returns them."""
    items = [value] if isinstance(value, str) else value
    accepted = "'KEY=VALUE' / 'TABLE.KEY=VALUE' strings or (table or None, key, value) tuples, in a list"
    if not isinstance(items, (list, tuple)):
        raise ArgumentError(function, "overrides", value, accepted)
    for item in items:
        ok = isinstance(item, str) or (
            isinstance(item, tuple)
            and len(item) in (3, 4)
            and (item[0] is None or isinstance(item[0], str))
            and isinstance(item[1], str)
        )
        if not ok:
            raise ArgumentError(function, "overrides (an entry)", item, accepted)
    return list(items)


def workers_arg(function: str, value) -> int | None:
    if value is not None and (isinstance(value, bool) or not isinstance(value, int) or value < 1):
        raise ArgumentError(function, "workers", value, "an integer >= 1 or None (every core)")
    return value


def device_arg(function: str, value) -> str:
    if not isinstance(value, str) or not (value == "cpu" or value == "cuda" or value.startswith("cuda:")):
        raise ArgumentError(function, "device", value, "'cpu' or 'cuda' (a Warp device: 'cuda:N')")
    return value


def flag_arg(function: str, argument: str, value) -> bool:
    if not isinstance(value, bool):
        raise ArgumentError(function, argument, value, "True or False")
    return value


def callback_arg(function: str, argument: str, value):
    if value is not None and not callable(value):
        raise ArgumentError(function, argument, value, "a callable or None")
    return value


def text_arg(function: str, argument: str, value, what: str) -> str | None:
    if value is not None and not isinstance(value, str):
        raise ArgumentError(function, argument, value, f"{what} (a str) or None")
    return value
