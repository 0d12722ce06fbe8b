"""GL consumer, every engine preset: each preset that ``make luts`` bakes (the Makefile's PRESETS, read here, so a new
preset is covered without editing this file) and whose output is a texture (EXR, DDS, KTX2 plain or zstd, PNG16, the
LTC DDS pair) is baked small, written in its own format, and
- read by an independent reader written from the format's specification (tests/test_formats.py: DDS, KTX2 incl.
  zstd; OpenImageIO's raw pixels for EXR and PNG) and uploaded to OpenGL with the texture's own internal format
  (half -> RG16F / RGB16F / RGBA16F, float -> *32F, 16-bit PNG -> RGB16 UNORM, 3D EXR -> a 3D texture);
- sampled in a GLSL shader (LINEAR, CLAMP_TO_EDGE) at random points, half of them texel centres and half between
  texels, whose uv the shader computes from the axis *values* with the file's documented formulas (``uv_formula``
  of each axis, the ``lutbake:axes`` metadata, turned into GLSL here); the shader also evaluates the preset's
  documented reconstruction (``RECONSTRUCTION``, from each table's ``reconstruction`` text: E = f0 scale + bias,
  mix(Fc, E, f0), HDRP's 2 pi and + 0.5, the sheen scaling, Turquin's 1 / E_sum, the LTC magnitude and det Minv);
- compared with lutbake's own CPU decode of the same file (lutbake.io: read_exr, dds.decode, ktx2.decode,
  lut_files.read_lut) filtered bilinearly / trilinearly on the CPU at the same texel positions, channels and
  reconstruction alike; at texel centres also with the baked table itself within the storage's rounding.
Text-array outputs (C/C++ headers, JS, C#, OpenPBR's header) are read back by their own independent readers
(test_code_arrays, test_ltc_formats, test_dielectric). Skipped, with the reason, where no GL context exists."""

from __future__ import annotations

import math
import re
import zlib
from pathlib import Path

import numpy as np
import pytest
from test_formats import read_dds_spec, read_ktx2_spec
from test_gl_consumer import ctx  # noqa: F401 - the shared GL context fixture

from lutbake.api import bake_table
from lutbake.config import load_config, parse_overrides, preset_path
from lutbake.io.formats import write_table

ROOT = Path(__file__).resolve().parents[1]
TEXTURE_FORMATS = ("exr", "dds", "ktx2", "ktx2zst", "png16", "ltc_dds")
SMALL_SIDE = 16  # the longest side of a reduced 2D bake (the preset's aspect ratio kept, >= MIN_SIDE)
MIN_SIDE = 4
# the costly bakes smaller still (what GL samples is the same at any size): an LTC fit (8² 1.2 s, 4² 0.3 s), the 3D
# dielectric table's adaptive quadrature (16² x 4 IOR slices 0.9 s, 8² x 4 0.1 s), the averages' (8 x 4 0.8 s, 4 x 4
# 0.35 s)
LTC_SIDE = 4
DIELECTRIC_SIDE = 8
IOR_SIZE = 4
ROUGHNESS_SIZE = 4
N_POINTS = 256
# GL vs the CPU filter of the same texels: GPUs weight texels with a few fractional bits (Direct3D 11 requires 8),
# so the bound is 2^-8 of the largest difference between the texels a point filters, plus float32 rounding. Mesa
# llvmpipe (LLVM 15) measured: max |GL - CPU| 1.5e-6 (LTC, values ~10), <= 2.3e-7 elsewhere; <= 1.2e-3 of the span.
SUBTEXEL = 2.0**-8
F32_RTOL = 4e-6
F32_ATOL = 1e-6
# lutbake's decode at a texel centre vs the baked table: the storage's rounding (half: 2^-11 relative; 16-bit
# UNORM: half a code; float: exact)
# the reconstruction from GL's filtered texels vs from the CPU's: the filtering bound carried through (1 / E_sum
# of Turquin's compensation, E_sum >= 0.3, amplifies it ~11x; measured below 1e-6 on llvmpipe)
RECONSTRUCTION_RTOL = 1e-4
RECONSTRUCTION_ATOL = 1e-5
STORAGE_RTOL = {"half": 2.0**-11, "float32": 0.0, "unorm16": 0.0}
STORAGE_ATOL = {"half": 6e-8, "float32": 0.0, "unorm16": 0.5 / 65535}


def makefile_presets() -> list[str]:
    text = (ROOT / "Makefile").read_text()
    m = re.search(r"^PRESETS \?=((?:.*\\\n)*.*)$", text, re.M)
    assert m, "Makefile: no PRESETS ?= line"
    return m.group(1).replace("\\\n", " ").split()


def small_overrides(spec) -> list[str]:
    """--set overrides that bake ``spec`` small (same conventions, fewer texels)."""
    o, name, out = spec.options, spec.name, []
    if "size" in o:
        if spec.kind == "ltc":
            w = h = LTC_SIDE
        elif "ior_size" in o:
            w = h = DIELECTRIC_SIDE
        else:
            f = SMALL_SIDE / max(o["size"])
            w, h = (max(MIN_SIDE, round(s * f)) for s in o["size"])
        out.append(f"{name}.size=[{w}, {h}]")
    if "ior_size" in o:
        out.append(f"{name}.ior_size={IOR_SIZE}")
    if "roughness_size" in o:
        out.append(f"{name}.roughness_size={ROUGHNESS_SIZE}")
    return out


def texture_tables() -> list[tuple[str, str]]:
    """(preset, table name) of every table of a Makefile preset whose format is a texture."""
    out = []
    for p in makefile_presets():
        for s in load_config(preset_path(p), []):
            if s.options.get("format", "exr") in TEXTURE_FORMATS:
                out.append((p, s.name))
    return out


TABLES = texture_tables()


def test_every_makefile_preset_is_a_texture_here_or_a_text_array_read_elsewhere():
    """The split this file relies on: a preset's table is a texture (tested here) or a text array (whose formats
    have independent readers in test_code_arrays / test_ltc_formats / test_dielectric), or Babylon's fuzz texture
    (its coded channels, their decode and round trip: test_babylon; three.js's module: node in test_code_arrays,
    three.js itself in test_web_threejs)."""
    text_formats = {"h", "js", "c", "cs", "openpbr_h", "wgsl", "rs", "threejs_dfg"}
    elsewhere = {"babylon_fuzz"}
    for p in makefile_presets():
        for s in load_config(preset_path(p), []):
            fmt = s.options.get("format", "exr")
            assert fmt in TEXTURE_FORMATS or fmt in text_formats or fmt in elsewhere, (p, s.name, fmt)
    assert len(TABLES) >= 13  # 12 presets, turquin with two tables


# ---------------------------------------------------------------------------------------------- readers


def raw_texels(path: Path) -> list[np.ndarray]:
    """The file's texels as stored (float16 / float32 / uint16), by readers independent of lutbake.io."""
    if path.suffix == ".dds":
        files = [path] + (
            [path.with_name(path.name.replace("_1.dds", "_2.dds"))] if path.name.endswith("_1.dds") else []
        )
        return [read_dds_spec(f.read_bytes())[0] for f in files]
    if path.suffix == ".ktx2":
        return [read_ktx2_spec(path.read_bytes())[0]]
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    parts = []
    try:
        sub = 0
        while inp.seek_subimage(sub, 0):
            spec = inp.spec()
            fmt = {oiio.HALF: "half", oiio.FLOAT: "float", oiio.UINT16: "uint16"}[spec.format.basetype]
            arr = np.asarray(inp.read_image(fmt))
            names = list(spec.channelnames)
            order = sorted(range(len(names)), key=lambda c: "RGBA".index(names[c][-1]))  # EXR stores B, G, R
            parts.append(np.ascontiguousarray(arr[..., order]))
            sub += 1
    finally:
        inp.close()
    return [np.stack(parts)] if len(parts) > 1 else parts


def lutbake_decode(path: Path) -> list[np.ndarray]:
    """lutbake's own CPU decode of the same file(s), float64."""
    from lutbake.io import dds, ktx2
    from lutbake.io.exr import read_exr
    from lutbake.io.lut_files import read_lut

    if path.suffix == ".exr":
        return [read_exr(path)[0].astype(np.float64)]
    if path.suffix == ".png":
        return [read_lut(path).data]
    if path.suffix == ".ktx2":
        return [ktx2.decode(path.read_bytes())[0].astype(np.float64)]
    files = [path] + ([path.with_name(path.name.replace("_1.dds", "_2.dds"))] if path.name.endswith("_1.dds") else [])
    return [dds.decode(f.read_bytes())[0].astype(np.float64) for f in files]


# ---------------------------------------------------------------------------------------- conventions


def glsl_uv(formula: str, var: str) -> str:
    """An axis' ``uv_formula`` (u in the axis value x) as GLSL: x -> var, integer literals -> floats."""
    expr = re.sub(r"\bx\b", var, formula)
    return re.sub(r"(?<![\w.])(\d+)(?![\w.])", r"\1.0", expr)


def axis_uv_formula(axis) -> str:
    """The documented formula; a ``listed`` axis says "search the listed values", which the test does on the CPU
    (np.interp, as lutbake.axes.Axis.uv) and hands the shader the resulting u."""
    return "x" if axis.mapping == "listed" else axis.uv_formula()


def value_at(axis, f: np.ndarray) -> np.ndarray:
    """The axis value at fractional storage index f (the axis chain of lutbake.axes, continuous in f, without the
    edge policy's clamps, so the documented uv formula inverts it exactly)."""
    n = axis.count
    if axis.mapping == "listed":
        return (f + 0.5) / n  # the u of the CPU search (see axis_uv_formula)
    g = n - 1 - f if axis.order == "hi_first" else f
    t = (g + 0.5) / n if axis.texel == "center" else g / (n - 1)
    s = {"one_minus_t2": 1 - t * t, "square": t * t, "texel_offset": t + 1.0 / n}.get(axis.mapping, t)
    return axis.lo + (axis.hi - axis.lo) * s


def index_range(axis) -> tuple[float, float]:
    """Storage indices whose value the formula inverts: cmgen's texel_offset clamps t + 1/N at 1 (the last t index)."""
    n = axis.count
    if axis.mapping == "texel_offset":
        return (1.0, n - 1.0) if axis.order == "hi_first" else (0.0, n - 2.0)
    return 0.0, n - 1.0


# the documented reconstruction of each layout (GLSL on t = texture 1, u = texture 2 (LTC), f0; numpy alike): two
# values per point
TWO_PI = 2 * math.pi
RECONSTRUCTION = {
    "scale_bias": ("vec2(f0 * t.r + t.g, 0.0)", lambda t, u, f0: (f0 * t[:, 0] + t[:, 1], 0 * f0)),
    "multiscatter_cloth": (
        "vec2(mix(t.r, t.g, f0), f0 * t.b)",
        lambda t, u, f0: ((1 - f0) * t[:, 0] + f0 * t[:, 1], f0 * t[:, 2]),
    ),
    "multiscatter_disney": (
        "vec2(mix(t.r, t.g, f0), t.b + 0.5)",
        lambda t, u, f0: ((1 - f0) * t[:, 0] + f0 * t[:, 1], t[:, 2] + 0.5),
    ),
    "charlie_fabric": (
        f"vec2(mix(t.r, t.g, f0) * {TWO_PI!r}, t.b)",
        lambda t, u, f0: (((1 - f0) * t[:, 0] + f0 * t[:, 1]) * TWO_PI, t[:, 2]),
    ),
    "babylon_f82": (  # getF82DirectionalAlbedo with F90 = 1: (1 - F0) x + F0 y, and the F82 term z / BRDF_Z_SCALE
        "vec2(mix(t.r, t.g, f0), t.b / 16.0)",
        lambda t, u, f0: ((1 - f0) * t[:, 0] + f0 * t[:, 1], t[:, 2] / 16.0),
    ),
    "charlie": ("vec2(f0 * t.b, 0.0)", lambda t, u, f0: (f0 * t[:, 2], 0 * f0)),
    "sheen_albedo": ("vec2(1.0 - f0 * t.r, 0.0)", lambda t, u, f0: (1 - f0 * t[:, 0], 0 * f0)),
    "energy": ("vec2(1.0 / t.b, t.r)", lambda t, u, f0: (1 / t[:, 2], t[:, 0])),  # f / E_sum (Turquin), E_R
    "ltc": (
        "vec2(f0 * u.x + (1.0 - f0) * u.y, t.x * t.w - t.y * t.z)",  # magnitude x Fresnel, det of Minv's xz block
        lambda t, u, f0: (f0 * u[:, 0] + (1 - f0) * u[:, 1], t[:, 0] * t[:, 3] - t[:, 1] * t[:, 2]),
    ),
}


def layout_of(spec) -> str:
    return "ltc" if spec.kind == "ltc" else spec.options["layout"]


# ------------------------------------------------------------------------------------------------ GL


def gl_dtype(a: np.ndarray) -> str:
    """moderngl's dtype for the file's own texel type: f2 -> GL_R*16F, f4 -> GL_R*32F, nu2 -> GL_R*16 (UNORM)."""
    return {np.dtype(np.float16): "f2", np.dtype(np.float32): "f4", np.dtype(np.uint16): "nu2"}[a.dtype]


def gl_run(ctx, textures: list[np.ndarray], uv_glsl: list[str], rec_glsl: str, params: np.ndarray, f0: np.ndarray):  # noqa: F811
    """Sample each texture at the uv the shader computes from ``params`` (n, dims); returns (texels per texture
    (n, 4) each, reconstruction (n, 2))."""
    import moderngl

    dims = textures[0].ndim - 1
    n = len(params)
    texs = []
    for a in textures:
        data, comps = np.ascontiguousarray(a).tobytes(), a.shape[-1]
        if dims == 3:
            tex = ctx.texture3d((a.shape[2], a.shape[1], a.shape[0]), comps, data, dtype=gl_dtype(a))
            tex.repeat_z = False
        else:
            tex = ctx.texture((a.shape[1], a.shape[0]), comps, data, dtype=gl_dtype(a))
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        texs.append(tex)
    sampler = "sampler3D" if dims == 3 else "sampler2D"
    coord = "vec3" if dims == 3 else "vec2"
    # uv_glsl lists the axes in table order ([z,] y, x); the texture coordinate is (x, y[, z])
    uv = f"{coord}({', '.join(reversed(uv_glsl))})"
    second = "texture(lut2, uv)" if len(textures) > 1 else "vec4(0.0)"
    targets = [ctx.texture((n, 1), 4, dtype="f4") for _ in range(3)]
    fbo = ctx.framebuffer(color_attachments=targets)
    prog = ctx.program(
        vertex_shader=f"""#version 330
            in vec4 in_p; in float in_i; flat out vec3 p; flat out float f0;
            void main() {{ p = in_p.xyz; f0 = in_p.w;
                gl_Position = vec4((in_i + 0.5) / {n}.0 * 2.0 - 1.0, 0.0, 0.0, 1.0); gl_PointSize = 1.0; }}""",
        fragment_shader=f"""#version 330
            uniform {sampler} lut; uniform {sampler} lut2; flat in vec3 p; flat in float f0;
            layout(location = 0) out vec4 o_t; layout(location = 1) out vec4 o_u; layout(location = 2) out vec4 o_rec;
            void main() {{
                {coord} uv = {uv};
                vec4 t = texture(lut, uv);
                vec4 u = {second};
                o_t = t; o_u = u; o_rec = vec4({rec_glsl}, 0.0, 0.0);
            }}""",
    )
    if "lut2" in prog:
        prog["lut2"].value = 1
    prog["lut"].value = 0
    p4 = np.zeros((n, 4))  # (axis values, f0)
    p4[:, :dims], p4[:, 3] = params, f0
    attrs = np.concatenate([p4, np.arange(n)[:, None]], axis=1).astype("f4")
    vbo = ctx.buffer(attrs.tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "4f 1f", "in_p", "in_i")])
    fbo.use()
    for k, tex in enumerate(texs):
        tex.use(k)
    ctx.disable(moderngl.BLEND)
    vao.render(moderngl.POINTS)
    out = [
        np.frombuffer(fbo.read(components=4, dtype="f4", attachment=k), dtype="f4").reshape(n, 4).astype(np.float64)
        for k in range(3)
    ]
    for o in (vao, vbo, prog, fbo, *targets, *texs):
        o.release()
    return out[:2], out[2][:, :2]


def cpu_filter(a: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Multilinear filtering of ``a`` ((z,) y, x, C) at fractional storage indices f (n, dims), clamp-to-edge;
    also the span (max - min) of the texels each point weights, per channel."""
    dims = a.ndim - 1
    lo = np.floor(f).astype(int)
    w = f - lo
    acc = np.zeros((len(f), a.shape[-1]))
    vals = []
    for corner in range(1 << dims):
        idx, weight = [], np.ones(len(f))
        for d in range(dims):
            bit = (corner >> d) & 1
            idx.append(np.clip(lo[:, d] + bit, 0, a.shape[d] - 1))
            weight = weight * (w[:, d] if bit else 1 - w[:, d])
        v = a[tuple(idx)].astype(np.float64)
        acc += weight[:, None] * v
        vals.append(np.where(weight[:, None] > 0, v, np.nan))
    stack = np.stack(vals)
    return acc, np.nanmax(stack, 0) - np.nanmin(stack, 0)


def storage_of(a: np.ndarray) -> str:
    return {np.dtype(np.float16): "half", np.dtype(np.float32): "float32", np.dtype(np.uint16): "unorm16"}[a.dtype]


@pytest.mark.parametrize("preset,name", TABLES, ids=[f"{p}:{n}" for p, n in TABLES])
def test_gl_samples_every_preset_texture_like_lutbakes_cpu_decode(ctx, tmp_path, preset, name):  # noqa: F811
    (full,) = [s for s in load_config(preset_path(preset), []) if s.name == name]
    (spec,) = [s for s in load_config(preset_path(preset), parse_overrides(small_overrides(full))) if s.name == name]
    table = bake_table(spec, workers=2)[0]
    fmt, dtype = spec.options.get("format", "exr"), spec.options.get("dtype", "float32")
    path = write_table(table, tmp_path, fmt, dtype)
    raw, ours = raw_texels(path), lutbake_decode(path)
    axes = table.axes[1:] if spec.kind == "ltc" else table.axes  # LTC: the z axis is the pair of files
    dims = len(axes)
    assert all(r.ndim == dims + 1 for r in raw) and len(raw) == len(ours)
    stored = {"png16": "unorm16"}.get(fmt, dtype)
    assert all(storage_of(r) == stored for r in raw), [r.dtype for r in raw]  # uploaded as the file stores it

    rng = np.random.default_rng(zlib.crc32(name.encode()))
    f = np.empty((N_POINTS, dims))
    for d, axis in enumerate(axes):
        lo, hi = index_range(axis)
        f[:, d] = rng.uniform(lo, hi, N_POINTS)
        centres = np.arange(N_POINTS) < N_POINTS // 2  # half the points at texel centres (every axis)
        f[centres, d] = rng.integers(int(math.ceil(lo)), int(hi) + 1, centres.sum())
    params = np.stack([value_at(a, f[:, d]) for d, a in enumerate(axes)], 1)
    f0 = rng.uniform(0.0, 1.0, N_POINTS)
    uv_glsl = [glsl_uv(axis_uv_formula(a), "p." + "xyz"[d]) for d, a in enumerate(axes)]
    rec_glsl, rec_np = RECONSTRUCTION[layout_of(spec)]
    got_tex, got_rec = gl_run(ctx, raw, uv_glsl, rec_glsl, params, f0)

    want, spans = zip(*(cpu_filter(o, f) for o in ours))
    for got, w, span, r in zip(got_tex, want, spans, raw):
        nch = r.shape[-1]
        tol = SUBTEXEL * span + F32_RTOL * np.abs(w) + F32_ATOL
        err = np.abs(got[:, :nch] - w)
        print(
            f"{preset}:{name} {r.dtype} {r.shape}: max |GL - CPU| {err.max():.2e}, "
            f"max / span (span > 1e-6) {np.max((err / np.maximum(span, 1e-6))[span > 1e-6], initial=0):.2e}"
        )
        assert np.all(err <= tol), (
            f"{name}: max |GL - CPU| {err.max():.3g} where the bound is {tol[err > tol].min():.3g}"
        )

    # the shader's reconstruction is the documented one: evaluated in numpy on the texels GL filtered (float32
    # arithmetic apart), and on lutbake's CPU-filtered decode (the filtering bound above, carried through)
    def pad4(a):
        return np.pad(a[:, :4], ((0, 0), (0, 4 - min(a.shape[-1], 4))))

    zeros = np.zeros((N_POINTS, 4))
    rec_gl = np.stack(rec_np(pad4(got_tex[0]), pad4(got_tex[1]) if len(raw) > 1 else zeros, f0), 1)
    np.testing.assert_allclose(got_rec, rec_gl, rtol=F32_RTOL * 4, atol=F32_ATOL)
    rec_cpu = np.stack(rec_np(pad4(want[0]), pad4(want[1]) if len(raw) > 1 else zeros, f0), 1)
    print(f"{preset}:{name} reconstruction ({layout_of(spec)}): max |GL - CPU| {np.abs(got_rec - rec_cpu).max():.2e}")
    np.testing.assert_allclose(got_rec, rec_cpu, rtol=RECONSTRUCTION_RTOL, atol=RECONSTRUCTION_ATOL)

    # texel centres: lutbake's decode holds the baked table to the storage's rounding
    centre = np.arange(N_POINTS) < N_POINTS // 2
    baked = [table.data[k] for k in range(2)] if spec.kind == "ltc" else [table.data]
    if spec.kind == "ltc":
        baked[1] = baked[1].copy()
        baked[1][..., 2] = 0.0  # the engines' unused channel (lutbake.io.ltc.engine_textures)
    for o, b in zip(ours, baked):
        idx = tuple(f[centre].astype(int).T)
        np.testing.assert_allclose(
            o[idx][:, : b.shape[-1]], b[idx], rtol=STORAGE_RTOL[stored], atol=STORAGE_ATOL[stored] + 1e-12
        )
