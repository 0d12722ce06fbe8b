"""Kind ltc_aniso with ``lobes = 2`` and ``3`` (lutbake.ltc.aniso_lobes): the check's refusals, the six (nine) textures
and their files, each set shading as the fit's model of the sum (lutbake.ltc.aniso.lookup, the shader's reconstruction,
on each one-lobe set, added), the Schlick channel against the one-lobe table's, the per-texel fit and the between fit
lowering their costs. Tiny: N = 3, 120 training configurations, 2 steps (the shader's two-lobe function:
tests/test_gl_ltc_aniso.py)."""

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake.api import bake
from lutbake.cli import main
from lutbake.config import load_configs
from lutbake.errors import ConfigError
from lutbake.io.ltc_aniso_textures import read_textures
from lutbake.io.readers import read_table
from lutbake.ltc import aniso, aniso_lobes, shaded

N = 3
GRID = aniso.Grid4("alphax_alphay", (N,) * 4)
COMMON = 'kind = "ltc_aniso"\nsize = 3\nfit_samples = 8\nsamples = 256\nfit = "shaded"\n'
TWO = COMMON + "lobes = 2\nbetween_configs = 120\nbetween_iterations = 2\n"
THREE = TWO.replace("lobes = 2", "lobes = 3")
MODEL_RTOL = 1e-9  # the same float64 sum in another order
FLOAT32_RTOL = 1e-6


def table(name: str, body: str, fmt: str = "exr") -> str:
    return f'[[table]]\nname = "{name}"\n{body}format = "{fmt}"\n\n'


@pytest.fixture(scope="module")
def baked(tmp_path_factory) -> dict:
    tmp = tmp_path_factory.mktemp("ltc_aniso_lobes")
    cfg = tmp / "two.toml"
    cfg.write_text(table("two", TWO) + table("twok", TWO, "ktx2") + table("one", COMMON))
    cfg.write_text(cfg.read_text() + table("three", THREE) + table("threed", THREE, "dds"))
    out = tmp / "out"
    bake(cfg, out, workers=1)
    return {"out": out, "tmp": tmp} | {k: read_table(out / f"{k}.exr") for k in ("one", "two", "three")}


def sets(data: np.ndarray) -> list[np.ndarray]:
    """Each lobe's channels (N, N, N, N, 12): M row-major (9), weight, weight_fresnel, sum_error."""
    d = np.asarray(data, np.float64).reshape(-1, N * N, N, N, 4)
    return [d[k : k + 3].transpose(1, 2, 3, 0, 4).reshape(N, N, N, N, 12) for k in range(0, len(d), 3)]


@pytest.mark.parametrize(
    "body, key, words",
    [
        ('lobes = 2\nfit = "l3"\n', "fit", "shaded"),
        ('lobes = 2\nfit = "shaded"\nformat = "ltc_aniso_npy"\n', "format", "exr, npy, ktx2 or dds"),
        ('lobes = 3\nfit = "l3"\n', "fit", "shaded"),
        ("lobes = 4\n", "lobes", "3"),
    ],
)
def test_check_refuses_two_lobes_without_the_shaded_fit_or_in_the_papers_npy(tmp_path, body, key, words):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(f'[[table]]\nname = "x"\nkind = "ltc_aniso"\nsize = 3\n{body}')
    with pytest.raises(ConfigError) as e:
        load_configs([cfg])
    assert key in str(e.value) and words in str(e.value)


def test_two_lobes_are_six_textures_with_their_record(baked):
    t = baked["two"]
    assert t.data.shape == (6, N**3, N, 4) and np.all(np.isfinite(t.data))
    one, two = sets(t.data)
    np.testing.assert_array_equal(one[..., 11], two[..., 11])  # sum_error: the same in t2 and t5
    assert np.all(one[..., 11] > 0.0)
    assert t.attrs["ltc_aniso_lobes"].startswith("2:") and "two_lobes" in t.attrs["ltc_aniso_shader"]
    assert (
        "120 configurations" in t.attrs["ltc_aniso_fit"] and "2 Levenberg-Marquardt steps" in t.attrs["ltc_aniso_fit"]
    )
    assert "t2/t5: weight" in t.attrs["channels"]


def test_three_lobes_are_nine_textures_split_from_two(baked):
    """lobes = 3: nine textures, the record naming the split (lutbake.ltc.aniso_lobes.split_narrow) and the
    three-lobe shader function; split_narrow keeps lobe 2 and the narrow lobe's weight (half to each of its two)."""
    t = baked["three"]
    assert t.data.shape == (9, N**3, N, 4) and np.all(np.isfinite(t.data))
    assert t.attrs["ltc_aniso_lobes"].startswith("3:") and "three_lobes" in t.attrs["ltc_aniso_shader"]
    assert "narrow lobe split" in t.attrs["ltc_aniso_fit"] and "t2/t5/t8: weight" in t.attrs["channels"]
    rng = np.random.default_rng(2)
    m, w = rng.normal(size=(5, 2, 3, 3)), rng.random((5, 2))
    m3, w3 = aniso_lobes.split_narrow(m, w)
    np.testing.assert_array_equal(m3[:, 1], m[:, 1])
    np.testing.assert_array_equal(w3[:, 1], w[:, 1])
    np.testing.assert_allclose(w3[:, 0] + w3[:, 2], w[:, 0], rtol=1e-15)
    for k, s in ((0, aniso_lobes.SPLIT[0]), (2, aniso_lobes.SPLIT[1])):
        np.testing.assert_allclose(m3[:, k], m[:, 0] * np.array([s, s, 1.0]), rtol=1e-15)


@pytest.mark.parametrize("name", ["two", "three"])
def test_no_lobe_has_a_negative_weight(baked, name):
    """The between fit projects w_k >= 0 (a negative lobe would shade a light holding only it below zero); without the
    projection the two-lobe table's w_2 reached -0.46."""
    for lobe in sets(baked[name].data):
        assert lobe[..., 9].min() >= 0.0 and lobe[..., 10].min() >= 0.0


@pytest.mark.parametrize("name", ["two", "three"])
def test_weight_fresnel_is_the_weight_times_the_one_lobe_tables_fresnel_over_magnitude(baked, name):
    """t2.z / t5.z (/ t8.z) = w_k fresnel / magnitude, fresnel and magnitude the one-lobe table's t2 (the same
    estimator)."""
    one_lobe = sets(baked["one"].data)[0]
    for lobe in sets(baked[name].data):
        want = lobe[..., 9] * one_lobe[..., 10] / one_lobe[..., 9]
        np.testing.assert_allclose(lobe[..., 10], want, rtol=4 * FLOAT32_RTOL, atol=1e-7)


@pytest.mark.parametrize("name", ["two", "three"])
def test_each_set_shades_as_the_fits_model_of_the_sum(baked, name):
    """At random points between the texels: Σ_k w_k I(M_k), each set reconstructed as a one-lobe table
    (lutbake.ltc.aniso.lookup, the shader's), equals the between fit's model (BetweenLobes: the 16 corners of the
    table x read back from the file) over the same tangent-frame lights."""
    lobes = sets(baked[name].data)
    x = np.concatenate([s[..., :9].reshape(-1, 9) for s in lobes] + [s[..., 9].reshape(-1, 1) for s in lobes], 1)
    rng = np.random.default_rng(5)
    u = rng.random((40, 4))
    ax, ay = aniso_lobes.table_alphas(GRID, u[:, 0], u[:, 1])
    theta, phi = u[:, 2] * aniso.THETA_SCALE * np.pi / 2, u[:, 3] * np.pi / 2
    lights = shaded.texel_lights(np.cos(theta), np.sqrt(ax * ay), 8)  # view frame
    polys = np.einsum("nij,nlvj->nlvi", aniso_lobes.rotation_z(phi), lights)
    index, weight = aniso.corner_weights(u, GRID.n)
    flat = np.ravel_multi_index(tuple(index.transpose(2, 0, 1)), GRID.n)
    ts = {"polys": polys, "G": np.zeros(polys.shape[:2]), "A": np.ones(len(u)), "texel": flat, "weight": weight}
    model = aniso_lobes.BetweenLobes(ts, N**4, len(lobes))
    value = model.residuals(x)[0] / model.scale
    host = 0.0
    for s in lobes:
        m, w = aniso.lookup(s[..., :9].reshape(N, N, N, N, 3, 3), GRID, ax, ay, theta, phi, s[..., 9:10])
        host = host + w[:, :1] * shaded.integrals(np.linalg.inv(m), np.arange(len(u)), polys)
    assert np.abs(host).max() > 1e-2
    np.testing.assert_allclose(host, value, rtol=MODEL_RTOL, atol=1e-12)


def test_per_texel_fit_and_between_fit_lower_their_costs(baked):
    """Two lobes fitted at each texel shade the texels' own lights better than the one-lobe shaded table
    (sum_error's median), and each step of the between fit lowers its regularised cost, the shaded cost with it."""
    one = sets(baked["one"].data)[0]
    m1, mag = one[..., :9].reshape(N, N, N, N, 3, 3), one[..., 9]
    per_texel = aniso_lobes.per_texel_table(GRID, mag, m1, 2, iterations=10)
    two_err = aniso_lobes.sum_error(GRID, mag, *per_texel)
    one_err = aniso_lobes.sum_error(GRID, mag, m1.reshape(-1, 1, 3, 3), mag.reshape(-1, 1))
    assert np.median(two_err) < 0.8 * np.median(one_err)
    ts = aniso_lobes.training_set(GRID, 100, 8, 11, aniso_lobes.HEMISPHERE)
    m, w = per_texel
    x0 = np.concatenate([m.reshape(len(m), -1), np.minimum(w, mag.reshape(-1, 1))], axis=1)
    model = aniso_lobes.BetweenLobes(ts, len(x0), 2)
    costs = []
    x = aniso_lobes.fit_between(x0, model, 3, log=costs.append)
    before_after = [tuple(float(c) for c in line.split("cost ")[1].split(",")[0].split(" -> ")) for line in costs]
    assert all(after < before for before, after in before_after)
    assert model.cost(x) < 0.9 * model.cost(x0)


@pytest.mark.parametrize("name, stem, ext, count", [("two", "twok", "ktx2", 6), ("three", "threed", "dds", 9)])
def test_texture_files_round_trip_and_inspect(baked, name, stem, ext, count):
    """Six KTX2 (two lobes) and nine DDS (three lobes) 3D textures: read back as one set, texel for texel the EXR's."""
    out = baked["out"]
    names = [f"{stem}_t{k}.{ext}" for k in range(count)]
    got = read_textures(out / f"{stem}_t4.{ext}")
    assert [f.name for f in got.files] == names
    np.testing.assert_array_equal(got.data.reshape(count, N**3, N, 4), baked[name].data)
    assert not (out / f"{stem}_t{count}.{ext}").exists()
    r = CliRunner().invoke(main, ["inspect", str(out / f"{stem}_t{count - 1}.{ext}")])
    assert r.exit_code == 0, r.output
    assert f"t{count - 1} = (M22, weight, weight_fresnel, sum_error)" in r.output


def test_narrow_first_orders_each_texels_lobes_by_their_spread_whatever_the_scale():
    """spread(diag(a, a, 1) s) = a^2 for any scale s; narrow_first swaps M and w together, texel by texel."""
    from lutbake.ltc.aniso_lobes import narrow_first, spread

    broad, narrow = np.diag([2.0, 2.0, 1.0]), np.diag([0.5, 0.5, 1.0])
    assert spread(7.0 * broad) == pytest.approx(4.0) and spread(0.1 * narrow) == pytest.approx(0.25)
    m = np.array([[3.0 * broad, narrow], [narrow, 0.2 * broad]])
    w = np.array([[0.3, 0.7], [0.6, 0.4]])
    got_m, got_w = narrow_first(m, w)
    np.testing.assert_array_equal(got_m[:, 0], [narrow, narrow])
    np.testing.assert_array_equal(got_w, [[0.7, 0.3], [0.6, 0.4]])
