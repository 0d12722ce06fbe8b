"""Babylon.js's shipped BRDF tables (@babylonjs/core 9.31, Misc/brdfTextureTools.js; tests/data/babylon_*.npz with
their provenance notes) against lutbake's presets ``babylon``, ``babylon-openpbr`` and ``babylon-fuzz``
(lutbake.layouts.babylon).

The shipped tables are 8-bit PNGs decoded as Babylon does (RGBD: pow(rgb, 2.2) / a); lutbake's bakes converge to
~1e-7. The stated tolerances are the measured errors (docs/presets.md) rounded up: the 8-bit codes (the RGBD step,
RGBD_HALF_STEP per texel) and Babylon's generator's own sampling noise.
"""

import json
from pathlib import Path

import numpy as np
import pytest

from lutbake.commands.audit import audit
from lutbake.layouts import TABLES, lookup_layout
from lutbake.layouts.babylon import f82_integrals, f82_stored

DATA = Path(__file__).resolve().parent / "data"
NAMES = ("babylon_environment_brdf", "babylon_openpbr_brdf", "babylon_environment_fuzz_brdf")
GRAZING_COLUMNS = 8  # NoV < 0.03 at 256² (the smooth grazing corner, where Babylon's generator is noisiest)
# environment BRDF (256², RGBD 8-bit) vs the converged bake: measured RMS R 1.7e-3, G 3.5e-3 (every texel)
ENV_RMS = {0: 2.5e-3, 1: 4.5e-3}
# ... and max |diff| over NoV >= 0.03: measured R 1.5e-2, G 1.2e-2 (the RGBD step at small D and generator noise)
ENV_MAX = {0: 2.0e-2, 1: 1.5e-2}
# the sheen channel B (Charlie DV, up to 36.5): median relative |diff| where B > 0.1 and NoV >= 0.03
ENV_SHEEN_RTOL_MEDIAN = 1e-2  # measured 4.6e-3
# OpenPBR F82 LUT (128², 8-bit): measured RMS R 3.4e-3, G 5.8e-3, B 4.3e-3
F82_RMS = {0: 4.5e-3, 1: 7.5e-3, 2: 6.0e-3}
F82_MAX = 2.0e-2  # measured 1.4e-2 (every channel, every texel)
AUDIT_SIDE = 16  # the F82 table's nominal RMS is 0.81x / 0.80x / 0.79x the best alternative's at sides 6 / 32 / 64
# fuzz table (32², Zeltner et al.'s random-walk *volume* fit, read linearly through the mix() ranges) vs the
# babylon-fuzz bake (their analytic approximation, lutbake's L3 fit) bilinearly at the shipped grid, rows mu >= 0.03:
# measured median |diff| A 2.3e-2, B 1.8e-2, R_i 7.1e-3; p95 0.25, 8.3e-2, 4.4e-2 (the paper's own approx table vs
# the shipped one: medians 1.9e-2, 1.4e-2, 9.0e-3: the gap is the two models', not the fit's)
FUZZ_MEDIAN = np.array([0.03, 0.025, 0.01])
FUZZ_P95 = np.array([0.3, 0.1, 0.06])
FUZZ_MODEL_GAP = 1.5  # the bake's median |diff| at most this times the published approx table's (measured <= 1.3)
FUZZ_GRID = np.maximum(0.01, np.arange(32) / 31)  # the shipped table's mu rows and alpha columns (endpoints)
RGBD_SIDE = 8  # the RGBD PNG's audit subset (its errors are compared with the decoded table's at the same texels)


def load(name):
    with np.load(DATA / f"{name}.npz") as z:
        return z["table"].astype(np.float64), z["codes"]


def rgbd_decode(codes: np.ndarray) -> np.ndarray:
    """Babylon's fromRGBD with toLinearSpace = pow(x, 2.2) (helperFunctions.js), written out here."""
    c = codes.astype(np.float64) / 255.0
    return c[..., :3] ** 2.2 / c[..., 3:4]


@pytest.mark.parametrize("name", NAMES)
def test_babylon_tables_are_the_rgbd_decode_of_their_pngs_and_hold_their_sample_values(name):
    """tests/data holds the PNG's codes and their decode as Babylon's fromRGBD computes it; the note's sample values
    ("[row, column]": R, G, B) are those of the stored table."""
    table, codes = load(name)
    note = json.loads((DATA / f"{name}.json").read_text())
    assert list(table.shape) == note["shape"] and codes.dtype == np.uint8 and codes.shape[-1] == 4
    np.testing.assert_allclose(table, rgbd_decode(codes), rtol=1e-6)
    for texel, want in note["sample_values"].items():
        row, col = json.loads(texel)
        np.testing.assert_allclose(table[row, col], want, rtol=1e-6)


def test_babylon_f82_layout_round_trips_blenders_three_integrals():
    e = np.random.default_rng(0).random((16, 3))
    np.testing.assert_allclose(f82_integrals(f82_stored(e)), e, atol=1e-15)
    lay = lookup_layout("dfg", "babylon_f82")
    assert lay.integrand == lookup_layout("dfg", "scale_bias_f82").integrand and lay.unit_range


def test_babylon_presets_are_its_engine_tables():
    assert {t.preset for t in TABLES if t.engine == "Babylon.js"} == {
        "babylon",
        "babylon-openpbr",
        "babylon-fuzz",
        "ltc-babylon",
        "babylon-ibl",
    }


@pytest.fixture(scope="module")
def environment(bake_preset):
    return bake_preset("babylon")[1].data.astype(np.float64), load("babylon_environment_brdf")[0]


def test_babylon_environment_brdf_matches_the_shipped_table_within_8bit_rgbd_and_noise(environment):
    """R = ∫ f/F Fc, G = ∫ f/F (Filament's pair, height-correlated GGX) at 256² texel centres, roughness 0 first."""
    baked, shipped = environment
    d = np.abs(baked - shipped)
    for ch, tol in ENV_RMS.items():
        assert np.sqrt(np.mean(d[..., ch] ** 2)) < tol, ch
    for ch, tol in ENV_MAX.items():
        assert d[:, GRAZING_COLUMNS:, ch].max() < tol, ch


def test_babylon_environment_sheen_channel_is_the_charlie_dv(environment):
    """B = ∫ D_charlie V_ashikhmin (n.l) dω (alpha = r²), as Filament's cloth channel: the median relative error away
    from the grazing corner is within 1 % (measured 0.46 %; p95 2.2 %, the 8-bit RGBD step)."""
    baked, shipped = environment
    b, s = baked[:, GRAZING_COLUMNS:, 2], shipped[:, GRAZING_COLUMNS:, 2]
    keep = b > 0.1
    assert np.median(np.abs(b - s)[keep] / b[keep]) < ENV_SHEEN_RTOL_MEDIAN


def test_babylon_openpbr_f82_lut_matches_the_shipped_table(bake_preset):
    """(bias, scale + bias, 16 F82 term) of the height-correlated GGX split sum at 128² texel centres."""
    baked = bake_preset("babylon-openpbr")[1].data.astype(np.float64)
    d = np.abs(baked - load("babylon_openpbr_brdf")[0])
    for ch, tol in F82_RMS.items():
        assert np.sqrt(np.mean(d[..., ch] ** 2)) < tol, ch
    assert d.max() < F82_MAX


@pytest.mark.parametrize("name, preset", [("babylon_openpbr_brdf", "babylon-openpbr")])
def test_audit_finds_babylons_declared_conventions_best(name, preset):
    """``lutbake audit`` under the preset: the declared conventions fit best (no flipped rows, texel offset or other
    split-sum layout). The environment table (babylon) is audited so, on the 64 x 64 subset its sheen channel's grazing
    corner needs, by tests/test_audit.py's test_audit_runs_on_every_shipped_table."""
    r = audit(DATA / f"{name}.npz", {"preset": preset}, max_side=AUDIT_SIDE)
    assert r.extra["chosen"] == "nominal", r.diagnosis


@pytest.fixture(scope="module")
def fuzz(bake_preset):
    return bake_preset("babylon-fuzz")[1]


def shipped_fuzz() -> np.ndarray:
    """The shipped fuzz PNG's codes read linearly through getFuzzBRDFLookup's mix() ranges (not Babylon's RGBD decode,
    whose gamma the coding never had: tests/test_sheen_volume.py)."""
    from lutbake.layouts.babylon import BABYLON_FUZZ

    return BABYLON_FUZZ.decode(load("babylon_environment_fuzz_brdf")[1][..., :3] / 255.0)


def bilinear_at(table: np.ndarray, points: np.ndarray) -> np.ndarray:
    """A (N, N, C) texel-centre table sampled as a clamp-to-edge bilinear sampler does at (row, column) values."""
    centres = (np.arange(table.shape[0]) + 0.5) / table.shape[0]
    along_x = np.apply_along_axis(lambda v: np.interp(points, centres, v), 1, table)  # (rows, points, C)
    return np.apply_along_axis(lambda v: np.interp(points, centres, v), 0, along_x)


def test_babylon_fuzz_file_is_the_mix_coding_of_the_fit_and_reads_back(fuzz, tmp_path):
    """format babylon_fuzz: one RGBA16F DDS, r, g, b = (A - 0.005)/0.875, (B + 0.18)/0.182, R_i/0.75 of the
    normal-frame fit (A = 1/ltc_1.w, B = ltc_1.z/ltc_1.w), a = 1, unclamped; inspect reads (A, B, R_i) back and says
    which values leave the mix() ranges (the sidecar lists them)."""
    from click.testing import CliRunner

    from lutbake.cli import main
    from lutbake.io import dds
    from lutbake.io.formats import write_table
    from lutbake.io.readers import read_table
    from lutbake.layouts.babylon import BABYLON_FUZZ

    path = write_table(fuzz, tmp_path, "babylon_fuzz", "half")
    stored = dds.decode(path.read_bytes())[0].astype(np.float64)
    inv = np.linalg.inv(np.array([[1.0, 0.0, 0.4], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]))  # A = 1: B = -0.4
    assert np.allclose(
        BABYLON_FUZZ.values(np.array([[[[inv[0, 0], inv[2, 0], inv[0, 2], inv[2, 2]]]], [[[0.5, 0.5, 0, 0]]]])),
        [1.0, -0.4, 0.5],
    )
    values = BABYLON_FUZZ.values(fuzz.data)
    want = np.stack([(values[..., 0] - 0.005) / 0.875, (values[..., 1] + 0.18) / 0.182, values[..., 2] / 0.75], -1)
    np.testing.assert_allclose(stored[..., :3], want, atol=1e-3, rtol=1e-3)  # RGBA16F rounding
    assert np.all(stored[..., 3] == 1.0)
    np.testing.assert_allclose(read_table(path).data, values, atol=2e-3, rtol=1e-3)
    outside = json.loads(path.with_name(path.name + ".json").read_text())["outside_mix_ranges"]
    assert outside == BABYLON_FUZZ.outside(values) and outside  # lutbake's fit leaves the ranges (A up to 1.03)
    r = CliRunner().invoke(main, ["inspect", str(path)])
    assert r.exit_code == 0 and "outside the mix ranges: A:" in r.output and "R = A:" in r.output, r.output


def test_babylon_fuzz_needs_a_normal_frame_lobe(tmp_path):
    from lutbake.config import validate_table
    from lutbake.errors import ConfigError

    with pytest.raises(ConfigError, match="normal's frame"):
        validate_table({"name": "t", "kind": "ltc", "lobe": "ggx", "format": "babylon_fuzz"}, tmp_path / "x.toml", 0)


def test_babylon_fuzz_preset_matches_the_shipped_table_as_closely_as_the_papers_own_approximation(fuzz):
    """The bake (the paper's analytic approximation, texel centres) read bilinearly at the shipped grid (mu, alpha =
    max(0.01, i/31), endpoints: half a texel off the centres Babylon samples) against the shipped table (their
    random-walk volume's fit): not the same model, so the tolerances are the measured differences (FUZZ_MEDIAN,
    FUZZ_P95) and the meaningful bound is that the gap is the models': the bake is within FUZZ_MODEL_GAP of the
    published approximation table's own median difference. Row mu = 0.01 (grazing) is left out: no LTC of this form
    fits it (relative L3 error ~1; tests/test_sheen_volume.py), |dA| up to 0.95 there."""
    from lutbake.layouts.babylon import BABYLON_FUZZ

    shipped = shipped_fuzz()
    ours = bilinear_at(BABYLON_FUZZ.values(fuzz.data), FUZZ_GRID)
    d = np.abs(ours - shipped)[1:]
    assert np.all(np.median(d, axis=(0, 1)) < FUZZ_MEDIAN), np.median(d, axis=(0, 1))
    assert np.all(np.quantile(d, 0.95, axis=(0, 1)) < FUZZ_P95), np.quantile(d, 0.95, axis=(0, 1))
    with np.load(DATA / "ltc_sheen_tables.npz") as z:
        paper = np.median(np.abs(z["approx"] - shipped)[1:], axis=(0, 1))
    assert np.all(np.median(d, axis=(0, 1)) < FUZZ_MODEL_GAP * paper), (np.median(d, axis=(0, 1)), paper)


def test_every_engine_table_names_a_storage_encoding_audit_knows():
    from lutbake.commands.audit_search import ENCODINGS

    assert {t.encoding for t in TABLES} <= set(ENCODINGS)
    # the environment BRDF tables ship as 8-bit RGBD PNGs, the area-light LTC tables as half floats (areaLightsLTC.bin)
    babylon = [t for t in TABLES if t.engine == "Babylon.js"]
    assert {t.encoding for t in babylon if t.preset == "ltc-babylon"} == {"plain"}
    assert {t.encoding for t in babylon if t.preset != "ltc-babylon" and t.kind != "environment_specular"} == {"rgbd"}


def test_audit_of_babylons_shipped_rgbd_png_decodes_rgbd_and_reports_the_real_error(tmp_path):
    """The shipped PNG (its 8-bit RGBA codes, tests/data) under --preset babylon: read as plain UNORM it was called
    'srgb_encoded' and failed by 25.7; the preset's engine table declares RGBD, so the audit decodes it as Babylon
    does and its errors are exactly those of the decoded table (the .npz's ``table``) against the converged bake."""
    import OpenImageIO as oiio

    codes = load("babylon_environment_brdf")[1]
    png = tmp_path / "shipped.png"
    spec = oiio.ImageSpec(codes.shape[1], codes.shape[0], 4, "uint8")
    spec.attribute("oiio:UnassociatedAlpha", 1)
    out = oiio.ImageOutput.create(str(png))
    assert out.open(str(png), spec) and out.write_image(np.ascontiguousarray(codes))
    out.close()
    r = audit(png, {"preset": "babylon"}, max_side=RGBD_SIDE)
    decoded = audit(DATA / "babylon_environment_brdf.npz", {"preset": "babylon"}, max_side=RGBD_SIDE)
    assert r.extra["encoding"] == "rgbd" and r.quantisation["kind"] == "unorm8", r.text()
    assert "storage rgbd" in r.conventions and any("RGBD-packed" in d for d in r.diagnosis)
    assert "srgb" not in r.extra["chosen"]
    for channel, s in decoded.errors.items():
        np.testing.assert_allclose([r.errors[channel][k] for k in ("max", "mean")], [s["max"], s["mean"]], rtol=1e-5)
    assert r.extra["raw_error"]["max"] == pytest.approx(decoded.extra["raw_error"]["max"], rel=1e-5)
