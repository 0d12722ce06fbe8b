"""lutbake: bake pre-integrated BRDF tables with Warp kernels on the CPU.

    import lutbake
    results = lutbake.bake(["configs/dfg.toml"], out_dir="outputs")

The names below are imported on first use (PEP 562), so ``import lutbake`` and the commands that do
not bake (``lutbake --help``, ``list``, ``inspect``, ``preview``) never load Warp.
"""

__version__ = "0.1.0"

_EXPORTS = {
    "bake": "api",
    "bake_table": "api",
    "BakeResult": "api",
    "load_config": "config",
    "load_configs": "config",
    "TableSpec": "config",
    "Table": "table",
}
__all__ = ["bake", "bake_table", "BakeResult", "load_config", "load_configs", "TableSpec", "Table", "__version__"]


def __getattr__(name):
    if name in _EXPORTS:
        import importlib

        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'lutbake' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_EXPORTS))
