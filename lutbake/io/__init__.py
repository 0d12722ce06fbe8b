"""Writers and readers for baked tables. EXR through OpenImageIO is the default format; lutbake.io.readers
reads every format lutbake writes, lutbake.io.describe says what a file holds (``lutbake inspect``)."""

from .exr import read_exr, write_exr

__all__ = ["read_exr", "write_exr"]
