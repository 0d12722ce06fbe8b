"""lutbake: bake pre-integrated BRDF tables with Warp kernels on the CPU.

import lutbake
results = lutbake.bake(["configs/dfg.toml"], out_dir="outputs")
"""

__version__ = "0.1.0"

from .api import BakeResult, bake, bake_table  # noqa: E402
from .config import TableSpec, load_config, load_configs  # noqa: E402
from .table import Table  # noqa: E402

__all__ = ["bake", "bake_table", "BakeResult", "load_config", "load_configs", "TableSpec", "Table", "__version__"]
