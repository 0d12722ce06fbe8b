"""The size caps every part of lutbake agrees on (a leaf module: configs, kinds, readers and the cluster import it)."""

# --- what a config may ask for (lutbake.config, lutbake.kinds) ------------------------------------------------------
MAX_TEXELS = 1 << 26  # 64 Mi texels of any kind (Kind.texels); float64 accumulation of 4 channels = 2 GiB
# a bake's peak memory per texel, measured (max RSS): a 2048^2 dfg bake 429 MB against 204 MB for 8^2 = 54 bytes a
# texel; 8192^2 (MAX_TEXELS) peaks at 3.4 GB (the float64 values, kernel inputs, the table and its file bytes)
BAKE_PEAK_BYTES_PER_TEXEL = 54
MAX_SAMPLES = 1 << 24  # per texel; beyond this a point set alone needs > 128 MiB and a table takes days
MAX_SEED = (1 << 64) - 1
MAX_LIST = 1024  # entries of a float_list key
MAX_GL_ORDER = 64  # ``samples`` where it is a Gauss-Legendre order (kinds diffuse, btf)

# --- what a reader takes from a file (lutbake.io) -------------------------------------------------------------------
MAX_READ_TEXELS = 2 * MAX_TEXELS  # texels of one file (z x y x x): the largest table a config allows, as an ltc pair
MAX_CHANNELS = 4
MAX_READ_BYTES = MAX_READ_TEXELS * MAX_CHANNELS * 4  # 2 GiB: float32 RGBA at MAX_READ_TEXELS texels
MAX_FILE_BYTES = 4 << 30  # a table is at most 2^24 texels x 4 channels x 4 bytes = 256 MiB; headers are text
MAX_TEXT_BYTES = 64 << 20  # a C/JS/WGSL/Rust array of a 1024^2 RGBA table is about 50 MiB
MAX_JSON_BYTES = 16 << 20  # a sidecar or a cache entry is a few KiB (a listed axis: tens of KiB)
MAX_JSON_DEPTH = 64  # lutbake's deepest JSON is 4 levels (sidecar > lutbake > axes > values)
MAX_SIDECAR_BYTES = 64 << 20  # a sidecar is a few KiB; anything far larger is not one (and is not read)
MAX_AXIS_COUNT = 1 << 20  # no lutbake axis is longer (the texel cap is 2^24 in all)
# the memory budget of a read and its command's work together (lutbake.io.bounded.check_memory)
MAX_READ_MEMORY = 2 << 30  # 2 GiB: a 2^26-texel RGBA float32 table (the largest a config bakes) for inspect
MAX_EXR_CHANNELS = 64  # channels of one EXR part (a table has 1 to 4; other tools add a few named ones)
MAX_EXR_ATTRIBUTES = 1024  # of one part (lutbake writes about 20; renderers a few dozen)
MAX_EXR_HEADER_BYTES = 1 << 20  # of one part's header (lutbake's: a few KiB, its config and axes included)
MAX_EXR_PARTS = 4096  # a 3D table has a part per z index
MAX_EXR_ALL_HEADERS = 16 << 20  # the headers of every part together
MAX_EXTRA_CHARS = 4096  # characters of one extra value in a values-cache entry (lutbake's: numbers, short descriptions)
LTC_FIT_GRID = 32  # the LTC fit's error metric: an N x N grid per sampling technique (ltc_code's Nsample)
BYTES_PER_TEXEL = (
    32  # float64 x 4 channels while baking: a table's values (lutbake.runtime.cluster sizes its transfers)
)
