"""Engine layouts of an ``ltc`` table (slice 0 = ltc_code's ltc_1, slice 1 = ltc_2; lutbake.kinds.ltc), behind the
formats ``ltc_dds``, ``js``, ``c`` and ``cs`` of lutbake.io.formats.

| format | files | what an engine does with them |
| --- | --- | --- |
| ``ltc_dds`` | <name>_1.dds, <name>_2.dds (+ .json) | ltc_code fit/results/ltc_1.dds, ltc_2.dds: RGBA16F (dtype half) |
| ``js`` | <name>.js (+ .json) | three.js: ``new DataTexture(LTC_MAT_1, N, N, RGBAFormat, FloatType, UVMapping, |
|  |  | ClampToEdgeWrapping, ClampToEdgeWrapping, LinearFilter, NearestFilter, 1)`` as RectAreaLightTexturesLib's |
|  |  | LTC_FLOAT_1 (LTC_HALF_*: DataUtils.toHalfFloat of the same arrays) |
| ``c`` | <name>.cc (+ .json) | Blender EEVEE eevee_lut.cc: ltc_mat_<lobe>[N][N][4], ltc_mag_<lobe>[N][N][2], |
|  |  | ltc_disk_integral[N][N][1] (rows = sqrt(1 - NoV), columns = roughness) |
| ``cs`` | <name>.cs (+ .json) | Unity HDRP LtcData.BRDF_<lobe>.cs: ushort[N * N * 4] of FP16 bits, one slice of its |
|  |  | Texture2DArray _LtcData (R16G16B16A16_SFloat); (M^-1_00, M^-1_20, M^-1_11, M^-1_02) / M^-1_22 |
| ``babylon_fuzz`` | <name>.dds (+ .json) | Babylon.js scene.environmentFuzzBRDFTexture: one RGBA16F (or 32F) DDS, |
|  |  | (A, B, R_i) of a normal-frame fit coded by getFuzzBRDFLookup's mix() (lutbake.layouts.babylon) |
| ``babylon_ltc`` | <name>.bin (+ .json) | Babylon.js areaLightsLTC.bin (Lights/LTC/ltcTextureTool.js |
|  |  | DecodeLTCTextureDataAsync): per texel 8 FP16 values, ltc_1 RGBA then ltc_2 RGBA, split into |
|  |  | scene._ltcTextures LTC1 / LTC2 (RawTexture RGBA, HALF_FLOAT, bilinear, clamp, invertY false) |
| ``ltc_aniso_npy`` | <name>.npy (+ .json) | the anisotropic LTC paper's LUT/*.npy: M (N, N, N, N, 3, 3) of a kind |
|  |  | ltc_aniso table (AakashKT/LTC-Anisotropic; lutbake.kinds.ltc_aniso) |
Every array is row 0 first (row = view index t, column = roughness index a: element a + t N, as ltc_code's
tab[a + t*N]); ltc_2's .z (lutbake's fit_error) is written as 0 as in ltc_code.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..table import Table
from .conventions import write_conventions, write_with_sidecar

FP16_MAX = 65504.0
EXTENSIONS = {
    "ltc_dds": "_1.dds",
    "js": ".js",
    "c": ".cc",
    "cs": ".cs",
    "babylon_fuzz": ".dds",
    "babylon_ltc": ".bin",
    "ltc_aniso_npy": ".npy",
}
FORMATS = {  # js: lutbake.io.code_arrays' format, which writes an ltc table as three.js' module (write_js)
    "ltc_dds": "ltc_code's two files <name>_1.dds, <name>_2.dds: RGBA16F (dtype half) or RGBA32F (kind ltc)",
    "c": "Blender EEVEE C arrays ltc_mat_<lobe>, ltc_mag_<lobe>, ltc_disk_integral (kind ltc)",
    "cs": "Unity HDRP C# table s_LtcMatrixData_BRDF_<LOBE>, FP16 bits of one RGBA16F slice (kind ltc)",
    "babylon_fuzz": "Babylon.js environmentFuzzBRDFTexture: one DDS, RGBA16F (half) or RGBA32F, (A, B, R_i) coded by "
    "getFuzzBRDFLookup's mix() ranges (kind ltc, normal-frame lobes: zeltner)",
    "babylon_ltc": "Babylon.js RectAreaLight's areaLightsLTC.bin: per texel ltc_1 RGBA then ltc_2 RGBA, always FP16 "
    "(kind ltc)",
    "ltc_aniso_npy": "the anisotropic LTC paper's layout: M (N, N, N, N, 3, 3) float32 + .json sidecar "
    "(kind ltc_aniso)",
}


def engine_textures(table: Table) -> tuple[np.ndarray, np.ndarray]:
    """(ltc_1, ltc_2) float32 (N, N, 4), ltc_2.z = 0 (the engines' unused channel)."""
    if table.kind != "ltc":
        raise ValueError(
            f"table {table.name!r}: the LTC layouts (ltc_dds, js, c) hold kind 'ltc' tables only, not {table.kind!r}"
        )
    t1 = np.asarray(table.data[0], np.float32)
    t2 = np.asarray(table.data[1], np.float32).copy()
    t2[..., 2] = 0.0
    return t1, t2


def _flat(a: np.ndarray, fmt: str = "{:.9g}") -> str:
    items = [fmt.format(float(x)) for x in a.ravel()]
    return ",\n".join(", ".join(items[i : i + 8]) for i in range(0, len(items), 8))


def write_ltc_dds(table: Table, path, dtype: str = "half") -> Path:
    from . import dds
    from .atomic import atomic_write_bytes_hashed

    t1, t2 = engine_textures(table)
    path = Path(path)
    second = path.with_name(path.name.replace("_1.dds", "_2.dds"))
    np_dtype = np.float16 if dtype == "half" else np.float32
    digests = {second.name: atomic_write_bytes_hashed(second, dds.encode(t2.astype(np_dtype)))}
    digests[path.name] = atomic_write_bytes_hashed(path, dds.encode(t1.astype(np_dtype)))
    write_conventions(
        table,
        path,
        "ltc_dds",
        {
            "files": [path.name, second.name],
            "dxgi_format": "R16G16B16A16_FLOAT" if dtype == "half" else "R32G32B32A32_FLOAT",
            "ltc_2_z": "0 (lutbake's fit_error is in the EXR only)",
        },
        digests=digests,
    )
    return path


def js_text(table: Table) -> str:
    from .. import __version__

    t1, t2 = engine_textures(table)
    n_y, n_x = t1.shape[:2]
    return (
        f"// {table.name}.js -- LTC tables generated by lutbake {__version__} (kind ltc, lobe "
        f"{table.attributes.get('terms', '')}); do not edit.\n"
        "// Heitz, Dupuy, Hill & Neubelt 2016, Real-Time Polygonal-Light Shading with Linearly Transformed Cosines.\n"
        f"// Layout of three.js RectAreaLightTexturesLib LTC_MAT_1 / LTC_MAT_2 (= selfshadow/ltc_code ltc.js): "
        f"{n_x} x {n_y} RGBA,\n"
        "// element (a + t * N) * 4 + c, a = roughness index (x), t = sqrt(1 - NoV) index (y), endpoint texels.\n"
        "// LTC_MAT_1 = inverse matrix (m00, m20, m02, m22) / m11; LTC_MAT_2 = (magnitude, fresnel, 0, sphere).\n"
        "// three.js: new DataTexture(LTC_MAT_1, N, N, RGBAFormat, FloatType, UVMapping, ClampToEdgeWrapping,\n"
        "//   ClampToEdgeWrapping, LinearFilter, NearestFilter, 1); half: DataUtils.toHalfFloat per element.\n"
        f"export const LTC_SIZE = {n_x};\n"
        f"export const LTC_MAT_1 = new Float32Array([\n{_flat(t1)}\n]);\n"
        f"export const LTC_MAT_2 = new Float32Array([\n{_flat(t2)}\n]);\n"
    )


def write_js(table: Table, path, dtype: str = "float32") -> Path:
    extra = {"exports": ["LTC_SIZE", "LTC_MAT_1", "LTC_MAT_2"]}
    return write_with_sidecar(table, path, js_text(table).encode("utf-8"), "js", extra)


def c_text(table: Table) -> str:
    import json

    from .. import __version__

    t1, t2 = engine_textures(table)
    n_y, n_x = t1.shape[:2]
    lobe = json.loads(table.attributes.get("terms", "{}")).get("lobe", "ggx")

    def arr(name: str, a: np.ndarray) -> str:
        c = a.shape[-1]
        return f"const float {name}[{n_y}][{n_x}][{c}] = {{\n{_flat(a, '{:.9g}f')}\n}};\n"

    return (
        f"/* {table.name}.cc -- LTC tables generated by lutbake {__version__}; do not edit.\n"
        " * Blender EEVEE layout (eevee_lut.hh: ltc_mat_ggx[64][64][4], ltc_mag_ggx[64][64][2],\n"
        " * ltc_disk_integral[64][64][1]): [row = sqrt(1 - NoV) index][column = roughness index][channel],\n"
        " * endpoint texels; ltc_matrix(lut) = mat3(vec3(lut.x, 0, lut.y), vec3(0, 1, 0), vec3(lut.z, 0, lut.w)).\n"
        " * ltc_mag = (magnitude, fresnel); ltc_disk_integral = ltc_code's sphere table (own axes:\n"
        " * [len index][z * 0.5 + 0.5 index]). */\n\n"
        + arr(f"ltc_mat_{lobe}", t1)
        + "\n"
        + arr(f"ltc_mag_{lobe}", t2[..., :2])
        + "\n"
        + arr("ltc_disk_integral", t2[..., 3:4])
    )


def write_c(table: Table, path, dtype: str = "float32") -> Path:
    extra = {"arrays": ["ltc_mat_<lobe>", "ltc_mag_<lobe>", "ltc_disk_integral"]}
    return write_with_sidecar(table, path, c_text(table).encode("utf-8"), "c", extra)


def hdrp_pack(ltc_1: np.ndarray) -> np.ndarray:
    """Unity HDRP's texel from ltc_code's: HDRP's SampleLtcMatrix (LTCAreaLight.hlsl) sets invM._m22 = 1 and
    invM._m00_m02_m11_m20 = texel, loading the *transpose* of M^-1 ("we load the matrix transpose"), so the texel
    is (M^-1_00, M^-1_20, M^-1_11, M^-1_02) / M^-1_22 of the true inverse (checked against HDRP's shipped GGX rows:
    tests/test_ltc.py)."""
    x, y, z, w = (ltc_1[..., k].astype(np.float64) for k in range(4))  # inv00, inv20, inv02, inv22 over inv11
    return np.stack([x / w, y / w, 1.0 / w, z / w], axis=-1)


def hdrp_fp16(ltc_1: np.ndarray) -> np.ndarray:
    """hdrp_pack as FP16, saturated to +-65504: at smooth, grazing texels M^-1_11 / M^-1_22 exceeds FP16, and HDRP's
    shipped table holds 65504 there (bits 31743, e.g. its last row at alpha = 0.001), i.e. it saturates too."""
    return np.clip(hdrp_pack(ltc_1), -FP16_MAX, FP16_MAX).astype(np.float16)


def cs_text(table: Table) -> str:
    import json

    from .. import __version__

    t1, _ = engine_textures(table)
    n_y, n_x = t1.shape[:2]
    lobe = json.loads(table.attributes.get("terms", "{}")).get("lobe", "ggx").upper()
    bits = hdrp_fp16(t1).view(np.uint16)
    rows = []
    for t in range(n_y):
        rows.append(f"            // row {t}: cos(theta) = 1 - ({t} / {n_y - 1})^2")
        rows += ["            " + ", ".join(str(int(b)) for b in bits[t, a]) + "," for a in range(n_x)]
    return (
        f"// {table.name}.cs -- LTC matrix table generated by lutbake {__version__}; do not edit.\n"
        "using UnityEngine;\nusing System;\n\nnamespace UnityEngine.Rendering.HighDefinition\n{\n"
        "    internal partial class LTCAreaLight\n    {\n"
        "        // 3x3 coefficients of M^-1 (Heitz et al. 2016 LTC), FP16 bits, as HDRP's\n"
        "        // Generated/LtcData.BRDF_*.cs: element (<roughnessIndex> + N * <thetaIndex>) * 4,\n"
        "        // roughness = (index / (N - 1))^2 (perceptual axis), cosTheta = 1 - (thetaIndex / (N - 1))^2;\n"
        "        // texel = (M^-1_00, M^-1_20, M^-1_11, M^-1_02) / M^-1_22, read by SampleLtcMatrix as\n"
        "        // invM._m00_m02_m11_m20 with invM._m22 = 1 (the transpose of M^-1); saturated to\n"
        "        // +-65504 where the ratio exceeds FP16 (smooth, grazing texels), as HDRP's own table.\n"
        f"        internal static ushort[] s_LtcMatrixData_BRDF_{lobe} = new ushort[{n_x} * {n_y} * 4]\n        {{\n"
        + "\n".join(rows)
        + "\n        };\n    }\n}\n"
    )


def write_cs(table: Table, path, dtype: str = "half") -> Path:
    extra = {"array": "s_LtcMatrixData_BRDF_<LOBE>: ushort FP16 bits, RGBA16F slice of _LtcData"}
    return write_with_sidecar(table, path, cs_text(table).encode("utf-8"), "cs", extra)


def babylon_fuzz_pixels(table: Table) -> tuple[np.ndarray, dict]:
    """Babylon's stored RGBA (ny, nx, 4) float64 of a normal-frame ``ltc`` table (lutbake.layouts.babylon
    BABYLON_FUZZ: r, g, b = (A, B, R_i) coded by the shader's mix() ranges, a = 1) and the values outside those ranges
    (channel -> texels, extent, range; empty when none). Unclamped: a float texture holds them and mix() reads them
    back exactly; the writer reports them."""
    from ..layouts.babylon import BABYLON_FUZZ

    if table.kind != "ltc":
        raise ValueError(f"table {table.name!r}: babylon_fuzz holds kind 'ltc' tables only, not {table.kind!r}")
    t1 = np.asarray(table.data[0], np.float64)
    if np.abs(t1[..., 1]).max() > 0 or np.abs(t1[..., 0] - 1.0).max() > 1e-6:
        raise ValueError(
            f"table {table.name!r}: babylon_fuzz stores an LTC fitted in the normal's frame, M^-1 = [[A, 0, B], "
            "[0, A, 0], [0, 0, 1]] (ltc_1 = (1, 0, B/A, 1/A)): fit a normal-frame lobe (zeltner)"
        )
    values = BABYLON_FUZZ.values(table.data)
    return BABYLON_FUZZ.encode(values), BABYLON_FUZZ.outside(values)


def write_babylon_fuzz(table: Table, path, dtype: str = "half") -> Path:
    """One DDS Babylon loads as scene.environmentFuzzBRDFTexture (isRGBD = false, invertY = false: row 0 at v = 0).
    Values outside the mix() ranges are not clamped (the float texture holds them and mix() extrapolates, so the
    shader reads the fitted values): the sidecar lists them (``outside_mix_ranges``: per channel the texel count, the
    extent and the range) and ``lutbake inspect`` / ``preview`` say so (lutbake.io.engine_files)."""
    from ..layouts.babylon import BABYLON_FUZZ
    from ..layouts.base import uv_of
    from . import dds

    stored, outside = babylon_fuzz_pixels(table)
    np_dtype = np.float16 if dtype == "half" else np.float32
    extra = {
        "dxgi_format": "R16G16B16A16_FLOAT" if dtype == "half" else "R32G32B32A32_FLOAT",
        "engine": BABYLON_FUZZ.engine,
        "coding": {
            c.name: {"channel": ch, "mix": [c.lo, c.hi], "meaning": c.meaning}
            for ch, c in zip("rgb", BABYLON_FUZZ.channels)
        },
        "alpha_channel": "1",
        "shader": BABYLON_FUZZ.shader.format(uv=uv_of(table.axes[1:])),
        "outside_mix_ranges": outside or "none",
    }
    return write_with_sidecar(table, path, dds.encode(stored.astype(np_dtype)), "babylon_fuzz", extra)


def babylon_ltc_bytes(table: Table) -> bytes:
    """Babylon's areaLightsLTC.bin: texel by texel (row t = sqrt(1 - NoV) index, column a = roughness index, element
    a + t N as ltc_code), the 4 FP16 values of ltc_1 then the 4 of ltc_2, little-endian; DecodeLTCTextureDataAsync
    copies values 0-3 of each 8 into LTC1's texel and 4-7 into LTC2's. Always FP16 (Babylon uploads the values as
    HALF_FLOAT textures), whatever ``dtype``; ValueError where a value is past FP16."""
    t1, t2 = engine_textures(table)
    both = np.concatenate([t1, t2], axis=-1)
    if not np.all(np.isfinite(both)) or np.abs(both).max() > FP16_MAX:
        raise ValueError(f"table {table.name!r}: an LTC value is past FP16's 65504; babylon_ltc writes FP16 only")
    return both.astype("<f2").tobytes()


def write_babylon_ltc(table: Table, path, dtype: str = "half") -> Path:
    extra = {
        "layout": "per texel (element a + t N) 8 FP16: ltc_1 RGBA, ltc_2 RGBA (Babylon.js areaLightsLTC.bin)",
        "load": "Tools.AssetBaseUrl = <folder>: Babylon fetches <folder>/areaLights/areaLightsLTC.bin",
    }
    return write_with_sidecar(table, path, babylon_ltc_bytes(table), "babylon_ltc", extra)


def aniso_matrices(table: Table) -> np.ndarray:
    """The paper's layout of an ltc_aniso table (lutbake.kinds.ltc_aniso: slices t0, t1, t2 of (layer x theta, phi,
    RGBA), layer = b + N a): M (N, N, N, N, 3, 3) float32, row-major from (t0.xyzw, t1.xyzw, t2.x)."""
    if table.kind != "ltc_aniso":
        raise ValueError(f"table {table.name!r}: ltc_aniso_npy holds kind 'ltc_aniso' tables only, not {table.kind!r}")
    data = np.asarray(table.data, np.float32)
    n = data.shape[2]
    ch = data.reshape(3, n, n, n, n, 4).transpose(1, 2, 3, 4, 0, 5).reshape(n, n, n, n, 12)
    return np.ascontiguousarray(ch[..., :9].reshape(n, n, n, n, 3, 3))


def write_ltc_aniso_npy(table: Table, path, dtype: str = "float32") -> Path:
    """The paper's own file (AakashKT/LTC-Anisotropic LUT/alphax_alphay_theta_phi.npy, alpha_lambda_theta_phi.npy):
    M[a, b, theta, phi] (N, N, N, N, 3, 3) float32; magnitude, fresnel and the fit error are not in it (the paper's
    renderer reads its amplitude from another table): they are in the texture layout (formats exr, npy)."""
    from .atomic import atomic_write_hashed

    m = aniso_matrices(table)
    path = Path(path)
    digest = atomic_write_hashed(path, lambda tmp: np.save(tmp, m, allow_pickle=False))
    extra = {
        "dtype": "float32",
        "shape": list(m.shape),
        "layout": "the paper's: M[a, b, theta, phi] row-major 3 x 3, tangent frame, |M e_z| = 1; magnitude, fresnel "
        "and fit_error only in the texture layout (format exr / npy)",
    }
    write_conventions(table, path, "ltc_aniso_npy", extra, digests={path.name: digest})
    return path


WRITERS = {
    "ltc_dds": write_ltc_dds,
    "js": write_js,
    "c": write_c,
    "cs": write_cs,
    "babylon_fuzz": write_babylon_fuzz,
    "babylon_ltc": write_babylon_ltc,
    "ltc_aniso_npy": write_ltc_aniso_npy,
}
