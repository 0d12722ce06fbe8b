"""The size caps every part of lutbake agrees on (a leaf module: configs, readers and the cluster import it)."""

MAX_TEXELS = 1 << 26  # 64 Mi texels of any kind (Kind.texels); float64 accumulation of 4 channels = 2 GiB
# a bake's peak memory per texel, measured (max RSS): a 2048^2 dfg bake 429 MB against 204 MB for 8^2 = 54 bytes a
# texel; 8192^2 (MAX_TEXELS) peaks at 3.4 GB (the float64 values, kernel inputs, the table and its file bytes)
BAKE_PEAK_BYTES_PER_TEXEL = 54
BYTES_PER_TEXEL = (
    32  # float64 x 4 channels while baking: a table's values (lutbake.runtime.cluster sizes its transfers)
)
