"""Kind ltc (Heitz et al. 2016 LTC fits): the metric against a straight port of ltc_code, the published GGX
table, the magnitude = albedo identity, the sphere table's closed form, independence of tiling, the Lambert
identity, polygon integrals and the area-light ground truth."""

from __future__ import annotations

import gzip
import re
from pathlib import Path

import ltc_port
import numpy as np
import pytest

from lutbake import api
from lutbake.config import load_configs
from lutbake.kinds.ltc import axes_for
from lutbake.ltc import fit, polygon, sphere
from lutbake.ltc.magnitude import magnitude_alpha, magnitude_fresnel, texel_params
from lutbake.validate import ltc_area

DATA = Path(__file__).parent / "data"
N = 64
METRIC_RTOL = 1e-6  # Warp kernel (float32 lobe terms) vs the float64 numpy port of computeError
MAGNITUDE_ATOL = 1e-6  # the bound: magnitude channel = albedo table
SPHERE_ATOL = 1e-7  # integrated sphere table vs Snyder's closed form
PUBLISHED_SPHERE_ATOL = 2e-5  # vs ltc_code's float32 closed form printed with 6 digits
NO_WORSE_FRACTION = 0.95  # the issue: no worse than the published table at >= 95 % of texels
AREA_REL_MEDIAN = (
    0.05  # GGX area lights: median relative error of magnitude x polygon integral (measured 0.022; ltc_code 0.020)
)
AREA_VS_PUBLISHED = 1.1  # ... and no more than 10 % above the published table's on the same texels and lights
LAMBERT_ATOL = 1e-6
# the metric's grid side (fit_samples) where a test's property does not depend on it (the Lambert identity, the
# free-frame gain, the small tables' layouts): 16 x 16, a quarter of the presets' 32 x 32 evaluations
CHEAP_GRID = 16


def published() -> tuple[np.ndarray, np.ndarray]:
    """ltc_code's g_ltc_1, g_ltc_2 as (64, 64, 4) arrays, row = view index t, column = roughness index a."""
    text = gzip.decompress((DATA / "ltc_code_ltc.js.gz").read_bytes()).decode()
    a, b = text.split("var g_ltc_2")
    num = re.compile(r"-?[0-9.]+(?:e[-+]?[0-9]+)?")
    t1 = np.array([float(x) for x in num.findall(a.split("[", 1)[1])]).reshape(N, N, 4)
    t2 = np.array([float(x) for x in num.findall(b.split("[", 1)[1])]).reshape(N, N, 4)
    return t1, t2


@pytest.fixture(scope="module")
def ggx():
    axes = axes_for({"lobe": "ggx", "size": [N, N]})
    nov, alpha = texel_params(axes)
    mag, _ = magnitude_fresnel("ggx", nov, alpha, None)
    return fit.Problem("ggx", nov, alpha, mag)


@pytest.fixture(scope="module")
def coarse(ggx):
    return fit.coarse_pass(ggx, N, N)


def test_heitz_metric_equals_a_straight_port_of_computeError(ggx):
    rng = np.random.default_rng(3)
    texels = rng.choice(N * N, 12, replace=False)
    q = np.stack(
        [np.log(rng.uniform(0.05, 1.0, 12)), np.log(rng.uniform(0.05, 1.0, 12)), rng.uniform(-0.3, 0.3, 12)], 1
    )
    m = ggx.matrices(texels, q)
    ours = ggx.error(texels, m)
    for k, t in enumerate(texels):
        v = ggx.v[t].astype(np.float64)
        ref = ltc_port.compute_error(m[k], ggx.magnitude[t], v, float(ggx.alpha[t]))
        np.testing.assert_allclose(ours[k], ref, rtol=METRIC_RTOL * 100)


SPARSE = np.arange(0, N * N, 13)  # the GGX texels fitted against the published table


@pytest.fixture(scope="module")
def sparse_fit(ggx, coarse):
    return fit.fit_texels(ggx, SPARSE, N, coarse)


def test_ggx_fit_no_worse_than_published_ltc_code(ggx, sparse_fit):
    t1, _ = published()
    texels = SPARSE
    m, err = sparse_fit
    err_pub = fit.heitz_error_of_packed(ggx, texels, t1.reshape(-1, 4)[texels])
    no_worse = np.mean(err <= err_pub)
    assert no_worse >= NO_WORSE_FRACTION, f"no worse at {no_worse:.3f} of texels"
    assert np.median(ggx.relative(texels, err)) < np.median(ggx.relative(texels, err_pub))


def test_fit_is_independent_of_how_texels_are_grouped(ggx, coarse, sparse_fit):
    """The first 60 of the 316 texels test_ggx_fit_no_worse_than_published_ltc_code fits at once, fitted as groups of
    17 and 43: the same bits."""
    texels = SPARSE[:60]
    m_all, e_all = (x[:60] for x in sparse_fit)
    m_a, e_a = fit.fit_texels(ggx, texels[:17], N, coarse)
    m_b, e_b = fit.fit_texels(ggx, texels[17:], N, coarse)
    np.testing.assert_array_equal(np.concatenate([m_a, m_b]), m_all)
    np.testing.assert_array_equal(np.concatenate([e_a, e_b]), e_all)


def test_pack_unpack_round_trip_and_published_layout():
    rng = np.random.default_rng(0)
    m = np.zeros((5, 3, 3))
    m[:, 0, 0], m[:, 1, 1], m[:, 2, 2] = rng.uniform(0.1, 1, 5), rng.uniform(0.1, 1, 5), 1.0
    m[:, 0, 2], m[:, 2, 0] = rng.uniform(-0.5, 0.5, 5), rng.uniform(-0.5, 0.5, 5)
    inv = np.linalg.inv(m)
    np.testing.assert_allclose(fit.unpack_inverse(fit.pack_inverse(m)), inv / inv[:, 1:2, 1:2], rtol=1e-12)
    # the published first row (t = 0, normal incidence) is diagonal: (m22 / m11 = 1, 0, 0, m22)
    t1, _ = published()
    np.testing.assert_array_equal(t1[0, :, 1:3], 0.0)
    np.testing.assert_array_equal(t1[0, :, 0], 1.0)


SMALL = 8


@pytest.fixture(scope="module")
def small_ltc(tmp_path_factory):
    over = [f"size=[{SMALL},{SMALL}]", f"fit_samples={CHEAP_GRID}", 'format="exr"']
    spec = load_configs([Path("lutbake/presets/ltc-ggx.toml")], over)
    return api.bake(spec, out_dir=tmp_path_factory.mktemp("ltc"), workers=2)[0].table


@pytest.mark.parametrize("fit_keys", [['fit="l3"'], ['fit="shaded"', 'magnitude="albedo"']])
def test_ltc_bake_magnitude_equals_albedo_table(fit_keys, tmp_path):
    """The magnitude channel is the albedo table with the L3 fit, and with the shaded fit told to keep it (the
    default shaded fit fits the magnitude with the matrix: tests/test_ltc_shaded.py)."""
    size = SMALL
    over = [f"size=[{SMALL},{SMALL}]", f"fit_samples={CHEAP_GRID}", 'format="exr"', *fit_keys]
    spec = load_configs([Path("lutbake/presets/ltc-ggx.toml")], over)
    ltc = api.bake(spec, out_dir=tmp_path, workers=2, write=False)[0].table
    cfg = tmp_path / "albedo.toml"
    cfg.write_text(
        '[[table]]\nname = "e"\nkind = "albedo"\n'
        f'size = [{size}, {size}]\ntexel = "endpoint"\naxis_order = "roughness_x"\n'
        f'nov_mapping = "one_minus_t2"\nnov_clamp = [{float(np.cos(np.float32(1.57)))!r}, 1.0]\n'
    )
    alb = api.bake([cfg], out_dir=tmp_path, workers=1, write=False)[0].table
    assert [a.name for a in alb.axes] == ["NoV", "perceptual_roughness"]
    np.testing.assert_array_equal(alb.axes[0].values(), ltc.axes[1].values())
    np.testing.assert_allclose(ltc.data[1, ..., 0], alb.data[..., 0], atol=MAGNITUDE_ATOL, rtol=0)
    assert float(ltc.attributes["fit_error_max"]) >= float(ltc.attributes["fit_error_median"]) > 0
    assert np.all(np.isfinite(ltc.data))


def test_sphere_table_integration_matches_snyder_closed_form():
    rng = np.random.default_rng(7)
    for omega, sigma in zip(rng.uniform(0, np.pi, 300), rng.uniform(1e-3, np.pi / 2, 300)):
        np.testing.assert_allclose(
            sphere.cap_projected_solid_angle(omega, sigma),
            sphere.snyder_cap(omega, sigma),
            atol=SPHERE_ATOL * np.pi * np.sin(sigma) ** 2,
        )


def test_sphere_table_matches_published_channel():
    _, t2 = published()
    np.testing.assert_allclose(sphere.sphere_table(N), t2[..., 3], atol=PUBLISHED_SPHERE_ATOL)


def test_lambert_fit_is_the_identity():
    axes = axes_for({"lobe": "lambert", "size": [8, 8]})
    nov, alpha = texel_params(axes)
    p = fit.Problem("lambert", nov, alpha, np.ones(len(nov)), CHEAP_GRID)
    texels = np.arange(len(nov))
    m, err = fit.fit_texels(p, texels, 8, fit.coarse_pass(p, 8, 8))
    packed = fit.pack_inverse(m)
    np.testing.assert_allclose(packed, np.tile([1.0, 0.0, 0.0, 1.0], (len(nov), 1)), atol=1e-3)
    assert np.max(p.relative(texels, err)) < LAMBERT_ATOL * 1e3


def test_form_factor_of_polygons_against_cosine_sampling():
    # one cosine-distributed sample per cell of a 256^2 grid (largest error 1.3e-4; 400k random samples: ~8e-4 sd)
    u1, u2 = fit.stratified_grid(256).astype(np.float64).T
    l = np.stack([np.sqrt(1 - u1) * np.cos(2 * np.pi * u2), np.sqrt(1 - u1) * np.sin(2 * np.pi * u2), np.sqrt(u1)], 1)
    for _, poly in ltc_area.light_set():
        mc = np.mean(ltc_area.hits(l, poly))
        np.testing.assert_allclose(abs(polygon.form_factor(poly)), mc, atol=4e-3)
        np.testing.assert_allclose(polygon.form_factor(poly, polygon.edge_fitted), polygon.form_factor(poly), atol=1e-3)


def test_clip_horizon_keeps_the_upper_part():
    quad = np.array([[-1, -1, -1.0], [1, -1, -1.0], [1, 1, 1.0], [-1, 1, 1.0]])
    c = polygon.clip_horizon(quad)
    assert len(c) == 4 and np.all(c[:, 2] >= 0)
    assert len(polygon.clip_horizon(quad - [0, 0, 5])) == 0


def test_area_lights_ggx_against_brute_force(ggx, coarse):
    """magnitude x polygon integral vs the brute-force integral of f (n.l) over 12 quad / triangle lights (several
    crossing the horizon) at 9 texels: lutbake's fit is as good as ltc_code's published one (whose errors here,
    like ours, come from what one clamped cosine cannot represent: bench_ltc.py reports the full distribution)."""
    texels = [(t, a) for t in (0, 24, 48) for a in (16, 40, 63)]
    idx = np.array([t * N + a for t, a in texels])
    m, _ = fit.fit_texels(ggx, idx, N, coarse)
    t1p, _ = published()
    ours, pub = np.zeros((N, N, 4)), np.zeros((N, N, 4))
    t2 = np.zeros((N, N, 4))
    for k, (t, a) in enumerate(texels):
        ours[t, a] = fit.pack_inverse(m[k : k + 1])[0]
        pub[t, a] = t1p[t, a]
        t2[t, a, 0] = ggx.magnitude[t * N + a]  # the same magnitude for both: the comparison is of the fits
    axes = axes_for({"lobe": "ggx", "size": [N, N]})
    medians, references = {}, {}
    for name, t1 in (("lutbake", ours), ("ltc_code", pub)):
        rows = ltc_area.compare("ggx", t1, t2, axes[1].values(), axes[2].alpha(), texels, s=256, references=references)
        rel = np.array([r["rel_error"] for r in rows if r["rel_error"] is not None])
        assert len(rel) > len(rows) // 2
        medians[name] = np.median(rel)
    print("area-light median relative error", medians)
    assert medians["lutbake"] < AREA_REL_MEDIAN, medians
    assert medians["lutbake"] <= AREA_VS_PUBLISHED * medians["ltc_code"], medians


# Unity-Technologies/Graphics, Packages/com.unity.render-pipelines.high-definition/Runtime/Material/LTCAreaLight/
# Generated/LtcData.BRDF_GGX.cs @ 77535410d2c8ed6c459db07f854b8c572ed08f9a (Unity Companion License): FP16 bits of
# row thetaIndex = 1 (cos theta = 0.9997481) at roughnessIndex 20, 40 and row 2 at 20, 40 (HDRP's own fit).
HDRP_GGX_ROWS = {
    (1, 20): (17652, 42421, 17652, 12061),
    (1, 40): (15758, 42013, 15759, 10013),
    (2, 20): (17652, 43446, 17654, 13086),
    (2, 40): (15757, 43048, 15759, 11041),
}
HDRP_RTOL = 2e-3  # HDRP's fit vs ltc_code's at smooth texels, FP16: measured 9.5e-4 (a wrong order, sign or scale: > 1)


def test_hdrp_packing_matches_hdrp_shipped_ggx_texels():
    from lutbake.io.ltc import hdrp_pack

    t1, _ = published()
    for (t, a), bits in HDRP_GGX_ROWS.items():
        hdrp = np.array(bits, np.uint16).view(np.float16).astype(np.float64)
        ours = hdrp_pack(t1[t, a])
        np.testing.assert_allclose(ours, hdrp, rtol=HDRP_RTOL, err_msg=f"texel (t={t}, a={a})")
    # both packings describe the same M^-1 up to scale
    x = hdrp_pack(t1[5, 30])
    inv_h = np.array([[x[0], 0, x[3]], [0, x[2], 0], [x[1], 0, 1.0]])
    inv_l = polygon.inverse_matrix(t1[5, 30])
    np.testing.assert_allclose(inv_h / inv_h[1, 1], inv_l, rtol=1e-12)


def test_engine_layouts_hold_the_table(small_ltc, tmp_path):
    from test_formats import read_dds_spec

    from lutbake.io.formats import write_table
    from lutbake.io.ltc import FP16_MAX, hdrp_fp16, hdrp_pack

    t1 = small_ltc.data[0].astype(np.float32)
    t2 = small_ltc.data[1].astype(np.float32)
    p = write_table(small_ltc, tmp_path, "ltc_dds", "half")
    d1 = read_dds_spec(p.read_bytes())[0]
    d2 = read_dds_spec((tmp_path / "ltc_ggx_2.dds").read_bytes())[0]
    np.testing.assert_array_equal(d1, t1.astype(np.float16))
    np.testing.assert_array_equal(d2[..., [0, 1, 3]], t2[..., [0, 1, 3]].astype(np.float16))
    np.testing.assert_array_equal(d2[..., 2], 0)  # ltc_code's unused channel
    num = re.compile(r"-?[0-9.]+(?:e[-+]?[0-9]+)?")
    js = write_table(small_ltc, tmp_path, "js").read_text()
    m1 = js.split("LTC_MAT_1 = new Float32Array([")[1].split("])")[0]
    np.testing.assert_array_equal(np.array(num.findall(m1), np.float32).reshape(SMALL, SMALL, 4), t1)
    c = write_table(small_ltc, tmp_path, "c").read_text()
    mag = c.split("ltc_mag_ggx[8][8][2] = {")[1].split("};")[0]
    np.testing.assert_array_equal(
        np.array([float(x) for x in num.findall(mag)], np.float32).reshape(8, 8, 2), t2[..., :2]
    )
    spec = load_configs(
        [Path("lutbake/presets/ltc-hdrp.toml")], [f"size=[{SMALL},{SMALL}]", f"fit_samples={CHEAP_GRID}"]
    )[0]
    hdrp = api.bake([spec], out_dir=tmp_path, workers=2, write=False)[0].table
    t1 = hdrp.data[0].astype(np.float32)
    cs = write_table(hdrp, tmp_path, "cs").read_text()
    body = cs.split("new ushort[8 * 8 * 4]")[1]
    bits = np.array([int(x) for x in re.findall(r"^\s+([0-9, ]+),$", body, re.M) for x in x.split(",")], np.uint16)
    np.testing.assert_array_equal(bits.reshape(8, 8, 4), hdrp_fp16(t1).view(np.uint16))
    finite = np.abs(hdrp_pack(t1)) <= FP16_MAX
    assert finite.mean() > 0.9  # only smooth grazing texels saturate (HDRP's shipped table saturates there too)
    np.testing.assert_allclose(hdrp_fp16(t1)[finite].astype(np.float64), hdrp_pack(t1)[finite], rtol=1e-3)


def test_ltc_presets_load_with_their_engine_layouts():
    from lutbake.config import preset_path
    from lutbake.io.formats import output_path

    want = {
        "ltc-ggx": ("ltc_dds", "ltc_ggx_1.dds"),
        "ltc-threejs": ("js", "ltc_threejs.js"),
        "ltc-eevee": ("c", "ltc_eevee.cc"),
        "ltc-hdrp": ("cs", "LtcData_BRDF_GGX.cs"),
        "ltc-babylon": ("babylon_ltc", "areaLightsLTC.bin"),
    }
    for preset, (fmt, file) in want.items():
        (spec,) = load_configs([preset_path(preset)])
        assert spec.kind == "ltc" and spec.options["lobe"] == "ggx" and spec.options["size"] == (64, 64)
        assert spec.options["format"] == fmt
        assert output_path("out", spec.name, fmt).name == file
    (hdrp,) = load_configs([preset_path("ltc-hdrp")])
    assert hdrp.options["alpha_min"] == 1e-3


@pytest.mark.parametrize("fmt", ["exr", "c", "js"])
def test_inspect_shows_the_fit_error_and_the_engine_layouts_hold_the_exr_values(small_ltc, tmp_path, fmt):
    """issue 14: the fit error's max / median in `lutbake inspect`, for the EXR and the engine layouts alike (whose
    values read back as the EXR's, ltc_2.z = 0: lutbake.io.engine_files)."""
    from lutbake.io.describe import describe
    from lutbake.io.formats import write_table
    from lutbake.io.readers import read_table

    path = write_table(small_ltc, tmp_path, fmt, "float32")
    text = describe(path)
    for key in ("fit_error_max", "fit_error_median"):
        assert f"  {key}: {small_ltc.attributes[key]}\n" in text, text
    expected = np.array(small_ltc.data, np.float32)
    if fmt != "exr":
        expected[1, ..., 2] = 0.0
    np.testing.assert_array_equal(read_table(path).data, expected)


CHARLIE_GAIN = 0.7  # free-frame fit: median relative L3 at most 0.7x the 3-parameter one (measured 0.54x on 64^2;
# 0.53x on this 8^2 table with the 32^2 metric grid, 0.52x with CHEAP_GRID's)


def test_charlie_free_frame_fit_beats_ltc_codes_three_parameters():
    """Charlie's 4-parameter fit (frame angle free) against ltc_code's 3 parameters (frame at the lobe's average
    direction), same texels, same seeding: no worse anywhere (up to the optimiser's tolerance), and much better at
    oblique views, where the sheen lobe's peak sits away from its average direction."""
    n = 8
    axes = axes_for({"lobe": "charlie", "size": [n, n]})
    nov, alpha = texel_params(axes)
    mag, _ = magnitude_fresnel("charlie", nov, magnitude_alpha(axes), None)
    texels = np.arange(n, n * n)  # every view but normal incidence (isotropic: both parametrisations coincide)
    rel = {}
    for dof in (4, 3):
        p = fit.Problem("charlie", nov, alpha, mag, CHEAP_GRID)
        assert p.dof == 4
        p.dof = dof
        _, err = fit.fit_texels(p, texels, n, fit.coarse_pass(p, n, n))
        rel[dof] = p.relative(texels, err)
    assert np.all(rel[4] <= rel[3] * (1 + 1e-3) + 1e-6), np.max(rel[4] - rel[3])
    assert np.median(rel[4]) < CHARLIE_GAIN * np.median(rel[3]), (np.median(rel[4]), np.median(rel[3]))


def test_hdrp_shares_the_ggx_texels_it_would_fit_alike_and_gets_the_same_bits():
    """The fit memo (lutbake.ltc.fit.MEMO): ltc-hdrp (alpha_min 1e-3) baked after ltc-ggx takes ltc-ggx's fits
    where a texel's inputs and seeds are equal, and its table is bit for bit the one it bakes alone (any workers).
    Its coarse pass fits the lobe's own alpha (LtcBake.unclamped_nodes): every seed is ltc-ggx's, so only the
    clamped column is fitted again."""
    n = 12  # coarse nodes 0, 2, 3, ...: alpha = (i / 11)^2 < 1e-3 at column 0 only
    over = [f"size=[{n},{n}]", "fit_samples=8", 'format="exr"', 'dtype="float32"']
    (ggx,) = load_configs([Path("lutbake/presets/ltc-ggx.toml")], over)
    (hdrp,) = load_configs([Path("lutbake/presets/ltc-hdrp.toml")], over)
    fit.MEMO.clear()
    alone = api.bake_table(hdrp, workers=1)[0].data
    fit.MEMO.clear()
    api.bake_table(ggx, workers=2)
    hits, misses = fit.MEMO.hits, fit.MEMO.misses
    shared = api.bake_table(hdrp, workers=2)[0].data
    # shared by candidates: columns >= 1 and every coarse node; fitted at most: column 0 (each texel a candidates
    # entry and, where its start is new, a start entry)
    assert fit.MEMO.hits - hits >= n * n - n + 8 * 8
    assert fit.MEMO.misses - misses <= 2 * n
    np.testing.assert_array_equal(shared, alone)
    assert not np.array_equal(shared[0, :, :2], api.bake_table(ggx, workers=1)[0].data[0, :, :2])


def test_fit_memo_waits_for_another_thread_and_refits_what_a_failed_one_released():
    import threading

    from lutbake.runtime.memo import RowMemo

    memo = RowMemo()
    started, go, calls = threading.Event(), threading.Event(), []

    def slow(i):
        calls.append(("slow", list(i)))
        started.set()
        go.wait()
        return np.stack([np.full(2, float(k)) for k in i]), np.asarray(i, float)

    worker = threading.Thread(target=memo.run, args=([b"a", b"b"], slow))
    worker.start()
    started.wait()
    result = {}
    waiter = threading.Thread(target=lambda: result.setdefault("r", memo.run([b"b", b"c"], slow)))
    waiter.start()  # claims c (computes it once go is set), waits for b
    go.set()
    worker.join()
    waiter.join()
    q, f = result["r"]
    np.testing.assert_array_equal(f, [1.0, 1.0])  # b from the first thread (its index 1), c computed as index 1
    assert sorted(c for _, c in calls) == [[0, 1], [1]] and memo.hits == 1 and memo.misses == 3

    def fail(i):
        raise RuntimeError("cancelled")

    with pytest.raises(RuntimeError):
        memo.run([b"d"], fail)
    q, f = memo.run([b"d"], lambda i: (np.zeros((1, 2)), np.array([7.0])))
    assert f[0] == 7.0 and memo.misses == 4


def test_memo_computes_a_key_repeated_in_one_call_once():
    """A key twice in one run (two texels of equal inputs: ltc-hdrp's clamped columns) is claimed and computed once,
    its repeat taken from it (a hit)."""
    from lutbake.runtime.memo import RowMemo

    memo, calls = RowMemo(), []

    def compute(i):
        calls.append(list(i))
        return (np.asarray(i, float)[:, None],)

    (rows,) = memo.run([b"a", b"b", b"a"], compute)
    assert calls == [[0, 1]] and rows[:, 0].tolist() == [0.0, 1.0, 0.0]
    assert memo.misses == 2 and memo.hits == 1


def test_every_file_of_an_ltc_dds_pair_carries_its_conventions(small_ltc, tmp_path):
    """Issue 39: `lutbake inspect ltc_ggx_2.dds` said "no lutbake metadata"; the pair's sidecar lists both files."""
    from lutbake.io.describe import describe
    from lutbake.io.formats import write_table, written_files
    from lutbake.io.readers import read_table

    write_table(small_ltc, tmp_path, "ltc_dds", "half")
    files = written_files(small_ltc.name, "ltc_dds")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(files)
    for name in (n for n in files if not n.endswith(".json")):
        text = describe(tmp_path / name)
        assert "no lutbake metadata" not in text and "ltc" in text, (name, text)
        view = read_table(tmp_path / name)
        assert view.kind == "ltc"
        np.testing.assert_array_equal(
            view.data[1][..., [0, 1, 3]], small_ltc.data[1][..., [0, 1, 3]].astype(np.float16)
        )
