"""lutbake audit: finds, on its own, the known defects of shipped tables and of broken copies of a lutbake table.

Shipped tables (tests/data, provenance in the .json beside each): Filament cmgen's DFG (one-texel roughness
offset, 1024 Hammersley samples, half floats) and the glTF Sample Viewer's lut_ggx (8-bit, 1024 samples).
Broken copies of a lutbake table are built here: sRGB-decoded, rows flipped, half-texel shifted.
"""

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake.cli import main
from lutbake.commands.audit import audit
from lutbake.integrands.specular import hemisphere_integral

DATA = Path(__file__).parent / "data"
N = 32  # side of the lutbake tables the broken copies are made of
MAX_SIDE = 32  # audit subset in these tests (speed)
# the filament audits' subset of the 128² tables (17 x 17 texels, first and last rows and columns included): the
# findings are those at MAX_SIDE (offset / nominal RMS 0.044 vs 0.042 at 32, estimated samples 1025 at both)
FILAMENT_SIDE = 16
CLEAN_TOL = 1e-5  # a lutbake table re-audited under its own conventions: GL 432 vs GL 432 at the same points
FILAMENT_SAMPLES = 1024  # cmgen's DFG sample count (filament_dfg.json)
GLTF_SAMPLES = 1024  # glTF IBL sampler's lut_ggx sample count (khronos_lut_ggx_u8.json)
SAMPLES_FACTOR = 2.0  # the estimated sample count must lie within this factor of the generator's


def dfg_at(r_rows: np.ndarray, nov_cols: np.ndarray) -> np.ndarray:
    """scale/bias at perceptual roughness r (rows) x NoV (columns): lutbake's integrand at points built here."""
    nov, r = np.meshgrid(nov_cols, r_rows)
    out = hemisphere_integral("ggx", "smith_height_correlated", "scale_bias", nov.ravel(), r.ravel() ** 2)
    return out.reshape(len(r_rows), len(nov_cols), 2)


@pytest.fixture(scope="module")
def clean():
    c = (np.arange(N) + 0.5) / N
    return dfg_at(c, c)


def srgb_decode(v):
    """IEC 61966-2-1 EOTF, written out here independently of lutbake.commands.audit."""
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def run(path, max_side=MAX_SIDE, **kw):
    return audit(path, {"preset": kw.pop("preset", "default")}, max_side=max_side, **kw)


def test_filament_shipped_table_one_texel_roughness_offset_found():
    r = run(DATA / "filament_dfg.npz", preset="filament-corrected", max_side=FILAMENT_SIDE)
    assert r.extra["chosen"] == "roughness_offset_+1"
    assert "convention mismatch" in r.diagnosis[0]
    assert r.quantisation["kind"] == "half"
    assert FILAMENT_SAMPLES / SAMPLES_FACTOR <= r.noise["samples"] <= FILAMENT_SAMPLES * SAMPLES_FACTOR
    assert not r.passed


def test_filament_preset_conventions_fit_the_shipped_table():
    r = run(DATA / "filament_dfg.npz", preset="filament", max_side=FILAMENT_SIDE)
    assert r.extra["chosen"] == "nominal"
    nominal = next(h for h in r.hypotheses if h["name"] == "nominal")
    others = [h["rms"] for h in r.hypotheses if h["name"] != "nominal"]
    assert nominal["rms"] < 0.1 * min(others)


# lutbake's own filament file: the conventions and texels of the filament audit above (its references reused)


@pytest.fixture(scope="module")
def own_filament(tmp_path_factory):
    """lutbake's own `filament` bake as `make luts` writes it (128 x 128 half RGBA16F DDS + sidecar; the cloth
    channel reaches ~18 at the smoothest row)."""
    from lutbake import api
    from lutbake.config import preset_path

    out = tmp_path_factory.mktemp("own")
    (r,) = api.bake([preset_path("filament")], out_dir=out)
    return r.path


def test_lutbakes_own_half_dds_passes_under_its_preset(own_filament):
    """`lutbake audit outputs/filament_dfg.dds --preset filament` failed: the cloth channel reaches 18, where half
    rounding alone is ~0.008 > the 1e-3 tolerance; the judged error is the one beyond a rounding step."""
    r = audit(own_filament, {"preset": "filament"}, max_side=FILAMENT_SIDE)
    assert r.passed and r.extra["chosen"] == "nominal", r.text()
    assert r.quantisation["kind"] == "half"
    assert r.extra["raw_error"]["max"] > 1e-3  # the raw |file - converged| is above the tolerance ...
    assert r.extra["raw_error"]["max"] <= r.extra["raw_error"]["step_at_max"]  # ... and within one half step


def test_lutbakes_own_file_is_audited_against_its_recorded_conventions(own_filament):
    """Without --preset, the file's sidecar conventions are used (not `default`, which gave 'layout mismatch')."""
    r = audit(own_filament, {}, max_side=FILAMENT_SIDE)
    assert r.passed and r.extra["chosen"] == "nominal", r.text()
    assert "recorded config" in r.conventions and "multiscatter_cloth" in r.conventions
    res = CliRunner().invoke(main, ["audit", str(own_filament), "--max-side", "16"])
    assert res.exit_code == 0 and "PASS" in res.output, res.output


def test_gltf_lut_ggx_8bit_quantisation_and_sample_noise_found():
    r = run(DATA / "khronos_lut_ggx_u8.npz", preset="gltf")
    assert r.extra["chosen"] == "nominal"
    assert r.quantisation["kind"] == "unorm8"
    np.testing.assert_allclose(r.quantisation["step"], 1 / 255)
    assert r.noise["detected"]
    assert r.noise["rms_residual"] > 1.5 * r.noise["rms_quantisation_alone"]
    assert GLTF_SAMPLES / SAMPLES_FACTOR <= r.noise["samples"] <= GLTF_SAMPLES * SAMPLES_FACTOR


def test_clean_lutbake_table_passes_and_shows_no_defect(clean, tmp_path):
    p = tmp_path / "clean.npy"
    np.save(p, clean.astype(np.float32))
    r = run(p, tolerance=CLEAN_TOL)
    assert r.passed and r.extra["chosen"] == "nominal"
    assert r.quantisation["kind"] == "float"
    assert not r.noise["detected"]


@pytest.mark.parametrize(
    "name, make, expected",
    [
        ("srgb", lambda t: srgb_decode(t), "srgb_decoded"),
        ("flipped", lambda t: t[::-1], "rows_flipped"),
        ("swapped", lambda t: t[..., ::-1], "channels_swapped"),
    ],
)
def test_broken_copy_is_diagnosed(clean, tmp_path, name, make, expected):
    p = tmp_path / f"{name}.npy"
    np.save(p, make(clean).astype(np.float32))
    r = run(p)
    assert r.extra["chosen"] == expected, r.text()
    assert not r.passed


def srgb_encode(v):
    """IEC 61966-2-1 OETF (the inverse of srgb_decode), written out here."""
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.maximum(v, 0) ** (1 / 2.4) - 0.055)


def test_two_stacked_mistakes_rows_flipped_and_srgb_encoded_are_both_named(clean, tmp_path):
    """Rows flipped *and* sRGB-encoded: each mistake alone explains little (rows_flipped RMS 0.148, srgb_encoded 0.206,
    declared 0.269), so a one-mistake audit called it 'the declared conventions fit ... Monte-Carlo noise'. The
    combination explains it exactly, and what is left is the storage rounding, not noise."""
    p = tmp_path / "flipped_srgb.npy"
    np.save(p, srgb_encode(clean[::-1]).astype(np.float32))
    r = run(p)
    assert r.extra["chosen"] == "rows_flipped+srgb_encoded", r.text()
    assert r.diagnosis[0].startswith("convention mismatch: rows flipped + sRGB-encoded"), r.diagnosis
    chosen = next(h for h in r.hypotheses if h["name"] == r.extra["chosen"])
    assert chosen["rms"] < CLEAN_TOL and chosen["mistakes"] == 2
    assert r.extra["explained"] == "rounding" and not r.noise["detected"]
    assert not any("Monte-Carlo" in d or "conventions fit" in d for d in r.diagnosis)


def test_a_smooth_perturbation_no_hypothesis_explains_is_said_so(clean, tmp_path):
    """A noise-free table plus a smooth random field (RMS ~5e-3): no combination explains it, and the residual is
    smooth where sampling noise of the same RMS is rough -- no noise, no sample count, no 'conventions fit'."""
    rng = np.random.default_rng(7)
    t = (np.arange(N) + 0.5) / N
    y, x = np.meshgrid(t, t, indexing="ij")
    field = sum(
        rng.normal() * np.cos(np.pi * kx * x + rng.uniform(0, 6)) * np.cos(np.pi * ky * y + rng.uniform(0, 6))
        for kx in range(3)
        for ky in range(3)
    )
    p = tmp_path / "perturbed.npy"
    np.save(p, (clean + 5e-3 * field[..., None] / field.std()).astype(np.float32))
    r = run(p)
    assert r.extra["explained"] == "smooth", r.text()
    assert r.diagnosis[0].startswith("no hypothesis explains the data: the best"), r.diagnosis
    assert not r.noise["detected"] and r.noise.get("samples") is None
    assert not any("Monte-Carlo" in d or "conventions fit" in d for d in r.diagnosis)


def _rgbd_codes(v):
    """Babylon's toRGBD written out here: D = floor(255 / max(rgb)) / 255 (at most 1), rgb = (v D)^(1/2.2), 8 bits."""
    rgb = np.concatenate([v, np.zeros(v.shape[:-1] + (3 - v.shape[-1],))], axis=-1)
    d = np.minimum(np.floor(255 / np.maximum(rgb.max(axis=-1, keepdims=True), 1e-9)), 255) / 255
    return np.round(np.concatenate([(rgb * d) ** (1 / 2.2), d], axis=-1) * 255).astype(np.uint8)


@pytest.mark.parametrize(
    "name, make, expected",
    [
        ("rgbd", _rgbd_codes, "rgbd"),
        ("half_bits", lambda t: t.astype(np.float16).view(np.uint16), "half_bits"),
        ("flipped_half_bits", lambda t: t[:, ::-1].astype(np.float16).view(np.uint16), "columns_flipped+half_bits"),
    ],
)
def test_a_storage_encoding_the_preset_does_not_declare_is_found(clean, tmp_path, name, make, expected):
    """Storage encodings are hypotheses: an RGBD-packed 8-bit RGBA array and half floats saved as 16-bit codes, read
    as plain UNORM under the default preset, are decoded by the hypothesis that names them."""
    p = tmp_path / f"{name}.npy"
    np.save(p, make(clean))
    r = run(p)
    assert r.extra["chosen"] == expected, r.text()


@pytest.mark.parametrize("shift", [-0.5, 0.5])
def test_half_texel_shifted_copy_is_diagnosed(tmp_path, shift):
    c = (np.arange(N) + 0.5) / N
    shifted = dfg_at(np.clip(c + shift / N, 0, 1), c)  # roughness rows hold r = (i + 0.5 + shift)/N
    p = tmp_path / "shifted.npy"
    np.save(p, shifted.astype(np.float32))
    r = run(p)
    assert r.extra["chosen"] == f"roughness_offset_{shift:+g}", r.text()


def test_audit_reads_png16_exr_ktx2_and_a_c_header(clean, tmp_path):
    from lutbake.axes import Axis
    from lutbake.io.formats import write_table
    from lutbake.table import Table

    axes = [Axis("perceptual_roughness", "y", N), Axis("NoV", "x", N)]
    table = Table("t", "dfg", clean.astype(np.float32), axes, {"scale": "", "bias": ""}, "")
    for fmt, tol in (("png16", 1 / 65535), ("exr", CLEAN_TOL), ("ktx2", 1e-3), ("h", 1e-3)):
        path = write_table(table, tmp_path, fmt, "half" if fmt in ("ktx2", "h") else "float32")
        r = run(path, tolerance=tol)
        assert r.passed and r.extra["chosen"] == "nominal", (fmt, r.text())


def test_audit_and_inspect_recognise_a_file_by_its_content_never_its_name(clean, tmp_path):
    """docs/formats.md: files are recognised by content. An npy saved as lut.bin and an EXR saved as lut.npy: inspect
    reads both, and audit reads them the same way (lutbake.io.readers.sniff) and passes them."""
    from lutbake.axes import Axis
    from lutbake.io.formats import write_table
    from lutbake.table import Table

    np.save(tmp_path / "t.npy", clean.astype(np.float32))
    axes = [Axis("perceptual_roughness", "y", N), Axis("NoV", "x", N)]
    exr = write_table(Table("t", "dfg", clean.astype(np.float32), axes, {"scale": "", "bias": ""}, ""), tmp_path, "exr")
    for src, name in ((tmp_path / "t.npy", "lut.bin"), (exr, "lut.npy")):
        (tmp_path / name).write_bytes(Path(src).read_bytes())
        for args in (["inspect", name], ["audit", name, "--max-side", "16", "--tolerance", "1e-5"]):
            res = CliRunner().invoke(main, [args[0], str(tmp_path / args[1]), *args[2:]])
            assert res.exit_code == 0, (args, res.output)
        assert "PASS" in res.output


def test_cli_json_exit_codes_and_error_map(clean, tmp_path):
    p = tmp_path / "flipped.npy"
    np.save(p, clean[::-1].astype(np.float32))
    png = tmp_path / "err.png"
    res = CliRunner().invoke(main, ["audit", str(p), "--json", "--max-side", "16", "--error-map", str(png)])
    assert res.exit_code == 1, res.output
    doc = json.loads(res.output)
    assert doc["extra"]["chosen"] == "rows_flipped" and not doc["passed"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    q = tmp_path / "clean.npy"
    np.save(q, clean.astype(np.float32))
    res = CliRunner().invoke(main, ["audit", str(q), "--max-side", "16", "--tolerance", "1e-5"])
    assert res.exit_code == 0, res.output
    assert "PASS" in res.output
    res = CliRunner().invoke(main, ["audit", str(q), "--preset", "no-such-engine"])
    assert res.exit_code == 2 and "no-such-engine" in res.output


def test_threejs_shipped_js_array_fits_the_threejs_preset():
    r = run(DATA / "threejs_dfg_lut.js", preset="threejs", shape=(16, 16, 2))
    assert r.extra["chosen"] == "nominal" and r.quantisation["kind"] == "half"
    nominal = next(h for h in r.hypotheses if h["name"] == "nominal")
    assert nominal["rms"] < 0.1 * min(h["rms"] for h in r.hypotheses if h["name"] != "nominal")


def test_threejs_shipped_table_is_height_correlated_not_separable():
    hc = run(DATA / "threejs_dfg_lut.js", preset="threejs", shape=(16, 16, 2))
    sep = audit(
        DATA / "threejs_dfg_lut.js",
        {"preset": "threejs", "overrides": ["masking=smith_separable"]},
        max_side=MAX_SIDE,
        shape=(16, 16, 2),
    )
    assert hc.hypotheses[0]["rms"] < 0.1 * sep.hypotheses[0]["rms"]


BEVY_MARGIN = 5.0  # the nominal conventions' RMS must be this many times below every alternative's


def test_bevy_shipped_ktx2_fits_the_bevy_preset():
    """Bevy's own dfg.ktx2 (tests/data/bevy_dfg.json): the preset's axes, texel centres and row order are the best
    hypothesis by more than BEVY_MARGIN (measured: 7.4x on this
    32-per-side subset, 8.7x on the full 64²), half floats."""
    r = run(DATA / "bevy_dfg.ktx2", preset="bevy")
    assert r.extra["chosen"] == "nominal" and r.quantisation["kind"] == "half"
    nominal = next(h for h in r.hypotheses if h["name"] == "nominal")
    assert nominal["rms"] * BEVY_MARGIN < min(h["rms"] for h in r.hypotheses if h["name"] != "nominal")


def test_bevy_shipped_table_is_height_correlated_not_separable():
    """On a 7 x 7 subset (first and last rows and columns): RMS ratio 0.022 there, 0.017 on 33 x 33."""
    hc = run(DATA / "bevy_dfg.ktx2", preset="bevy", max_side=FAST_SIDE)
    sep = audit(
        DATA / "bevy_dfg.ktx2", {"preset": "bevy", "overrides": ["masking=smith_separable"]}, max_side=FAST_SIDE
    )
    assert hc.hypotheses[0]["rms"] < 0.1 * sep.hypotheses[0]["rms"]


def test_unity_hdrp_table_audits_clean_and_its_sqrt_axis_flip_is_found(tmp_path):
    """A lutbake unity-hdrp table (Disney channel B, x = sqrt(NoV), endpoints) re-audited under its preset."""
    import lutbake
    from lutbake.config import load_config, preset_path

    spec = load_config(preset_path("unity-hdrp"), [(None, "size", [16, 16])])[0]
    table, _, _ = lutbake.bake_table(spec)
    p = tmp_path / "hdrp.npy"
    np.save(p, table.data)
    r = run(p, preset="unity-hdrp", tolerance=CLEAN_TOL)
    assert r.passed and r.extra["chosen"] == "nominal", r.text()
    q = tmp_path / "hdrp_flipped.npy"
    np.save(q, table.data[:, ::-1])
    assert run(q, preset="unity-hdrp").extra["chosen"] == "columns_flipped"


def test_cli_rejects_non_finite_values_and_undeclared_text_layouts(clean, tmp_path):
    p = tmp_path / "nan.npy"
    bad = clean.astype(np.float32).copy()
    bad[3, 5, 1] = np.nan
    np.save(p, bad)
    res = CliRunner().invoke(main, ["audit", str(p)])
    assert res.exit_code == 2 and "row 3, column 5, channel G" in res.output
    js = tmp_path / "lut.js"
    js.write_text("const DATA = new Uint16Array( [ 0x3c00, 0x0000 ] );\n")
    res = CliRunner().invoke(main, ["audit", str(js)])
    assert res.exit_code == 2 and "--shape" in res.output


@pytest.fixture
def no_area_lights(monkeypatch):
    """audit() of an LTC table without the area-light comparison (the tests using this do not read it;
    test_audit_runs_on_every_shipped_table does)."""
    from functools import partial

    from lutbake.commands import audit_tables

    monkeypatch.setattr(audit_tables, "audit_ltc", partial(audit_tables.audit_ltc, area_texels=0))


def write_ltc_js(path, t1, t2):
    path.write_text(
        "var g_ltc_1 = [" + ", ".join(f"{v:.6g}" for v in t1.ravel()) + "];\n"
        "var g_ltc_2 = [" + ", ".join(f"{v:.6g}" for v in t2.ravel()) + "];\n"
    )
    return path


def test_ltc_audit_fails_a_table_whose_matrices_are_packed_in_the_wrong_order(tmp_path, no_area_lights):
    """ltc_code's table with ltc_1's (y, z) coefficients exchanged (glm's column-major invM read row-major, a
    classic port mistake): the magnitudes are intact, so only the fit-quality check can catch it -- and does."""
    from lutbake.commands.audit_tables import FIT_RATIO_MAX, read_ltc_pair

    t1, t2 = read_ltc_pair(DATA / "ltc_code_ltc.js.gz")
    path = write_ltc_js(tmp_path / "ltc_swapped.js", t1[..., [0, 2, 1, 3]], t2)
    r = audit(path, {"preset": "ltc-ggx"}, max_side=FAST_SIDE, tolerance=1.0)
    assert r.extra["chosen"] == "nominal"
    assert r.extra["fit_ratio"] > FIT_RATIO_MAX
    assert not r.passed


def test_ltc_audit_names_flipped_view_rows(tmp_path, no_area_lights):
    """ltc_code's table with its view rows in reverse order (both textures): the magnitude hypotheses name it."""
    from lutbake.commands.audit_tables import read_ltc_pair

    t1, t2 = read_ltc_pair(DATA / "ltc_code_ltc.js.gz")
    r = audit(write_ltc_js(tmp_path / "ltc_flipped.js", t1[::-1], t2[::-1]), {"preset": "ltc-ggx"}, max_side=FAST_SIDE)
    assert r.extra["chosen"] == "rows_flipped", r.findings
    assert not r.passed


def test_ltc_audit_passes_lutbakes_own_table(tmp_path, no_area_lights):
    """A lutbake LTC table (ltc-threejs preset, JS floats, 4^2: what is checked holds at any size) audited under its
    own preset: magnitudes and Fresnel within float rounding, the conventions fit, the matrices are lutbake's fit
    (per-texel ratio 1)."""
    from lutbake import api
    from lutbake.config import load_configs

    spec = load_configs([Path("lutbake/presets/ltc-threejs.toml")], ["size=[4, 4]"])
    path = api.bake(spec, out_dir=tmp_path, workers=2)[0].path
    r = audit(path, {"preset": "ltc-threejs"}, max_side=4, tolerance=CLEAN_TOL)
    assert r.passed, r.text()
    assert r.extra["chosen"] == "nominal"
    np.testing.assert_allclose(r.extra["fit_ratio"], 1.0, rtol=CLEAN_TOL)


# ---- other tools' files are read -------------------------------------------------------------------------------------


def _write_oiio(path, pixels, names, pixel_type):
    import OpenImageIO as oiio

    h, w, n = pixels.shape
    spec = oiio.ImageSpec(w, h, n, pixel_type)
    spec.channelnames = tuple(names)
    spec.attribute("oiio:UnassociatedAlpha", 1)  # the codes as given (OIIO would un-premultiply them otherwise)
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec), oiio.geterror()
    assert out.write_image(np.ascontiguousarray(pixels))
    out.close()


@pytest.mark.parametrize(
    "name, names, pixel_type",
    [
        ("float_rg.exr", ["R", "G"], "float"),
        ("half_rgb.exr", ["R", "G", "B"], "half"),
        ("layer_rgba.exr", ["dfg.R", "dfg.G", "dfg.B", "dfg.A"], "float"),
        ("u16_rgb.png", ["R", "G", "B"], "uint16"),
        ("u16_grey_alpha.png", ["Y", "A"], "uint16"),
        ("u8_rgb.png", ["R", "G", "B"], "uint8"),
    ],
)
def test_other_tools_exr_and_png_files_are_read_and_pass_when_right(clean, tmp_path, name, names, pixel_type):
    """EXR (float/half, RG/RGB/RGBA, layer-prefixed channel names, no lutbake attribute) and PNG (8/16-bit, RGB and
    grey+alpha) as another tool writes them: read, and a correct table passes at a tolerance far below the 8-bit
    step (the storage rounding is not counted against it)."""
    n = len(names)
    values = np.concatenate([clean, np.zeros(clean.shape[:2] + (max(0, n - 2),))], axis=-1)[..., :n]
    if n == 4:
        values[..., 3] = 1.0
    if pixel_type.startswith("uint"):
        top = 255 if pixel_type == "uint8" else 65535
        pixels = np.round(values * top).astype(np.uint8 if top == 255 else np.uint16)
    else:
        pixels = values.astype(np.float16 if pixel_type == "half" else np.float32)
    path = tmp_path / name
    _write_oiio(path, pixels, names, pixel_type)
    r = run(path, tolerance=CLEAN_TOL)
    assert r.passed and r.extra["chosen"] == "nominal", (name, r.text())
    expect = {"uint8": "unorm8", "uint16": "unorm16", "half": "half", "float": "float"}[pixel_type]
    assert r.quantisation["kind"] == expect


# ------------------------------------------------------------------------- every shipped table in tests/data
# (last in the file: babylon's 64-side audit alone fills the reference memo, lutbake.commands.reference.REFERENCES)

# file -> (preset, audit keyword arguments); every table file of tests/data must be listed (the test below checks)
SHIPPED = {
    "filament_dfg.npz": ("filament", {}),
    "khronos_lut_ggx_u8.npz": ("gltf", {}),
    "blender_eevee_next_brdf_ggx.npz": ("blender-eevee", {}),
    "threejs_dfg_lut.js": ("threejs", {"shape": (16, 16, 2)}),
    "bevy_dfg.ktx2": ("bevy", {}),
    # IOR slices and roughness rows 0, 11, 22, 31: both ends of each axis, both sides of eta = 1 (the time is the
    # averages' per-slice quadrature)
    "openpbr_energy_tables.npz": ("openpbr", {"max_side": 3}),
    "ltc_code_ltc.js.gz": ("ltc-ggx", {}),
    # its sheen channel's smooth grazing corner (36.5 shipped vs 26.6 converged) outweighs a 6 x 6 subset's other texels
    "babylon_environment_brdf.npz": ("babylon", {"max_side": 64}),
    "babylon_openpbr_brdf.npz": ("babylon-openpbr", {}),
}
# tables of tests/data no preset bakes: the model they hold is not one lutbake integrates
UNAUDITED = {
    "babylon_environment_fuzz_brdf.npz": "Zeltner, Burley & Chiang 2022's LTC fit of their random-walk volume "
    "(identified in tests/test_sheen_volume.py; lutbake integrates their analytic approximation: preset babylon-fuzz, "
    "compared in tests/test_babylon.py; audit_ltc reads ltc_code pairs, not this (A, B, R_i) coding)",
    "ltc_sheen_tables.npz": "Zeltner et al.'s two published LTC tables (volume, approx): the references of "
    "tests/test_sheen_volume.py, no engine loads them",
    "ltc_aniso_alphax_alphay_theta_phi.npy": "Kt et al. 2022's anisotropic GGX LTC table (8^4 matrices, no magnitude):"
    " the reference of tests/test_ltc_aniso.py and benchmarks/bench_ltc_aniso.py; no kind writes this layout yet",
    "ltc_aniso_alpha_lambda_theta_phi.npy": "the same paper's alpha x lambda table (tests/test_ltc_aniso.py)",
    "env_studio_64x32.exr": "a CC0 lat-long environment (Blender's studio light, reduced): a source of "
    "tests/test_environment.py, not a table",
    "env_sunrise_64x32.exr": "a CC0 lat-long environment (Blender's sunrise, reduced): a source of "
    "tests/test_environment.py, not a table",
    "bevy_pisa_diffuse_rgb9e5_zstd.ktx2": "a cube map (Bevy's irradiance cube): audited by "
    "lutbake.commands.audit_cube in tests/test_cube_audit.py",
    "filament_pillars_2k_ibl_mips1-4.ktx": "a cube map (Filament's prefiltered IBL, mips 1-4): audited by "
    "lutbake.commands.audit_cube in tests/test_cube_audit.py",
}
FAST_SIDE = 6  # the loop's subset (its own tests above use MAX_SIDE)
OPENPBR_RATIO_MEAN = 2e-3  # the ratio re-baked: its averages' noise divided by them (measured mean 6.1e-4, all slices)
OPENPBR_AVG_ATOL = 1e-3  # the averages: Monte Carlo noise of OpenPBR's generator (measured max 4.3e-4)
LTC_SPHERE_ATOL = 2e-5  # ltc_code's float32 closed form printed with 6 digits (test_ltc PUBLISHED_SPHERE_ATOL)
LTC_MAGNITUDE_P50 = 2e-3  # ltc_code's 32 x 32-sample magnitudes (measured median 6.3e-4; max 0.066 at NoV = 8e-4)


def test_every_shipped_table_in_tests_data_is_audited():
    tables = {p.name for p in DATA.iterdir() if p.suffix not in (".json", ".md")}
    assert tables == set(SHIPPED) | set(UNAUDITED), tables ^ (set(SHIPPED) | set(UNAUDITED))


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_audit_runs_on_every_shipped_table(name):
    """Each shipped table audited under its engine's preset (fast subset): the preset's conventions fit the dfg-family
    tables (Filament's cmgen offset is the 'filament' preset itself), OpenPBR's averages match lutbake's within their
    Monte Carlo noise and its reflection ratio obeys the reciprocity identity and matches lutbake's on average, and
    ltc_code's unique LTC quantities match (sphere to its printed digits, magnitude to its sampling noise) with
    matrices that fit the lobe within FIT_RATIO_MAX of lutbake's own fit."""
    from lutbake.commands.audit_tables import FIT_RATIO_MAX, UNORM16_STEP

    preset, kw = SHIPPED[name]
    r = audit(DATA / name, {"preset": preset}, **{"max_side": FAST_SIDE, **kw})
    text = r.text()
    assert text.startswith(f"audit {DATA / name}") and ("PASS" in text or "FAIL" in text)
    if preset == "openpbr":
        for key in ("ideal_dielectric", "opaque_dielectric", "ideal_metal"):
            assert r.errors[f"{key}_avg_energy_complement"]["max"] < OPENPBR_AVG_ATOL
        assert r.extra["reciprocity_residual_max"] <= UNORM16_STEP
        assert r.errors["ideal_dielectric_reflection_ratio (alpha index >= 2, eta != 1)"]["mean"] < OPENPBR_RATIO_MEAN
    elif preset == "ltc-ggx":
        assert r.errors["sphere (t2.w)"]["max"] < LTC_SPHERE_ATOL
        assert r.errors["magnitude (t2.x)"]["p50"] < LTC_MAGNITUDE_P50
        assert r.extra["fit_ratio"] <= FIT_RATIO_MAX
        assert r.extra["area"]["file"]["median"] < 2 * r.extra["area"]["lutbake fit"]["median"]
    else:
        assert r.extra["chosen"] == "nominal", r.diagnosis
