"""The environment kinds as config tables (lutbake.kinds.environment): names resolved once, the environment file and
every key refused at config time (nothing created), the environment's sha256 in the content hash (an edit rebakes, no
edit skips, a changed cube or SH file is never up to date), the one-run presets bevy-ibl / gltf-ibl with one set of
conventions in every file, inspect of the cube files, worker-count independence and failure isolation. Tiny cubes
(8^2 faces from the 64 x 32 CC0 sources of tests/data): the whole module takes seconds."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from click.testing import CliRunner
from test_environment import DATA

import lutbake
from lutbake.cli import main
from lutbake.config import load_config, load_configs, preset_path, validate_table
from lutbake.errors import ConfigError
from lutbake.io.cubemap import read_cube_record
from lutbake.io.environment import read_latlong
from lutbake.io.integrity import sha256_file, verified_attributes
from lutbake.kinds.environment import ENVIRONMENT_SPECULAR
from lutbake.layouts import TABLES
from lutbake.pipeline import bake_cube_table

SUNRISE = DATA / "env_sunrise_64x32.exr"
STUDIO = DATA / "env_studio_64x32.exr"
SMALL_IBL = ["bevy_specular.size=8", "bevy_diffuse.size=4"]  # bevy-ibl's cubes at test size (its DFG is 64^2)


def write_env(path, image: np.ndarray):
    """A lat-long EXR of ``image`` (h, 2h, 3) float32, written through OpenImageIO."""
    import OpenImageIO as oiio

    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), oiio.ImageSpec(image.shape[1], image.shape[0], 3, "float"))
    assert out.write_image(np.ascontiguousarray(image, np.float32))
    out.close()
    return path


def config(tmp_path, *tables: str, name: str = "c.toml"):
    path = tmp_path / name
    path.write_text("\n".join(f"[[table]]\n{t.strip()}\n" for t in tables))
    return path


SPECULAR = 'name = "spec"\nkind = "environment_specular"\nenvironment = "env.exr"\nsize = 8\nmips = 3'
IRRADIANCE = 'name = "irr"\nkind = "environment_irradiance"\nenvironment = "env.exr"\nsize = 4\nformat = "exr"'
DDS = 'name = "spec_dds"\nkind = "environment_specular"\nenvironment = "env.exr"\nsize = 4\nformat = "dds"'


@pytest.fixture(scope="module")
def baked(tmp_path_factory):
    """One batch of the three cube formats from a copy of the sunrise beside its config: (config, out-dir, results)."""
    d = tmp_path_factory.mktemp("env")
    shutil.copy(SUNRISE, d / "env.exr")
    cfg = config(d, SPECULAR, IRRADIANCE, DDS)
    results = lutbake.bake([cfg], out_dir=d / "out")
    return cfg, d / "out", results


# --- config: names resolved once, refusals before any work -------------------------------------------------------


def test_names_resolve_once_into_the_specs_records_and_defaults_fill_in(tmp_path):
    shutil.copy(SUNRISE, tmp_path / "env.exr")
    (spec,) = load_config(config(tmp_path, 'name = "s"\nkind = "environment_specular"\nenvironment = "env.exr"'))
    assert spec.records["curve"].obj.name == "linear" and spec.records["lobe"].name == "ggx_nl"
    assert spec.options["size"] == 256 and spec.options["mips"] is None and spec.options["orientation"] == "gl"
    assert spec.options["format"] == "ktx2" and spec.options["dtype"] == "half"
    assert ENVIRONMENT_SPECULAR.texels(spec.options) == 6 * sum((256 >> m) ** 2 for m in range(9))


def refusal(tmp_path, table: str, **files) -> str:
    """``lutbake bake`` of a one-table config beside ``files`` (name -> bytes or an image): its exit status must be 2,
    nothing created; returns its message."""
    for name, content in files.items():
        if isinstance(content, bytes):
            (tmp_path / name).write_bytes(content)
        elif isinstance(content, str):  # "dir"
            (tmp_path / name).mkdir()
        else:
            write_env(tmp_path / name, content)
    cfg = config(tmp_path, table)
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(out)])
    assert r.exit_code == 2, r.output
    assert not out.exists() and "Traceback" not in r.output
    return " ".join(r.output.split())


NAN = np.ones((4, 8, 3), np.float32)
NAN[1, 2, 0] = np.nan


@pytest.mark.parametrize(
    "files, fragment",
    [
        ({}, "no such file"),
        ({"env.exr": "dir"}, "not a regular file"),
        ({"env.exr": b"not an image at all"}, "OpenImageIO cannot read it"),
        ({"env.exr": np.ones((4, 6, 3), np.float32)}, "6 x 4 is not a lat-long image"),
        ({"env.exr": NAN}, "NaN or an infinite"),
        ({"env.png": b"\x89PNG\r\n\x1a\n"}, "not an EXR or Radiance HDR"),
    ],
    ids=["missing", "directory", "garbage", "not_2_to_1", "nan", "png"],
)
def test_a_bad_environment_is_refused_at_config_time_naming_file_and_key(tmp_path, files, fragment):
    name = next(iter(files), "env.exr")
    msg = refusal(tmp_path, SPECULAR.replace("env.exr", name), **files)
    assert "c.toml" in msg and "key 'environment'" in msg and fragment in msg, msg


@pytest.mark.parametrize(
    "line, key, fragment",
    [
        ('curve = "linaer"', "curve", "did you mean 'linear'?"),
        ('lobe = "phong"', "lobe", "allowed: ggx_nl, ggx, charlie"),
        ('format = "png16"', "format", "allowed: ktx2, dds, exr"),
        ('orientation = "d3d"', "orientation", "allowed: gl, d3d_left_handed"),
        ("mips = 5", "mips", "at most 4 mips"),  # an 8^2 cube: 8, 4, 2, 1
        ("tau = 0.0", "tau", ">= 0.0001"),
        ('sh_form = "radiance"', "sh_form", "is not a key of kind 'environment_specular'"),
    ],
)
def test_a_bad_key_is_refused_naming_file_key_and_allowed_values(tmp_path, line, key, fragment):
    write_env(tmp_path / "env.exr", np.ones((4, 8, 3), np.float32))
    msg = refusal(tmp_path, SPECULAR.replace("mips = 3", line if line.startswith("mips") else "mips = 3\n" + line))
    assert "c.toml" in msg and f"key '{key}'" in msg and fragment in msg, msg


def test_a_preset_without_an_environment_says_how_to_give_one(tmp_path):
    r = CliRunner().invoke(main, ["bake", "--preset", "bevy-ibl", "--out-dir", str(tmp_path / "o")])
    assert r.exit_code == 2 and not (tmp_path / "o").exists()
    assert "--preset bevy-ibl --environment FILE" in " ".join(r.output.split()), r.output
    with pytest.raises(ConfigError, match="no table of the batch takes an environment"):
        load_configs([preset_path("bevy")], environment=STUDIO)


def test_environment_fills_only_the_tables_that_take_it_with_the_path_made_absolute(monkeypatch):
    monkeypatch.chdir(DATA)
    specs = load_configs([preset_path("bevy-ibl")], environment=STUDIO.name)
    assert [s.kind for s in specs] == ["dfg", "environment_specular", "environment_irradiance"]
    assert "environment" not in specs[0].options
    assert {s.options["environment"] for s in specs[1:]} == {str(STUDIO)}


def test_lutbake_bake_of_an_environment_config_writes_then_skips(tmp_path):
    """examples/environment/studio.toml (its environment relative to itself) through the command line, at 8^2."""
    example = DATA.parent.parent / "examples" / "environment" / "studio.toml"
    args = ["bake", str(example), "--out-dir", str(tmp_path), "--set", "size=8"]
    first = CliRunner().invoke(main, args)
    assert first.exit_code == 0, first.output
    assert "studio_specular.ktx2  6x8x8x3, 4 mips" in first.output and "samples/texel" not in first.output
    again = CliRunner().invoke(main, args)
    assert again.exit_code == 0 and "2 tables: 0 baked, 2 up to date, 0 failed" in again.output, again.output
    assert json.loads((tmp_path / "studio_diffuse_sh.json").read_text())["form"] == "irradiance_over_pi"


# --- the content hash: the environment's bytes -------------------------------------------------------------------


def statuses(results) -> dict[str, str]:
    return {r.name: r.status for r in results}


def test_editing_the_environment_rebakes_and_leaving_it_skips(tmp_path):
    image = read_latlong(STUDIO).image.copy()
    write_env(tmp_path / "env.exr", image)
    cfg = config(tmp_path, SPECULAR.replace("size = 8\nmips = 3", "size = 2"), IRRADIANCE)
    out = tmp_path / "out"
    assert statuses(lutbake.bake([cfg], out_dir=out)) == {"spec": "baked", "irr": "baked"}
    assert statuses(lutbake.bake([cfg], out_dir=out)) == {"spec": "skipped", "irr": "skipped"}
    before = (out / "spec.ktx2").read_bytes()
    image[3, 5] += 1.0
    write_env(tmp_path / "env.exr", image)
    assert statuses(lutbake.bake([cfg], out_dir=out)) == {"spec": "baked", "irr": "baked"}
    assert (out / "spec.ktx2").read_bytes() != before
    record = read_cube_record(out / "spec.ktx2")["record"]
    assert record["source_sha256"] == sha256_file(tmp_path / "env.exr")
    assert statuses(lutbake.bake([cfg], out_dir=out)) == {"spec": "skipped", "irr": "skipped"}


def test_a_changed_cube_or_sh_file_or_key_is_never_up_to_date(baked, tmp_path):
    cfg, out, _ = baked
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    from lutbake.batch import schedule

    specs = load_configs([cfg])
    assert {j.name: j.status for j in schedule(specs, copy)} == {
        "spec": "skipped",
        "irr": "skipped",
        "spec_dds": "skipped",
    }
    for name in ("spec.ktx2", "spec_dds.dds"):  # one byte of the last mip's pixels
        data = bytearray((copy / name).read_bytes())
        data[-3] ^= 0x40
        (copy / name).write_bytes(bytes(data))
    (copy / "irr_sh.json").write_text((copy / "irr_sh.json").read_text().replace("radiance", "radiance "))
    assert all(j.status == "pending" for j in schedule(specs, copy))
    other = load_configs([cfg], ["spec.tau=0.2"])
    assert {j.name: j.status for j in schedule(other, out)}["spec"] == "pending"  # another hash, same bytes


# --- the one-run presets: both halves, one set of conventions ----------------------------------------------------


@pytest.fixture(scope="module")
def bevy_ibl(tmp_path_factory):
    out = tmp_path_factory.mktemp("bevy_ibl")
    results = lutbake.bake([preset_path("bevy-ibl")], out_dir=out, overrides=SMALL_IBL, environment=STUDIO)
    return out, results


def test_bevy_ibl_writes_the_dfg_and_both_cubes_with_one_set_of_conventions(bevy_ibl):
    out, results = bevy_ibl
    assert statuses(results) == {"bevy_dfg": "baked", "bevy_specular": "baked", "bevy_diffuse": "baked"}
    names = {"bevy_dfg.ktx2", "bevy_specular.ktx2", "bevy_diffuse.ktx2", "bevy_diffuse_sh.json"}
    assert names | {n + ".json" for n in names - {"bevy_diffuse_sh.json"}} == {p.name for p in out.iterdir()}
    dfg = verified_attributes(out / "bevy_dfg.ktx2")
    cubes = [read_cube_record(out / f"bevy_{n}.ktx2")["record"] for n in ("specular", "diffuse")]
    ibl = json.loads(dfg["ibl"])
    assert all(c["ibl"] == ibl for c in cubes)
    assert ibl["engine"] == "Bevy" and (ibl["ndf"], ibl["roughness"], ibl["mip_curve"]) == (
        "ggx",
        "perceptual",
        "linear",
    )
    terms = json.loads(dfg["terms"])  # the DFG table was integrated with the conventions it records
    assert terms["ndf"].startswith("ggx") and terms["masking"].startswith(ibl["masking"])
    specular = cubes[0]
    assert specular["mip_curve"].startswith(ibl["mip_curve"]) and specular["weighting"].startswith(ibl["lobe"])
    assert specular["roughness"] == [0.0, 1 / 3, 2 / 3, 1.0] and specular["alpha"] == [
        r * r for r in specular["roughness"]
    ]
    assert specular["face_convention"].startswith("d3d_left_handed")  # Bevy samples vec3(R.xy, -R.z)
    assert cubes[1]["sh_file"] == "bevy_diffuse_sh.json"
    sh = json.loads((out / "bevy_diffuse_sh.json").read_text())
    assert sh["coefficients"] == cubes[1]["sh"] and sh["source_sha256"] == specular["source_sha256"]


ALL_KINDS = {"dfg", "environment_specular", "environment_irradiance"}
IBL_KINDS = {
    "bevy-ibl": ALL_KINDS,
    "gltf-ibl": ALL_KINDS,
    "filament-ibl": ALL_KINDS - {"environment_irradiance"},
    "babylon-ibl": ALL_KINDS - {"environment_irradiance"},
}


@pytest.mark.parametrize("preset", sorted(IBL_KINDS))
def test_each_ibl_presets_tables_hold_the_conventions_their_engine_records(preset):
    """Every table of an ibl preset is an engine table with the engine's IBL conventions, and holds the keys those
    conventions fix (dfg: ndf, masking, roughness; the specular cube: curve, lobe)."""
    from lutbake.layouts import engine_table

    specs = load_config(preset_path(preset), environment=STUDIO)
    tables = [engine_table(s.kind, s.name, s.options) for s in specs]
    assert all(t is not None and t.ibl is not None for t in tables), preset
    assert len({t.ibl for t in tables}) == 1
    for spec, table in zip(specs, tables):
        for key, want in table.ibl.keys(spec.kind).items():
            assert spec.options[key] == want, (preset, spec.name, key)
    assert {t.kind for t in TABLES if t.preset == preset} == IBL_KINDS[preset]


# Filament's: the DFG table and one KTX 1 (the cube 8^2 to 2^2 by the quadrature; the harmonics' fixed cost: ~10 CPU s)
SMALL_FILAMENT = ["filament_specular.size=8", "filament_specular.mips=3", "filament_specular.estimator=quadrature"]
# cmgen's R11F_G11F_B10F rounds to a nearest code: half a step, 2^-(M+1) of the value (M = 6, 6, 5 mantissa bits),
# below 2^-14 within one subnormal step 2^-14 / 2^M (tests/test_filament_ibl.py)
R11G11B10F_HALF_STEP = np.array([2.0**-7, 2.0**-7, 2.0**-6])
R11G11B10F_SUBNORMAL = np.array([2.0**-20, 2.0**-20, 2.0**-19])


@pytest.fixture(scope="module")
def filament_ibl(tmp_path_factory):
    out = tmp_path_factory.mktemp("filament_ibl")
    results = lutbake.bake([preset_path("filament-ibl")], out_dir=out, overrides=SMALL_FILAMENT, environment=STUDIO)
    return out, results


def test_filament_ibl_writes_the_dfg_and_one_ktx1_with_one_set_of_conventions(filament_ibl):
    out, results = filament_ibl
    assert statuses(results) == {"filament_dfg_corrected": "baked", "filament_specular": "baked"}
    names = {"filament_dfg_corrected.dds", "filament_specular.ktx"}
    assert names | {n + ".json" for n in names} == {p.name for p in out.iterdir()}
    found = read_cube_record(out / "filament_specular.ktx")
    assert (found["format"], found["size"], found["mips"]) == ("ktx1", 8, 3)
    record = found["record"]
    ibl = json.loads(verified_attributes(out / "filament_dfg_corrected.dds")["ibl"])
    assert record["ibl"] == ibl and ibl["engine"] == "Filament"
    assert (ibl["ndf"], ibl["masking"], ibl["roughness"], ibl["mip_curve"], ibl["lobe"]) == (
        "ggx",
        "smith_height_correlated",
        "perceptual",
        "filament",
        "ggx_nl",
    )
    # cmgen's level m of M: lodToPerceptualRoughness(m / (M - 1)) = 1 - sqrt(1 - m / (M - 1)), alpha = r^2
    np.testing.assert_allclose(record["roughness"], [0.0, 1 - np.sqrt(0.5), 1.0], rtol=0, atol=1e-15)
    assert record["alpha"] == [r * r for r in record["roughness"]]
    assert record["face_convention"].startswith("gl") and record["weighting"].startswith("ggx_nl")
    assert record["reconstruction"].startswith("Filament: lod = iblRoughnessOneLevel * r * (2.0 - r)")


def test_filament_ibl_ktx1_holds_the_cube_within_its_rounding_and_the_sources_sh(filament_ibl):
    from lutbake.environment import sh
    from lutbake.io.ktx1 import decode_ktx1_cube

    out, results = filament_ibl
    cube = next(r.table for r in results if r.name == "filament_specular")
    mips, fmt, pairs = decode_ktx1_cube((out / "filament_specular.ktx").read_bytes())
    assert fmt == "r11g11b10f" and [m.shape for m in mips] == [(6, n, n, 3) for n in (8, 4, 2)]
    for got, want in zip(mips, cube.mips, strict=True):
        assert np.all(np.abs(got - want) <= R11G11B10F_HALF_STEP * want + R11G11B10F_SUBNORMAL)
    # the key sh: the filament form of the source's SH (Filament's iblSH), as written to 9 digits, and in the record
    want = sh.convolve(sh.project(read_latlong(STUDIO).image), "filament")
    np.testing.assert_allclose(np.array(pairs["sh"].split(), float).reshape(9, 3), want, rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(cube.record["sh"], want, rtol=1e-14, atol=0)
    assert cube.record["sh_form"] == "filament"


def test_inspect_shows_filaments_ktx1_and_its_conventions(filament_ibl):
    out, _ = filament_ibl
    r = CliRunner().invoke(main, ["inspect", str(out / "filament_specular.ktx")])
    assert r.exit_code == 0, r.output
    text = " ".join(r.output.split())
    assert "KTX 1.1 cube, r11g11b10f (glInternalFormat 0x8c3a), 8 x 8 faces, 3 mip(s)" in text
    assert "bytes (and its other files) match" in text and "sh (filament, also in the file's key sh)" in text
    assert "ibl conventions (every file of the engine's run): engine Filament, ndf ggx" in text
    assert "mip_curve: filament: lod = (M - 1) * r * (2 - r)" in text


def test_bake_environment_for_filament_writes_its_one_ktx1(tmp_path, monkeypatch):
    """No irradiance cube: the SH is the KTX 1's key (the cube by the quadrature, for the test's time)."""
    from lutbake.commands.environment import bake_environment
    from lutbake.environment import prefilter

    real = prefilter.bake_cube
    monkeypatch.setattr(prefilter, "bake_cube", lambda *a, **k: real(*a, **{**k, "method": "quadrature"}))
    paths = bake_environment(STUDIO, tmp_path, "studio", engine="filament", size=4)
    assert set(paths) == {"specular"} and paths["specular"].name == "studio_specular.ktx"
    found = read_cube_record(paths["specular"])
    assert found["pixel_format"].startswith("r11g11b10f") and found["record"]["sh_form"] == "filament"


@pytest.mark.parametrize(
    "table, key, fragment",
    [
        (SPECULAR + '\ndtype = "r11g11b10f"', "dtype", "written in format ktx1 only, not ktx2"),
        (SPECULAR.replace("mips = 3", 'mips = 4\nformat = "ktx1"\ndtype = "half"'), "mips", "1 x 1 (6 bytes"),
        (SPECULAR + '\nformat = "ktx1"\ndtype = "rgb9e5"', "dtype", "format ktx1 takes dtype r11g11b10f, half"),
        (IRRADIANCE.replace('"exr"', '"ktx1"'), "format", "allowed: ktx2, dds, exr"),  # its SH: the specular KTX
    ],
    ids=["r11g11b10f_in_ktx2", "half_1x1_in_ktx1", "rgb9e5_in_ktx1", "irradiance_ktx1"],
)
def test_filaments_ktx1_storage_is_refused_where_it_cannot_be_written(tmp_path, table, key, fragment):
    write_env(tmp_path / "env.exr", np.ones((4, 8, 3), np.float32))
    msg = refusal(tmp_path, table)
    assert "c.toml" in msg and f"key '{key}'" in msg and fragment in msg, msg


def test_inspect_prints_the_record_of_each_cube_format(baked, bevy_ibl):
    _, out, _ = baked
    for name, fmt in (("spec.ktx2", "KTX 2.0 cube"), ("spec_dds.dds", "DDS cube"), ("irr.exr", "OpenEXR cube")):
        r = CliRunner().invoke(main, ["inspect", str(out / name)])
        assert r.exit_code == 0, r.output
        assert fmt in r.output and "bytes (and its other files) match" in r.output
        assert "face_convention: gl" in r.output and "sha256 565d7e58" in r.output  # the sunrise's
    spec = CliRunner().invoke(main, ["inspect", str(out / "spec.ktx2.json")]).output  # its sidecar: the same
    assert "mip_curve: linear: lod = r * (M - 1)" in spec and "8 x 8 faces, 3 mip(s)" in spec
    rows = spec[spec.index("mips:") :].splitlines()[2:5]
    assert [r.split()[:4] for r in rows] == [["0", "8", "0", "0"], ["1", "4", "0.5", "0.25"], ["2", "2", "1", "1"]]
    assert rows[0].split()[4] == "footprint" and all(float(r.split()[5]) < 1e-3 for r in rows)
    bevy = CliRunner().invoke(main, ["inspect", str(bevy_ibl[0] / "bevy_specular.ktx2")]).output
    lines = bevy.splitlines()
    assert lines[lines.index("reconstruction:") + 1].startswith("  Bevy: radiance_level = perceptual_roughness")
    assert "ibl conventions (every file of the engine's run): engine Bevy, ndf ggx" in bevy


def test_inspect_reads_the_sh_file_and_preview_draws_a_cube(baked, tmp_path):
    _, out, _ = baked
    sh = CliRunner().invoke(main, ["inspect", str(out / "irr_sh.json")])
    assert sh.exit_code == 0 and "form: radiance" in sh.output and "coefficients (9 x RGB):" in sh.output
    doc = json.loads((out / "irr_sh.json").read_text())
    assert doc["coefficients"] == read_cube_record(out / "irr.exr")["record"]["sh"]
    r = CliRunner().invoke(main, ["preview", str(out / "spec.ktx2"), "-o", str(tmp_path / "p.png")])
    assert r.exit_code == 0 and (tmp_path / "p.png").is_file()  # tests/test_environment_render.py: what it draws


# --- the bake itself ----------------------------------------------------------------------------------------------


def test_cubes_are_bit_identical_for_one_or_two_workers():
    spec = validate_table(
        {"name": "w", "kind": "environment_specular", "environment": str(SUNRISE), "size": 8, "mips": 3},
        "<test>",
        0,
    )
    one, _ = bake_cube_table(spec, workers=1)
    two, _ = bake_cube_table(spec, workers=2)
    for a, b in zip(one.mips, two.mips, strict=True):
        np.testing.assert_array_equal(a, b)
    assert one.record == two.record and one.attributes["content_hash"] == two.attributes["content_hash"]


HEMISPHERE_ATOL = 1e-6  # measured 2.2e-8: the source is exact (the z = 0 plane is a column edge), the rest quadrature


@pytest.mark.parametrize("orientation, sign", [("gl", 1.0), ("d3d_left_handed", -1.0)])
def test_the_irradiance_of_a_lit_hemisphere_is_its_closed_form_in_each_orientation(tmp_path, orientation, sign):
    """L = 1 on the world's z > 0 half (the lat-long's columns u >= 1/2, exactly), 0 elsewhere: E / pi at a world
    normal n is (1 + n_z) / 2. A texel's lookup vector d stands for the world direction d (gl) or (d.x, d.y, -d.z)
    (d3d_left_handed, Bevy's vec3(N.xy, -N.z)), so its value is (1 + d_z) / 2, or (1 - d_z) / 2."""
    from lutbake.environment import cube

    image = np.zeros((32, 64, 3), np.float32)
    image[:, 32:] = 1.0
    write_env(tmp_path / "half.exr", image)
    raw = {"name": "h", "kind": "environment_irradiance", "size": 4, "orientation": orientation}
    baked, _ = bake_cube_table(validate_table({**raw, "environment": str(tmp_path / "half.exr")}, "<test>", 0))
    d = cube.texel_centres(4).reshape(-1, 3)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    want = np.repeat(((1 + sign * d[:, 2]) / 2)[:, None], 3, axis=1)
    np.testing.assert_allclose(baked.mips[0].reshape(-1, 3), want, rtol=0, atol=HEMISPHERE_ATOL)


def test_a_failing_environment_table_leaves_every_other_output_as_it_was(baked, tmp_path, monkeypatch):
    from lutbake.environment import prefilter

    cfg, out, first = baked
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    dfg = config(tmp_path, 'name = "dfg"\nkind = "dfg"\nsize = [8, 4]\nsamples = 48', name="dfg.toml")
    kept = {p.name: p.read_bytes() for p in copy.iterdir()}

    def broken(*args, **kwargs):
        raise RuntimeError("the prefilter broke")

    monkeypatch.setattr(prefilter, "bake_cube", broken)
    results = lutbake.bake([cfg, dfg], out_dir=copy, force=True, check=False)
    assert statuses(results) == {"spec": "failed", "irr": "failed", "spec_dds": "failed", "dfg": "baked"}
    assert "the prefilter broke" in results[0].message and results.exit_status == 1
    assert {p.name: p.read_bytes() for p in copy.iterdir() if p.name in kept} == kept
    assert (copy / "dfg.exr").is_file()


@pytest.mark.parametrize("fmt", ["ktx2", "dds", "exr"])
def test_a_cube_half_cannot_hold_writes_no_file_of_its_unit(tmp_path, fmt):
    from lutbake.io.cubemap import write_cube

    mips = [np.full((6, 2, 2, 3), 1.0), np.full((6, 1, 1, 3), 7e4)]  # 7e4 > 65504, half's largest
    with pytest.raises(ValueError, match="past what half holds"):
        write_cube(mips, tmp_path / f"c.{fmt}", {}, fmt, "half", {"c_sh.json": b"{}"})
    assert not any(tmp_path.iterdir())


def test_every_file_of_the_batch_is_written_and_listed(baked):
    _, out, results = baked
    assert statuses(results) == {"spec": "baked", "irr": "baked", "spec_dds": "baked"}
    assert {p.name for p in out.iterdir()} == {
        "spec.ktx2",
        "spec.ktx2.json",
        "irr.exr",
        "irr_sh.json",
        "spec_dds.dds",
        "spec_dds.dds.json",
    }
    assert [r.shape for r in results] == ["6x8x8x3, 3 mips", "6x4x4x3, 1 mip", "6x4x4x3, 3 mips"]
