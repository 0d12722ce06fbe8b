"""The first function lutbake.runtime.cluster runs on a Dask worker: it reports what the worker would bake with.

lutbake.runtime.cluster registers this module with cloudpickle to be pickled *by value*, so the probe reaches a
worker that cannot import lutbake (not installed, or broken) and reports that as a refusal, instead of
failing while unpickling a reference to a module the worker lacks. It must therefore import nothing
from lutbake at module level.
"""


def probe() -> dict:
    """lutbake.runtime.cluster.worker_info() of this worker, or {"error": why lutbake cannot be imported here}."""
    try:
        from lutbake.runtime import cluster
    except Exception as e:  # ImportError, or a broken install raising anything while importing
        return {"error": f"cannot import lutbake ({type(e).__name__}: {e})"}
    return cluster.worker_info()
