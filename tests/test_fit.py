"""lutbake fit: the published closed forms re-implemented in numpy match lutbake's terms, and the refits help."""

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake.cli import main
from lutbake.commands.fit import GOTANDA_PUBLISHED, KARIS_PUBLISHED, fit_gotanda, fit_karis, gotanda_eq8, karis_mobile
from lutbake.integrands import diffuse

EQ8_RTOL = 1e-5  # float32 Warp term vs float64 numpy


def test_karis_published_constants_reproduce_envbrdfapprox_by_hand():
    # Karis 2014 at roughness 0.5, NoV 0.5, written out: r = 0.5 c0 + c1
    r = 0.5 * np.array([-1, -0.0275, -0.572, 0.022]) + np.array([1, 0.0425, 1.04, -0.04])
    a004 = min(r[0] ** 2, 2 ** (-9.28 * 0.5)) * r[0] + r[1]
    expected = np.array([-1.04 * a004 + r[2], 1.04 * a004 + r[3]])
    np.testing.assert_allclose(karis_mobile(KARIS_PUBLISHED, np.array(0.5), np.array(0.5)), expected, rtol=1e-12)


def test_gotanda_eq8_numpy_equals_lutbake_fitted_term():
    rng = np.random.default_rng(3)
    nl, nv, sig = rng.uniform(0.05, 1, 64), rng.uniform(0.05, 1, 64), rng.uniform(0, 1, 64)
    phi = rng.uniform(0, np.pi, 64)
    sl, sv = np.sqrt(1 - nl**2), np.sqrt(1 - nv**2)
    l = np.stack([sl * np.cos(phi), sl * np.sin(phi), nl], -1)
    v = np.stack([sv, 0 * sv, nv], -1)
    ref = diffuse.eval_brdf("fitted", l, v, sig)
    got = gotanda_eq8(GOTANDA_PUBLISHED, nl, nv, sl * sv * np.cos(phi) + nl * nv, sig)
    np.testing.assert_allclose(got, ref, rtol=EQ8_RTOL, atol=1e-7)


@pytest.fixture(scope="module")
def karis16():
    """The Karis refit on a 16^2 grid, shared by the tests that read it."""
    return fit_karis(n=16)


@pytest.fixture(scope="module")
def gotanda_small():
    """The Gotanda refit on a 6 x 4 x 5 grid (40 evaluations at most), shared by both languages' test."""
    return fit_gotanda(6, 4, 5, max_nfev=40)


def test_karis_refit_lowers_the_rms_and_emits_both_languages(karis16):
    r = karis16
    for key in ("max |E - E_exact| (f0 = 0.04)", "max |E - E_exact| (f0 = 1)", "mean |A - scale|"):
        assert r.errors["refit"][key] < r.errors["published"][key], key
    assert "EnvBRDFApprox_lutbake" in r.code["glsl"] and "float2" in r.code["hlsl"]


@pytest.mark.parametrize("lang", ["glsl", "hlsl"])
def test_gotanda_refit_lowers_the_floored_max_relative_error(gotanda_small, lang):
    r = gotanda_small
    key = "max relative, floored at 0.02/pi"
    assert r.errors["refit"][key] < r.errors["published"][key]
    assert "Fd_gotanda_refit" in r.code[lang]


def test_cli_fit_writes_the_shader(tmp_path):
    out = tmp_path / "approx.hlsl"
    res = CliRunner().invoke(main, ["fit", "karis-mobile", "--lang", "hlsl", "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "published" in res.output and "float2 EnvBRDFApprox_lutbake" in out.read_text()


def test_emitted_glsl_compiles_and_matches_numpy(karis16):
    """The emitted Karis GLSL, run on a real OpenGL (moderngl, EGL), returns what the numpy form returns."""
    moderngl = pytest.importorskip("moderngl")
    try:
        ctx = moderngl.create_standalone_context(backend="egl")
    except Exception as e:  # no EGL / GL driver here
        pytest.skip(f"no OpenGL context: {e}")
    r = karis16
    pts = np.array([[0.1, 0.2], [0.5, 0.5], [0.9, 0.95], [0.02, 0.7]], np.float32)
    got = _render(ctx, r.code["glsl"], "vec4(EnvBRDFApprox_lutbake(q.x, q.y), 0.0, 1.0)", pts)[:, :2]
    np.testing.assert_allclose(
        got, karis_mobile(r.refit, pts[:, 0].astype(np.float64), pts[:, 1].astype(np.float64)), atol=1e-5
    )
    glsl_gotanda = fit_gotanda(6, 4, 5, max_nfev=5).code["glsl"]
    _render(ctx, glsl_gotanda, "vec4(Fd_gotanda_refit(q.x, q.y, 0.1, 0.5, 0.04))", pts)  # compiles and runs
    ctx.release()


def _render(ctx, functions: str, expr: str, pts: np.ndarray) -> np.ndarray:
    """Evaluate ``expr`` (GLSL, of vec2 q) at every point: one pixel per point of a float framebuffer."""
    import moderngl

    n = len(pts)
    prog = ctx.program(
        vertex_shader="#version 330\nin vec2 p; in float i; out vec2 q;\nuniform float n;\n"
        "void main() { q = p; gl_Position = vec4((2.0 * i + 1.0) / n - 1.0, 0.0, 0.0, 1.0); "
        "gl_PointSize = 1.0; }",
        fragment_shader="#version 330\nin vec2 q; out vec4 color;\n" + functions + f"void main() {{ color = {expr}; }}",
    )
    prog["n"].value = float(n)
    data = np.concatenate([pts, np.arange(n, dtype=np.float32)[:, None]], 1).astype(np.float32)
    vao = ctx.vertex_array(prog, [(ctx.buffer(data.tobytes()), "2f 1f", "p", "i")])
    fbo = ctx.framebuffer(color_attachments=[ctx.texture((n, 1), 4, dtype="f4")])
    fbo.use()
    fbo.clear()
    vao.render(moderngl.POINTS)
    return np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(n, 4)
