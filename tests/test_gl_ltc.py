"""GL consumer, area lights: the ltc-ggx preset's DDS files are uploaded as textures (RGBA16F, linear filtering),
docs/shaders/lutbake_ltc.glsl integrates a quad light with them at random shading points (random normal, view,
roughness, f0 and light), and the result equals lutbake.ltc.polygon.shade evaluated on the CPU from the same
texels (same uv, same edge-integral fit, float64). Skipped where no GL context exists (see test_gl_consumer)."""

from pathlib import Path

import numpy as np
import pytest
from test_formats import read_dds_spec
from test_gl_consumer import ctx  # noqa: F401 - the shared GL context fixture

from lutbake.api import bake_table
from lutbake.config import load_configs
from lutbake.io.formats import write_table
from lutbake.ltc import polygon

SNIPPET = Path(__file__).resolve().parents[1] / "docs" / "shaders" / "lutbake_ltc.glsl"
N_POINTS = 256
SIZE = 16  # a small table (the fit takes seconds); the shader gets the size through LUTBAKE_LTC_SIZE
# the GPU evaluates in float32 and filters with its own weight precision; measured on Mesa llvmpipe (LLVM 15):
# max relative difference 1.9e-5 on lit cases, max absolute 1.6e-7. Bounds: 10x those.
GL_RTOL = 2e-4
GL_ATOL = 2e-6


def random_case(rng):
    """(roughness, NoV, f0, rotation R, quad in the shading frame (4, 3)): lights of several sizes and distances,
    some crossing the horizon."""
    rough = rng.uniform(0.05, 0.98)
    nov = rng.uniform(0.02, 0.99)
    f0 = rng.uniform(0.0, 1.0)
    a = rng.normal(size=3)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    el, az = rng.uniform(-0.3, 1.4), rng.uniform(0, 2 * np.pi)
    d, s = rng.uniform(0.8, 4.0), rng.uniform(0.3, 3.0)
    c = d * np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    n = -c / d
    t1 = np.cross(n, a / np.linalg.norm(a))
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    quad = np.array([c + s / 2 * (x * t1 + y * t2) for x, y in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    return rough, nov, f0, q, quad


@pytest.mark.parametrize("fit", ["l3", "shaded"])
def test_gl_integrates_a_quad_light_with_the_ltc_tables(ctx, tmp_path, fit):  # noqa: F811
    import moderngl

    spec = load_configs([Path("lutbake/presets/ltc-ggx.toml")], [f"size=[{SIZE},{SIZE}]", f'fit="{fit}"'])[0]
    table = bake_table(spec, workers=2)[0]
    path = write_table(table, tmp_path, "ltc_dds", "half")
    t1 = read_dds_spec(path.read_bytes())[0]
    t2 = read_dds_spec(path.with_name(path.name.replace("_1.dds", "_2.dds")).read_bytes())[0]
    assert t1.shape == (SIZE, SIZE, 4) and t1.dtype == np.float16

    rng = np.random.default_rng(14)
    cases = [random_case(rng) for _ in range(N_POINTS)]
    attrs = []
    for rough, nov, f0, r, quad in cases:
        v = np.array([np.sqrt(1 - nov * nov), 0.0, nov])
        attrs.append(np.concatenate([r[:, 2], r @ v, (quad @ r.T).ravel(), [rough, f0]]))
    attrs = np.array(attrs, np.float32)

    texs = []
    for data in (t1, t2):
        tex = ctx.texture((SIZE, SIZE), 4, np.ascontiguousarray(data).tobytes(), dtype="f2")
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        texs.append(tex)
    target = ctx.texture((N_POINTS, 1), 4, dtype="f4")
    fbo = ctx.framebuffer(color_attachments=[target])
    prog = ctx.program(
        vertex_shader=f"""#version 330
            in vec3 in_n; in vec3 in_v; in vec3 in_p0; in vec3 in_p1; in vec3 in_p2; in vec3 in_p3; in vec2 in_rf;
            in float in_i;
            flat out vec3 n; flat out vec3 v; flat out vec3 p0; flat out vec3 p1; flat out vec3 p2; flat out vec3 p3;
            flat out vec2 rf;
            void main() {{ n = in_n; v = in_v; p0 = in_p0; p1 = in_p1; p2 = in_p2; p3 = in_p3; rf = in_rf;
                gl_Position = vec4((in_i + 0.5) / {N_POINTS}.0 * 2.0 - 1.0, 0.0, 0.0, 1.0); gl_PointSize = 1.0; }}""",
        fragment_shader=f"#version 330\n#define LUTBAKE_LTC_SIZE {SIZE}.0\n"
        + SNIPPET.read_text()
        + """
            uniform sampler2D ltc_1; uniform sampler2D ltc_2;
            flat in vec3 n; flat in vec3 v; flat in vec3 p0; flat in vec3 p1; flat in vec3 p2; flat in vec3 p3;
            flat in vec2 rf; out vec4 color;
            void main() {
                vec3 p[4] = vec3[4](p0, p1, p2, p3);
                vec3 s = lutbake_ltc_specular(ltc_1, ltc_2, n, v, rf.x, vec3(rf.y), p, vec3(1.0), true);
                color = vec4(s, 1.0);
            }""",
    )
    prog["ltc_1"].value = 0
    prog["ltc_2"].value = 1
    data = np.concatenate([attrs, np.arange(N_POINTS, dtype=np.float32)[:, None]], axis=1)
    vbo = ctx.buffer(np.ascontiguousarray(data).tobytes())
    vao = ctx.vertex_array(
        prog, [(vbo, "3f 3f 3f 3f 3f 3f 2f 1f", "in_n", "in_v", "in_p0", "in_p1", "in_p2", "in_p3", "in_rf", "in_i")]
    )
    fbo.use()
    texs[0].use(0)
    texs[1].use(1)
    ctx.disable(moderngl.BLEND)
    vao.render(moderngl.POINTS)
    got = np.frombuffer(fbo.read(components=4, dtype="f4"), dtype="f4").reshape(N_POINTS, 4)[:, 0]
    for o in (vao, vbo, prog, fbo, target, *texs):
        o.release()

    t1c, t2c = t1.astype(np.float64), t2.astype(np.float64)
    want = np.array(
        [
            polygon.shade(t1c, t2c, a[-2], nov, quad, f0=a[-1], edge=polygon.edge_fitted)
            for a, (rough, nov, f0, r, quad) in zip(attrs.astype(np.float64), cases)
        ]
    )
    lit = want > 1e-3
    assert lit.sum() > N_POINTS // 3, "too few lit cases to test anything"
    rel = np.max(np.abs(got - want)[lit] / want[lit])
    print(f"max |GL - CPU| {np.abs(got - want).max():.2e}, max rel (lit) {rel:.2e}")
    np.testing.assert_allclose(got, want, rtol=GL_RTOL, atol=GL_ATOL)
