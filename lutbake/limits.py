"""The size caps every part of lutbake agrees on (a leaf module: configs, readers and the cluster import it)."""

MAX_TEXELS = 1 << 26  # 64 Mi texels of any kind (Kind.texels); float64 accumulation of 4 channels = 2 GiB
