"""Pictures of an environment: the ground truth of spheres under it against lutbake's own tables (white furnace),
the split sum's plumbing (a uniform environment gives the DFG lookup), the cube lookup (exact at texel centres,
seamless, second order), the SH sphere in closed form, the cube preview (size, not blank, the cross, every file
format) and the spheres command."""

import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake.cli import main
from lutbake.commands import preview_cube, spheres
from lutbake.commands.preview import lookup
from lutbake.config import load_configs, preset_path, validate_table
from lutbake.environment import cube, ground_truth, latlong, prefilter, render, sh
from lutbake.environment.curves import CURVES
from lutbake.io.cubemap import write_cube_table
from lutbake.pipeline import bake_cube_table, bake_table

SUNRISE = Path(__file__).parent / "data" / "env_sunrise_64x32.exr"
# measured at 32 x 64 texels, the default rule (K = 8, one node more): the GGX pair against the dfg table 8.0e-5
# (grazing n.v = 1/16 included); against the diffuse tables Lambert 2e-7, Gotanda's fitted model 5.8e-6, Oren-Nayar
# 2.1e-5 (its max(0, cos phi) kink; 1.6e-6 at K = 16, two nodes more)
FURNACE_TOLERANCE = 2e-4
DIFFUSE_FURNACE_TOLERANCE = 5e-5
EXACT = 1e-12
NUMPY_TOLERANCE = 1e-5  # of the largest value; measured 2.8e-6 against the 64 x 64 midpoint sums, 1.1e-6 at 128


def frames(mu: np.ndarray, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(n, v): random unit normals n and views v with n.v = mu."""
    rng = np.random.default_rng(seed)
    n = rng.normal(size=(len(mu), 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    t = np.cross(n, rng.normal(size=(len(mu), 3)))
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    return n, mu[:, None] * n + np.sqrt(1 - mu * mu)[:, None] * t


@pytest.fixture(scope="module")
def dfg():
    """The glTF preset's DFG table (scale_bias, GGX, height-correlated Smith, perceptual r) at 8 n.v x 6 r."""
    return bake_table(load_configs([preset_path("gltf")], ["lut_ggx.size=[8,6]"])[0])[0]


# --- the ground truth ---------------------------------------------------------------------------------------------


def test_the_ground_truth_of_a_uniform_environment_is_the_dfg_tables_albedo(dfg):
    """White furnace: L = 1 everywhere gives ∫ f/F (1 - Fc) (n.l) and ∫ f/F Fc (n.l), the table's scale and bias
    at its texel centres (n.v from 1/16, r from 1/12), for normals and views in every direction."""
    axes = {a.name: a for a in dfg.axes}
    mu, rs = axes["NoV"].values(), axes["perceptual_roughness"].values()
    env = ground_truth.Environment(np.ones((32, 64, 3)))
    worst = 0.0
    for k, r in enumerate(rs):
        n, v = frames(mu, k)
        a, b = ground_truth.specular(env, n, v, r * r)
        np.testing.assert_allclose(a, a[:, :1].repeat(3, 1), rtol=0, atol=EXACT)  # grey in, grey out
        worst = max(worst, float(np.abs(np.stack([a[:, 0], b[:, 0]], 1) - dfg.data[k]).max()))
    assert worst < FURNACE_TOLERANCE, worst


def numpy_ggx_pair(image: np.ndarray, n: np.ndarray, v: np.ndarray, alpha: float, m: int) -> np.ndarray:
    """(a, b) (2, 3) of one pixel by an m x m midpoint rule in (cos theta, phi) per texel, numpy only: GGX D
    (Walter et al. 2007, Eq. 33), height-correlated Smith (Heitz 2014, Eq. 99), Schlick's (1 - v.h)^5."""
    h, w = image.shape[:2]
    mu_edges, phi_edges = np.cos(latlong.row_edges(h)), latlong.column_edges(w)
    x = (np.arange(m) + 0.5) / m
    mu = (mu_edges[:-1, None] + np.diff(mu_edges)[:, None] * x).reshape(h, 1, m, 1)
    phi = (phi_edges[:-1, None] + np.diff(phi_edges)[:, None] * x).reshape(1, w, 1, m)
    s = np.sqrt(1 - mu * mu)
    l = np.stack(np.broadcast_arrays(s * np.cos(phi), mu, s * np.sin(phi)), axis=-1)  # (h, w, m, m, 3)
    a2 = alpha * alpha
    nol, nov = l @ n, n @ v
    half = l + v
    half /= np.linalg.norm(half, axis=-1, keepdims=True)
    noh, voh = half @ n, half @ v
    D = a2 / (np.pi * (noh * noh * (a2 - 1) + 1) ** 2)

    def lam(c):
        return 0.5 * (np.sqrt(c * c + a2 * (1 - c * c)) / c - 1)

    common = np.where(nol > 0, D / (1 + lam(nov) + lam(np.maximum(nol, 1e-12))) / (4 * nov), 0.0)
    fc = (1 - voh) ** 5
    cell = (np.abs(np.diff(mu_edges))[:, None] * np.diff(phi_edges)[None, :]) / (m * m)
    sums = [(common * f).sum(axis=(2, 3)) * cell for f in (1 - fc, fc)]
    return np.array([np.einsum("hw,hwc->c", t, image) for t in sums])


def test_the_ground_truth_of_a_random_environment_is_a_fine_numpy_sum():
    """Random texel radiance: the kernel's pair against numpy's midpoint sums of its own GGX, Smith and Schlick
    (64 x 64 points per texel: the difference, 2.8e-6 of the largest value, falls to 1.1e-6 at 128 x 128 as the
    midpoint rule's own error does)."""
    image = np.random.default_rng(5).uniform(0.0, 3.0, (8, 16, 3))
    mu = np.array([0.15, 0.9])
    n, v = frames(mu, 2)
    a, b = ground_truth.specular(image, n, v, 0.25)
    for k in range(len(mu)):
        ref = numpy_ggx_pair(image, n[k], v[k], 0.25, 64)
        np.testing.assert_allclose(np.array([a[k], b[k]]), ref, rtol=0, atol=NUMPY_TOLERANCE * ref.max())


def test_the_mirror_limit_reflects_the_texel_at_R_times_schlick():
    image = np.random.default_rng(3).uniform(0.1, 2.0, (8, 16, 3))
    mu = np.array([0.2, 0.6, 0.95])
    n, v = frames(mu, 7)
    a, b = ground_truth.specular(image, n, v, 0.0)
    fc = ((1 - mu) ** 5)[:, None]
    L = latlong.lookup(image, 2 * mu[:, None] * n - v)
    np.testing.assert_allclose(a, L * (1 - fc), rtol=EXACT)
    np.testing.assert_allclose(b, L * fc, rtol=EXACT)


@pytest.mark.parametrize("model, sigma", [("lambert", 0.0), ("oren_nayar", 0.7), ("fitted", 1.0)])
def test_a_diffuse_models_ground_truth_of_a_uniform_environment_is_its_diffuse_table(model, sigma):
    """∫ f (n.l) dω for L = 1 is the directional albedo lutbake's diffuse table holds (texel centres in n.v)."""
    raw = {"name": "d", "kind": "diffuse", "model": model, "size": [6, 1], "sigma_range": [sigma, 1.0]}
    table = bake_table(validate_table(raw, "<test>", 0))[0]
    mu = next(a for a in table.axes if a.name == "NoV").values()
    sig = next(a for a in table.axes if a.name == "sigma").values()[0]
    n, v = frames(mu, 11)
    got = ground_truth.diffuse(np.ones((32, 64, 3)), n, v, model, float(sig))
    np.testing.assert_allclose(got[:, 0], table.data[0, :, 0], rtol=0, atol=DIFFUSE_FURNACE_TOLERANCE)


# --- the split sum --------------------------------------------------------------------------------------------------


def test_the_split_sum_of_a_uniform_environment_is_the_dfg_lookup(dfg):
    """L = 2: the prefiltered cube is 2 in every texel of every mip, so the split sum is 2 (f0 scale + bias) with
    scale and bias the DFG table's bilinear lookup at (n.v, r), for any lod, and the irradiance cube is 2."""
    pyr = latlong.pyramid(np.full((8, 16, 3), 2.0))
    curve = CURVES["linear"]
    baked = prefilter.bake_cube(pyr, 4, [curve.roughness(m, 3) for m in range(3)], estimate=False, method="quadrature")
    sampler = render.CubeSampler(baked.mips)
    view = render.sphere_view(9, render.camera_direction(0.4, 0.3))
    f0 = np.array([1.0, 0.71, 0.29])
    nov = np.clip(np.sum(view.n * view.v, axis=1), 0, 1)
    for r in (0.0, 0.3, 0.75, 1.0):
        got = render.split_sum_specular(sampler, curve, spheres.dfg_of(dfg), view.n, view.v, r, f0)
        t = lookup(dfg.data, dfg.axes, {"NoV": nov, "perceptual_roughness": np.full_like(nov, r)})
        np.testing.assert_allclose(got, 2 * (f0 * t[:, :1] + t[:, 1:2]), rtol=1e-12)


def test_lod_inverts_each_curve():
    for curve in CURVES.values():
        for mips in (5, 9):
            for m in np.linspace(0, mips - 1, 7):
                r = curve.roughness(m, mips)
                if r < 1:  # past r = 1 a curve is flat (hdrp): any lod there reads r = 1
                    assert abs(render.lod(curve, r, mips) - m) < 1e-9, (curve.name, mips, m)


# --- the cube lookup ------------------------------------------------------------------------------------------------


def linear(d: np.ndarray) -> np.ndarray:
    return (d @ np.array([0.3, -0.5, 0.8]) + 1.0)[..., None] * np.array([1.0, 2.0, 3.0])


def test_the_cube_lookup_is_exact_at_texel_centres_and_trilinear_between_mips():
    mips = [linear(cube.texel_centres(n)) for n in (8, 4)]
    sampler = render.CubeSampler(mips)
    centres = cube.texel_centres(8).reshape(-1, 3)
    np.testing.assert_allclose(sampler.sample(centres, 0.0), linear(centres), rtol=0, atol=EXACT)
    d = np.random.default_rng(0).normal(size=(500, 3))
    half = (sampler.bilinear(0, d) + sampler.bilinear(1, d)) / 2
    np.testing.assert_allclose(sampler.sample(d, 0.5), half, rtol=0, atol=EXACT)


def test_the_cube_lookup_is_seamless_across_every_edge_and_corner():
    """The bilinear lookup is continuous across every face edge and corner (the padding takes the neighbour's
    texels: a face clamped at its edge would jump by a texel's difference, ~0.1 here); its mean error falls as the
    texel size squared (measured ratios 3.8, 3.9 per halving), its largest, in the texels by an edge where the
    neighbour's texel is not at the extended grid's place (as in GL's seamless filtering), as the texel size."""
    sampler = render.CubeSampler([linear(cube.texel_centres(8))])
    faces = np.arange(6)
    for u, v in ((1.0, 0.3), (-1.0, -0.6), (0.2, 1.0), (-0.7, -1.0), (1.0, 1.0), (-1.0, 1.0)):  # edges, corners
        on = cube.face_directions(faces, u, v)
        outward = cube.face_directions(faces, (1 + 1e-7) * u, (1 + 1e-7) * v) - on  # a step across the edge
        jump = np.abs(sampler.bilinear(0, on + outward) - sampler.bilinear(0, on - outward))
        assert jump.max() < 1e-5, (u, v, jump.max())
    d = np.random.default_rng(1).normal(size=(4000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    errors = [
        np.abs(render.CubeSampler([linear(cube.texel_centres(n))]).bilinear(0, d) - linear(d)) for n in (8, 16, 32)
    ]
    means, tops = [e.mean() for e in errors], [e.max() for e in errors]
    assert means[0] / means[1] > 3.5 and means[1] / means[2] > 3.5, means
    assert tops[0] / tops[1] > 1.9 and tops[1] / tops[2] > 1.9, tops


# --- the SH sphere --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("form", sorted(sh.FORMS))
def test_the_sh_sphere_of_a_linear_environment_is_its_closed_form(form):
    """L = a + b.ω: L_0 = 2 sqrt(pi) a, L_1m = sqrt(3 / (4 pi)) (4 pi / 3) b_(y, z, x); E / pi = a + (2/3) b.n
    (Ramamoorthi & Hanrahan 2001, Eq. 8), from the coefficients in every form."""
    a, b = np.array([0.5, 1.0, 2.0]), np.array([[0.2, -0.1, 0.3], [0.4, 0.0, -0.2], [-0.3, 0.6, 0.1]])  # b[c] = b.xyz
    radiance = np.zeros((9, 3))
    radiance[0] = 2 * math.sqrt(math.pi) * a
    radiance[1:4] = math.sqrt(3 / (4 * math.pi)) * 4 * math.pi / 3 * b[:, [1, 2, 0]].T
    view = render.sphere_view(17, render.camera_direction(1.0, -0.4))
    got = render.sh_irradiance_over_pi(sh.convolve(radiance, form), form, view.n)
    np.testing.assert_allclose(got, a + 2 / 3 * view.n @ b.T, rtol=0, atol=EXACT)


# --- the cube preview -----------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def cubes(tmp_path_factory):
    """The sunrise's specular cube (8^2, 4 mips) and irradiance cube (4^2, SH radiance), as CubeTables and files."""
    out = tmp_path_factory.mktemp("cubes")
    tables = {}
    for kind, size in (("environment_specular", 8), ("environment_irradiance", 4)):
        raw = {"name": kind[12:], "kind": kind, "environment": str(SUNRISE), "size": size, "estimator": "quadrature"}
        tables[kind] = bake_cube_table(validate_table(raw, "<test>", 0))[0]
    return tables, out


def test_the_cross_puts_each_face_where_its_edges_meet_its_neighbours():
    faces = np.arange(6, dtype=float)[:, None, None, None] * np.ones((6, 2, 2, 1))
    img = preview_cube.cross_image(faces, background=-1)
    blocks = img[::2, ::2, 0]
    np.testing.assert_array_equal(blocks, [[-1, 2, -1, -1], [1, 4, 0, 5], [-1, 3, -1, -1]])
    # the shared edges meet: +Z's right column and +X's left column are the same directions, and so on
    n = 6
    centres = cube.texel_centres(n)
    cross = preview_cube.cross_image(centres)
    for row in (n, 2 * n - 1):
        for col in (n, 2 * n, 3 * n):  # -X|+Z, +Z|+X, +X|-Z
            assert np.linalg.norm(cross[row, col - 1] - cross[row, col]) < 2.5 / n
    assert np.linalg.norm(cross[n - 1, n + 2] - cross[n, n + 2]) < 2.5 / n  # +Y over +Z
    assert np.linalg.norm(cross[2 * n - 1, n + 2] - cross[2 * n, n + 2]) < 2.5 / n  # +Z over -Y


@pytest.mark.parametrize("fmt", ["ktx2", "dds", "exr"])
def test_a_cube_file_reads_back_as_written(cubes, fmt):
    tables, out = cubes
    for kind, table in tables.items():
        back = preview_cube.read_cube_file(write_cube_table(table, out / f"{kind}.{fmt}", fmt))
        assert (back.kind, back.name, back.record["roughness" if "specular" in kind else "sh"]) == (
            kind,
            table.name,
            table.record["roughness" if "specular" in kind else "sh"],
        )
        for got, want in zip(back.mips, table.mips, strict=True):
            np.testing.assert_allclose(got, want, rtol=1e-3, atol=1e-4)  # half floats


@pytest.mark.parametrize(
    "kind, fmt, shape", [("environment_specular", "ktx2", (640, 960)), ("environment_irradiance", "exr", (380, 1280))]
)
def test_the_preview_of_a_cube_file_has_its_size_and_is_not_blank(cubes, kind, fmt, shape):
    """Specular: 4 mips in 3 columns (2 rows); irradiance: its cross and three spheres; 100 dpi."""
    import matplotlib.image

    tables, out = cubes
    path = write_cube_table(tables[kind], out / f"{kind}.{fmt}", fmt)
    png = out / f"{kind}_{fmt}.png"
    r = CliRunner().invoke(main, ["preview", str(path), "-o", str(png)])
    assert r.exit_code == 0 and r.output.strip() == str(png), r.output
    pixels = matplotlib.image.imread(png)
    assert pixels.shape[:2] == shape
    assert pixels[..., :3].std() > 0.1  # faces, spheres and text, not one colour


@pytest.mark.parametrize("name", ["bevy_pisa_diffuse_rgb9e5_zstd.ktx2", "filament_pillars_2k_ibl_mips1-4.ktx"])
def test_the_preview_of_an_engines_cube_draws_its_mips(name, tmp_path):
    """Bevy's RGB9E5 irradiance cube (1 mip) and cmgen's KTX 1.1 mips 1-4: no lutbake record, crosses only."""
    import matplotlib.image

    png = tmp_path / "e.png"
    r = CliRunner().invoke(main, ["preview", str(SUNRISE.parent / name), "-o", str(png)])
    assert r.exit_code == 0, r.output
    rows, cols = (1, 1) if "bevy" in name else (2, 3)
    assert matplotlib.image.imread(png).shape[:2] == (round((2.6 * rows + 1.2) * 100), round(3.2 * cols * 100))


def test_the_preview_of_a_cube_table_from_python(cubes, tmp_path):
    import matplotlib.image

    tables, _ = cubes
    png = preview_cube.render_cube(tables["environment_irradiance"], tmp_path / "irr.png")
    assert matplotlib.image.imread(png).shape[:2] == (380, 1280)
    with pytest.raises(ValueError, match="needs out"):
        preview_cube.render_cube(tables["environment_irradiance"], None)


# --- the spheres ----------------------------------------------------------------------------------------------------


def test_the_spheres_command_writes_the_pictures_and_arrays(tmp_path):
    out = tmp_path / "s.png"
    args = ["spheres", str(SUNRISE), "-o", str(out), "--size", "8", "--height", "8", "--cube-size", "4"]
    r = CliRunner().invoke(main, args + ["--estimator", "quadrature"])
    assert r.exit_code == 0, r.output
    lines = r.output.splitlines()
    assert lines[0].split() == ["material", "r", "max", "RMS", "mean", "truth", "±"] and len(lines) == 1 + 12 + 3 + 3
    arrays = np.load(out.with_suffix(".npz"))
    assert arrays["truth"].shape == arrays["split_sum"].shape == (2, 6, 8, 8, 3)
    assert arrays["split_sum_error_max_rms_mean"].shape == (2, 6, 3) and np.all(arrays["truth_error"] < 1e-3)
    assert arrays["diffuse_truth"].shape == (3, 8, 8, 3)
    assert out.with_name("s_diffuse.png").is_file()
    bad = CliRunner().invoke(main, ["spheres", str(tmp_path / "none.exr"), "-o", str(tmp_path / "x.png")])
    assert bad.exit_code == 2 and "none.exr" in bad.output


def test_the_spheres_of_baked_cube_tables_in_either_orientation_are_those_of_the_bake_here(cubes):
    """spheres.lighting_of reads a CubeTable's curve and orientation from its record: the kinds' gl and
    d3d_left_handed cubes of the sunrise give the split sum spheres.lighting bakes here (the same prefilter)."""
    from lutbake.io.environment import read_latlong

    tables, _ = cubes
    image = read_latlong(SUNRISE).image
    here = spheres.lighting(image, cube_size=8, irradiance_size=4, method="quadrature")
    d3d = {}
    for kind, size in (("environment_specular", 8), ("environment_irradiance", 4)):
        raw = {"name": "d", "kind": kind, "environment": str(SUNRISE), "size": size, "estimator": "quadrature"}
        d3d[kind] = bake_cube_table(validate_table(raw | {"orientation": "d3d_left_handed"}, "<test>", 0))[0]
    want = spheres.render_spheres(here, size=6, roughness=(0.5,), probe_stride=1000)
    for cubes_of in (tables, d3d):
        light = spheres.lighting_of(image, cubes_of["environment_specular"], cubes_of["environment_irradiance"])
        got = spheres.render_spheres(light, size=6, roughness=(0.5,), probe_stride=1000)
        np.testing.assert_allclose(got.split, want.split, rtol=1e-9)
        np.testing.assert_array_equal(got.truth, want.truth)
