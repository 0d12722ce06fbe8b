"""Writers and readers for baked tables. EXR through OpenImageIO is the default format."""

from .exr import describe_exr, read_exr, write_exr

__all__ = ["describe_exr", "read_exr", "write_exr"]
