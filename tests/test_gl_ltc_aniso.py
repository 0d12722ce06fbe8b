"""GL consumer, anisotropic area lights: the published 8^4 anisotropic LTC table (tests/data) in lutbake's texture
layout (lutbake.ltc.aniso.texture_layout: three RGBA32F 3D textures 8 x 8 x 64, linear filtering) through
docs/shaders/ltc_aniso.glsl equals the host reconstruction (lutbake.ltc.aniso.lookup, then the polygon integral with
the same edge fit) at random shading points (normal, tangent, view in every azimuth quadrant, alpha_x, alpha_y, f0,
quad). Skipped where no GL context exists (see test_gl_consumer)."""

from pathlib import Path

import numpy as np
from test_gl_consumer import ctx  # noqa: F401 - the shared GL context fixture

from lutbake.ltc import aniso, polygon

SHADERS = Path(__file__).resolve().parents[1] / "docs" / "shaders"
DATA = Path(__file__).parent / "data"
N_POINTS = 128
GL_RTOL = 2e-3  # float32 shading and the GPU's filter weights (8-bit sub-texel precision in some drivers)
GL_ATOL = 2e-4


def test_gl_shades_anisotropic_ggx_with_the_texture_layout(ctx):  # noqa: F811
    import moderngl

    g = aniso.Grid4("alphax_alphay", (8, 8, 8, 8))
    m = np.load(DATA / "ltc_aniso_alphax_alphay_theta_phi.npy").astype(np.float64)
    a, b, th, ph = np.meshgrid(*g.axes(), indexing="ij")
    mag = 1.0 - 0.3 * a * np.cos(th)  # any smooth channels: the test is the reconstruction, not the values
    fres = 0.1 + 0.05 * b
    tex = aniso.texture_layout(m, mag, fres, np.zeros(g.n))
    rng = np.random.default_rng(3)
    rows, want = [], []
    for _ in range(N_POINTS):
        ax, ay, f0 = rng.uniform(0.02, 1.0), rng.uniform(0.02, 1.0), rng.uniform(0.0, 1.0)
        theta, phi = np.arccos(rng.uniform(0.05, 1.0)), rng.uniform(0, 2 * np.pi)
        v = np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
        el, az, d, s = rng.uniform(-0.2, 1.4), rng.uniform(0, 2 * np.pi), rng.uniform(0.8, 3.0), rng.uniform(0.3, 2.0)
        c = d * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        t1 = np.cross(-c / d, [0.3, 0.5, 0.8])
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(-c / d, t1)
        quad = np.array([c + s / 2 * (x * t1 + y * t2) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
        mt, e = aniso.lookup(m, g, ax, ay, theta, phi, np.stack([mag, fres], -1))
        ff = abs(polygon.form_factor(quad @ np.linalg.inv(mt[0]).T, polygon.edge_fitted))
        want.append(ff * (f0 * e[0, 0] + (1 - f0) * e[0, 1]))
        rows.append(np.concatenate([v, quad.ravel(), [ax, ay, f0]]))  # frame: T = x, B = y, N = z
    attrs = np.array(rows, np.float32)
    textures = []
    for k in range(3):  # clamp to edge, linear: the layout's filtering
        t = ctx.texture3d((8, 8, 64), 4, np.ascontiguousarray(tex[k]).tobytes(), dtype="f4")
        t.repeat_x = t.repeat_y = t.repeat_z = False
        t.filter = (moderngl.LINEAR, moderngl.LINEAR)
        textures.append(t)
    prog = ctx.program(
        vertex_shader=f"""#version 330
            in vec3 in_v; in vec3 in_p0; in vec3 in_p1; in vec3 in_p2; in vec3 in_p3; in vec3 in_a; in float in_i;
            flat out vec3 v; flat out vec3 p0; flat out vec3 p1; flat out vec3 p2; flat out vec3 p3; flat out vec3 a;
            void main() {{ v = in_v; p0 = in_p0; p1 = in_p1; p2 = in_p2; p3 = in_p3; a = in_a;
                gl_Position = vec4((in_i + 0.5) / {N_POINTS}.0 * 2.0 - 1.0, 0.0, 0.0, 1.0); gl_PointSize = 1.0; }}""",
        fragment_shader="#version 330\n"
        + (SHADERS / "lutbake_ltc.glsl").read_text()
        + (SHADERS / "ltc_aniso.glsl").read_text()
        + """
            uniform sampler3D t0; uniform sampler3D t1; uniform sampler3D t2;
            flat in vec3 v; flat in vec3 p0; flat in vec3 p1; flat in vec3 p2; flat in vec3 p3; flat in vec3 a;
            out vec4 color;
            void main() {
                vec3 p[4] = vec3[4](p0, p1, p2, p3);
                vec3 s = lutbake_ltc_aniso_specular(t0, t1, t2, vec3(0, 0, 1), vec3(1, 0, 0), v, a.x, a.y, vec3(a.z),
                                                    p, vec3(1.0), true);
                color = vec4(s, 1.0);
            }""",
    )
    target = ctx.texture((N_POINTS, 1), 4, dtype="f4")
    fbo = ctx.framebuffer(color_attachments=[target])
    for k in range(3):
        prog[f"t{k}"].value = k
        textures[k].use(k)
    data = np.concatenate([attrs, np.arange(N_POINTS, dtype=np.float32)[:, None]], axis=1)
    vbo = ctx.buffer(np.ascontiguousarray(data).tobytes())
    vao = ctx.vertex_array(
        prog, [(vbo, "3f 3f 3f 3f 3f 3f 1f", "in_v", "in_p0", "in_p1", "in_p2", "in_p3", "in_a", "in_i")]
    )
    fbo.use()
    ctx.disable(moderngl.BLEND)
    vao.render(moderngl.POINTS)
    got = np.frombuffer(fbo.read(components=4, dtype="f4"), dtype="f4").reshape(N_POINTS, 4)[:, 0]
    for o in (vao, vbo, prog, fbo, target, *textures):
        o.release()
    want = np.array(want)
    assert (want > 1e-3).sum() > N_POINTS // 3, "too few lit cases to test anything"
    print(f"max |GL - CPU| {np.abs(got - want).max():.2e}")
    np.testing.assert_allclose(got, want, rtol=GL_RTOL, atol=GL_ATOL)
