"""lutbake: bake pre-integrated BRDF tables with Warp kernels on the CPU.

import lutbake
results = lutbake.bake(["configs/dfg.toml"], out_dir="outputs", overrides=["samples=2048", "dfg.dtype=half"])
"""

__version__ = "0.1.0"

# imported on first use (PEP 562), so the command line starts without numpy/Warp and a Ctrl-C during those
# imports is handled by lutbake._entry, not printed as a traceback
_EXPORTS = {
    "bake": "api",
    "bake_table": "api",
    "BakeResult": "api",
    "TableSpec": "config",
    "load_config": "config",
    "load_configs": "config",
    "Table": "table",
    "ConfigError": "errors",  # every wrong input of the API (docs/batch.md)
    "LutbakeError": "errors",
    "TableError": "errors",
    # your own BRDF terms (docs/plugins.md)
    "register_fresnel": "plugins",
    "register_ndf": "plugins",
    "register_diffuse": "plugins",
    "register_brdf": "plugins",
    "load_plugin": "plugins",
}


def __getattr__(name: str):
    if name in _EXPORTS:
        import importlib

        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    """The module's names and the public API still to be imported (PEP 562), so ``dir(lutbake)`` lists it."""
    return sorted(set(globals()) | set(__all__))


__all__ = ["bake", "bake_table", "BakeResult", "load_config", "load_configs", "TableSpec", "Table", "__version__"]
__all__ += ["ConfigError", "LutbakeError", "TableError"]
__all__ += ["register_fresnel", "register_ndf", "register_diffuse", "register_brdf", "load_plugin"]
