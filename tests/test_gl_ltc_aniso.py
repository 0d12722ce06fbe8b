"""GL consumer, anisotropic area lights: the published 8^4 anisotropic LTC table (tests/data) in lutbake's texture
layout (lutbake.ltc.aniso.texture_layout: three RGBA 3D textures 8 x 8 x 64, linear filtering) through
docs/shaders/ltc_aniso.glsl equals the host reconstruction (lutbake.ltc.aniso.lookup, then the polygon integral with
the same edge fit) at random shading points (normal, tangent, view in every azimuth quadrant, alpha_x, alpha_y, f0,
quad): uploaded from the arrays, and from the bytes of the KTX 2.0 and DDS files kind ltc_aniso writes
(lutbake.io.ltc_aniso_textures), as an engine uploads them (the header's size, the level's bytes to glTexImage3D).
The GL tests skip where no GL context exists (see test_gl_consumer)."""

import struct
from pathlib import Path

import numpy as np
import pytest
from test_gl_consumer import ctx  # noqa: F401 - the shared GL context fixture

from lutbake.io.formats import write_table
from lutbake.kinds.ltc_aniso import CHANNELS, axes_for
from lutbake.ltc import aniso, polygon
from lutbake.table import Table

SHADERS = Path(__file__).resolve().parents[1] / "docs" / "shaders"
DATA = Path(__file__).parent / "data"
N = 8
N_POINTS = 128
GL_RTOL = 2e-3  # float32 shading and the GPU's filter weights (8-bit sub-texel precision in some drivers)
GL_ATOL = 2e-4
LIT = 1e-3  # a point whose result is above this is lit (the relative differences are taken there)
# half storage against float32, the host reconstruction at the N_POINTS points (measured: max 6.6e-4, median 1.2e-4
# relative over the 105 lit ones), every entry of M (|M| < 2) moved by at most half half's spacing on [1, 2): 2^-11
HALF_MAX_RTOL = 1e-3
HALF_MEDIAN_RTOL = 2e-4


@pytest.fixture(scope="module")
def published() -> np.ndarray:
    """The published table's M with smooth stand-in magnitude and fresnel channels (the test is the reconstruction,
    not the values), as the three textures (3, 64, 8, 8, 4) float32."""
    g = aniso.Grid4("alphax_alphay", (N,) * 4)
    m = np.load(DATA / "ltc_aniso_alphax_alphay_theta_phi.npy").astype(np.float64)
    a, b, th, _ = np.meshgrid(*g.axes(), indexing="ij")
    return aniso.texture_layout(m, 1.0 - 0.3 * a * np.cos(th), 0.1 + 0.05 * b, np.zeros(g.n))


def shading_points(n: int = N_POINTS, seed: int = 3) -> list[tuple]:
    """(v, quad, alpha_x, alpha_y, f0, theta, phi) in the tangent frame (T = x, B = y, N = z): views in every azimuth
    quadrant, quads above and across the horizon."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        ax, ay, f0 = rng.uniform(0.02, 1.0), rng.uniform(0.02, 1.0), rng.uniform(0.0, 1.0)
        theta, phi = np.arccos(rng.uniform(0.05, 1.0)), rng.uniform(0, 2 * np.pi)
        v = np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
        el, az, d, s = rng.uniform(-0.2, 1.4), rng.uniform(0, 2 * np.pi), rng.uniform(0.8, 3.0), rng.uniform(0.3, 2.0)
        c = d * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        t1 = np.cross(-c / d, [0.3, 0.5, 0.8])
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(-c / d, t1)
        quad = np.array([c + s / 2 * (x * t1 + y * t2) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
        out.append((v, quad, ax, ay, f0, theta, phi))
    return out


def host_specular(tex: np.ndarray, points: list[tuple]) -> np.ndarray:
    """lutbake_ltc_aniso_specular on the host from the textures' values ``tex`` (3, N^2, N, N, 4): M and (magnitude,
    fresnel) unpacked, quadrilinear (lutbake.ltc.aniso.lookup), the polygon integral with the shader's edge fit."""
    g = aniso.Grid4("alphax_alphay", (N,) * 4)
    ch = np.asarray(tex, np.float64).transpose(1, 2, 3, 0, 4).reshape(N, N, N, N, 12)
    m, extra = ch[..., :9].reshape(N, N, N, N, 3, 3), ch[..., 9:11]
    want = []
    for _, quad, ax, ay, f0, theta, phi in points:
        mt, e = aniso.lookup(m, g, ax, ay, theta, phi, extra)
        ff = abs(polygon.form_factor(quad @ np.linalg.inv(mt[0]).T, polygon.edge_fitted))
        want.append(ff * (f0 * e[0, 0] + (1 - f0) * e[0, 1]))
    return np.array(want)


SPECULAR = {  # textures -> the shader's function (docs/shaders/ltc_aniso.glsl)
    3: "lutbake_ltc_aniso_specular(t0, t1, t2, ",
    6: "lutbake_ltc_aniso_specular_two_lobes(t0, t1, t2, t3, t4, t5, ",
    9: "lutbake_ltc_aniso_specular_three_lobes(t0, t1, t2, t3, t4, t5, t6, t7, t8, ",
}


def gl_specular(ctx, blobs: list[bytes], size: tuple[int, int, int], dtype: str, points: list[tuple]):  # noqa: F811
    """docs/shaders/ltc_aniso.glsl at ``points``, its t0, t1, t2 (six or nine blobs: to t5 or t8, the two- or three-lobe
    function) uploaded from ``blobs`` (each a 3D texture's texels in glTexImage3D order, ``size`` = (width, height,
    depth), moderngl ``dtype`` f2 or f4)."""
    import moderngl

    n = len(points)
    textures = []
    for blob in blobs:  # clamp to edge, linear: the layout's filtering
        t = ctx.texture3d(size, 4, blob, dtype=dtype)
        t.repeat_x = t.repeat_y = t.repeat_z = False
        t.filter = (moderngl.LINEAR, moderngl.LINEAR)
        textures.append(t)
    prog = ctx.program(
        vertex_shader=f"""#version 330
            in vec3 in_v; in vec3 in_p0; in vec3 in_p1; in vec3 in_p2; in vec3 in_p3; in vec3 in_a; in float in_i;
            flat out vec3 v; flat out vec3 p0; flat out vec3 p1; flat out vec3 p2; flat out vec3 p3; flat out vec3 a;
            void main() {{ v = in_v; p0 = in_p0; p1 = in_p1; p2 = in_p2; p3 = in_p3; a = in_a;
                gl_Position = vec4((in_i + 0.5) / {n}.0 * 2.0 - 1.0, 0.0, 0.0, 1.0); gl_PointSize = 1.0; }}""",
        fragment_shader="#version 330\n"
        + (SHADERS / "lutbake_ltc.glsl").read_text()
        + (SHADERS / "ltc_aniso.glsl").read_text()
        + """
            """
        + "".join(f"uniform sampler3D t{k}; " for k in range(len(blobs)))
        + """
            flat in vec3 v; flat in vec3 p0; flat in vec3 p1; flat in vec3 p2; flat in vec3 p3; flat in vec3 a;
            out vec4 color;
            void main() {
                vec3 p[4] = vec3[4](p0, p1, p2, p3);
                vec3 s = """
        + SPECULAR[len(blobs)]
        + """vec3(0, 0, 1), vec3(1, 0, 0), v, a.x, a.y, vec3(a.z),
                                                    p, vec3(1.0), true);
                color = vec4(s, 1.0);
            }""",
    )
    target = ctx.texture((n, 1), 4, dtype="f4")
    fbo = ctx.framebuffer(color_attachments=[target])
    for k in range(len(blobs)):
        prog[f"t{k}"].value = k
        textures[k].use(k)
    rows = [np.concatenate([v, q.ravel(), [ax, ay, f0], [i]]) for i, (v, q, ax, ay, f0, _, _) in enumerate(points)]
    vbo = ctx.buffer(np.ascontiguousarray(rows, dtype=np.float32).tobytes())
    vao = ctx.vertex_array(
        prog, [(vbo, "3f 3f 3f 3f 3f 3f 1f", "in_v", "in_p0", "in_p1", "in_p2", "in_p3", "in_a", "in_i")]
    )
    fbo.use()
    ctx.disable(moderngl.BLEND)
    vao.render(moderngl.POINTS)
    got = np.frombuffer(fbo.read(components=4, dtype="f4"), dtype="f4").reshape(n, 4)[:, 0]
    for o in (vao, vbo, prog, fbo, target, *textures):
        o.release()
    return got


def test_gl_shades_anisotropic_ggx_with_the_texture_layout(ctx, published):  # noqa: F811
    points = shading_points()
    want = host_specular(published, points)
    got = gl_specular(ctx, [np.ascontiguousarray(t).tobytes() for t in published], (N, N, N * N), "f4", points)
    assert (want > LIT).sum() > N_POINTS // 3, "too few lit cases to test anything"
    print(f"max |GL - CPU| {np.abs(got - want).max():.2e}")
    np.testing.assert_allclose(got, want, rtol=GL_RTOL, atol=GL_ATOL)


def ktx2_texture(blob: bytes) -> tuple[bytes, tuple[int, int, int], str]:
    """(level 0's bytes, (pixelWidth, pixelHeight, pixelDepth), moderngl dtype) of a KTX 2.0 file as a loader reads
    it (KTX 2.0 §3.1-3.9: the header's vkFormat and sizes at byte 12, the level index at byte 80)."""
    vk, _, w, h, d = struct.unpack_from("<5I", blob, 12)
    offset, length, _ = struct.unpack_from("<3Q", blob, 80)
    return blob[offset : offset + length], (w, h, d), {97: "f2", 109: "f4"}[vk]  # R16G16B16A16 / R32G32B32A32_SFLOAT


def dds_texture(blob: bytes) -> tuple[bytes, tuple[int, int, int], str]:
    """The same of a DDS with a DX10 header (Microsoft's DDS file layout: DDS_HEADER's height, width at byte 12,
    depth at 24; DDS_HEADER_DXT10's dxgiFormat at byte 128; the data from byte 148)."""
    h, w, _, d = struct.unpack_from("<4I", blob, 12)
    dxgi = struct.unpack_from("<I", blob, 128)[0]
    dtype = {10: "f2", 2: "f4"}[dxgi]  # DXGI_FORMAT_R16G16B16A16_FLOAT, DXGI_FORMAT_R32G32B32A32_FLOAT
    return blob[148 : 148 + w * h * d * 4 * int(dtype[1])], (w, h, d), dtype


@pytest.mark.parametrize("fmt, dtype", [("ktx2", "half"), ("dds", "float32")])
def test_gl_shades_with_the_textures_uploaded_from_the_files_bytes(ctx, published, tmp_path, fmt, dtype):  # noqa: F811
    """The files of format ktx2 (dtype half, as preset ltc-aniso) and dds: each file's header gives the texture's size
    and pixel type, its level's bytes go to glTexImage3D as they are; the result equals the host reconstruction from
    the stored (rounded) values."""
    data = published.reshape(3, N**3, N, 4)
    table = Table("la", "ltc_aniso", data, axes_for({"size": N}), CHANNELS, "")
    first = write_table(table, tmp_path, fmt, dtype)
    files = [first.with_name(first.name.replace("_t0.", f"_t{k}.")) for k in range(3)]
    read = ktx2_texture if fmt == "ktx2" else dds_texture
    blobs, sizes, dtypes = zip(*(read(f.read_bytes()) for f in files))
    assert set(sizes) == {(N, N, N * N)} and set(dtypes) == {"f2" if dtype == "half" else "f4"}
    stored = np.stack([np.frombuffer(b, "<" + dtypes[0]).reshape(N * N, N, N, 4) for b in blobs])
    np.testing.assert_array_equal(stored, published.astype(np.float16 if dtype == "half" else np.float32))
    points = shading_points()
    want = host_specular(stored, points)
    got = gl_specular(ctx, list(blobs), sizes[0], dtypes[0], points)
    np.testing.assert_allclose(got, want, rtol=GL_RTOL, atol=GL_ATOL)


def test_half_textures_shade_within_1e_3_of_float32(published):
    """What dtype half (preset ltc-aniso's KTX2) costs the shader, on the host: the result from the half-rounded
    textures against float32 at the shading points."""
    points = shading_points()
    full = host_specular(published, points)
    half = host_specular(published.astype(np.float16), points)
    assert np.abs(published).max() < 2.0
    assert np.abs(published.astype(np.float16) - published).max() <= 2.0**-11
    lit = full > LIT
    rel = np.abs(half - full)[lit] / full[lit]
    print(f"half vs float32: max {rel.max():.2e}, median {np.median(rel):.2e} relative over {lit.sum()} lit points")
    assert lit.sum() > N_POINTS // 3 and rel.max() < HALF_MAX_RTOL and np.median(rel) < HALF_MEDIAN_RTOL


@pytest.mark.parametrize("lobes", [2, 3])
def test_gl_lobes_are_the_sum_of_the_one_lobe_sets(ctx, published, lobes):  # noqa: F811
    """lobes = 2 and 3 (lutbake.ltc.aniso_lobes.lobe_textures' layout, 3 K textures): the shader's two- and three-lobe
    functions equal the host reconstruction of (t0, t1, t2) plus that of (t3, t4, t5) (plus (t6, t7, t8)). Lobe k > 1:
    the published M broadened k times in x and y (not normalised: the layout does not need |M e_z| = 1), other
    weights."""
    g = aniso.Grid4("alphax_alphay", (N,) * 4)
    m = np.load(DATA / "ltc_aniso_alphax_alphay_theta_phi.npy").astype(np.float64)
    a, b, th, _ = np.meshgrid(*g.axes(), indexing="ij")
    more = [
        aniso.texture_layout(m @ np.diag([k, k, 1.0]), 0.2 / k + 0.1 * a, 0.02 + 0.03 * b * th / k, np.zeros(g.n))
        for k in range(2, lobes + 1)
    ]
    points = shading_points()
    want = host_specular(published, points) + sum(host_specular(t, points) for t in more)
    blobs = [np.ascontiguousarray(t).tobytes() for t in np.concatenate([published, *more])]
    got = gl_specular(ctx, blobs, (N, N, N * N), "f4", points)
    assert min(np.abs(host_specular(t, points)).max() for t in more) > 10 * GL_ATOL  # every lobe is seen
    np.testing.assert_allclose(got, want, rtol=GL_RTOL, atol=GL_ATOL)
