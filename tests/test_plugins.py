"""A BRDF from outside the package (lutbake.plugins): the examples' Fresnel and diffuse lobe bake from a config and from
Python and match independent scipy integrals to the table's tolerance; the plugin's text is in the content hash (an
edit rebakes, no edit skips) and in the file's metadata (inspect names it); a plugin NDF with GGX's terms bakes
lutbake's GGX table; a plugin that fails to import, redefines a name or does not compile is refused before any work,
naming its file and line; an installed package's entry point registers its records."""

import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from hemisphere_reference import hemisphere_integral

import lutbake
from lutbake.config import load_configs, preset_path, validate_table
from lutbake.errors import ConfigError
from lutbake.io.describe import describe
from lutbake.io.readers import read_table

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
SMALL = ["size=[16, 8]"]


@pytest.fixture(scope="module")
def fresnel_example(tmp_path_factory):
    """The custom-Fresnel example copied to a folder of its own and baked at 16 x 8 from its config."""
    folder = tmp_path_factory.mktemp("schlick4")
    for f in ("schlick4.py", "dfg_schlick4.toml"):
        shutil.copy(EXAMPLES / "custom_fresnel" / f, folder / f)
    results = lutbake.bake([folder / "dfg_schlick4.toml"], out_dir=folder / "out", overrides=SMALL)
    assert [r.status for r in results] == ["baked"], results[0].message
    return folder, results[0]


def ggx_dfg_reference(nov: float, alpha: float, Fc) -> np.ndarray:
    """(scale, bias) = ∫ D G2 / (4 n.v) (1 - Fc, Fc) dμ dφ, height-correlated Smith GGX, by scipy (independent)."""
    a2 = alpha * alpha

    def lam(c):
        return 0.5 * (np.sqrt(1.0 + a2 * (1.0 - c * c) / (c * c)) - 1.0)

    def f(mu, noh, voh):
        d = a2 / (np.pi * (noh * noh * (a2 - 1.0) + 1.0) ** 2)
        return d / (4.0 * nov) / (1.0 + lam(nov) + lam(mu))  # f/F (n.l): the 1/(n.l) cancels

    scale = hemisphere_integral(lambda mu, noh, voh: f(mu, noh, voh) * (1.0 - Fc(voh)), nov)
    bias = hemisphere_integral(lambda mu, noh, voh: f(mu, noh, voh) * Fc(voh), nov)
    return np.array([scale, bias])


def test_the_custom_fresnel_dfg_matches_an_independent_integral(fresnel_example):
    folder, result = fresnel_example
    view = read_table(result.path)
    tol = float(view.attrs["tolerance"].split("(")[1].split(",")[0])  # "max(1e-06, 0 |v|) per value"
    nov_axis, r_axis = view.axes[1], view.axes[0]
    for i, j in ((4, 3), (8, 5), (12, 7), (2, 4)):  # (NoV column, roughness row), away from the sharpest lobes
        nov, r = float(nov_axis.values()[i]), float(r_axis.values()[j])
        want = ggx_dfg_reference(nov, r * r, lambda c: np.clip(1.0 - c, 0.0, 1.0) ** 4)
        np.testing.assert_allclose(view.data[j, i, :2], want, rtol=0.0, atol=tol + 2e-7, err_msg=f"{nov=}, {r=}")
    # not Schlick's table: the fourth power moves the bias by > 1e-3 at grazing
    schlick = ggx_dfg_reference(float(nov_axis.values()[1]), 0.25, lambda c: np.clip(1.0 - c, 0.0, 1.0) ** 5)
    assert abs(view.data[4, 1, 1] - schlick[1]) > 1e-3


def test_the_python_api_bakes_the_same_bits(fresnel_example):
    folder, result = fresnel_example
    (record,) = lutbake.load_plugin(folder / "schlick4.py")
    assert record.name == "schlick4" and record.family == "fresnel" and record.line == 27
    spec = validate_table({"name": "api", "kind": "dfg", "size": [16, 8], "fresnel": "schlick4"}, "<api>", 0)
    assert spec.records["fresnel"] is record
    table, _, _ = lutbake.bake_table(spec)
    np.testing.assert_array_equal(table.data, read_table(result.path).data)


def test_inspect_names_the_plugin_its_function_and_source_hash(fresnel_example):
    import hashlib

    folder, result = fresnel_example
    text = describe(result.path)
    sha = hashlib.sha256((folder / "schlick4.py").read_bytes()).hexdigest()
    assert f"fresnel 'schlick4' from {folder / 'schlick4.py'}, line 27 (F_schlick4, Fc_schlick4)" in text
    assert f"source sha256 {sha}" in text
    assert '"fresnel": "schlick4"' in text


def test_editing_the_plugin_rebakes_and_leaving_it_skips(fresnel_example, tmp_path):
    folder, result = fresnel_example
    out = folder / "out"
    again = lutbake.bake([folder / "dfg_schlick4.toml"], out_dir=out, overrides=SMALL)
    assert again[0].status == "skipped"
    plugin = folder / "schlick4.py"
    plugin.write_text(plugin.read_text() + "# an edit\n")
    edited = lutbake.bake([folder / "dfg_schlick4.toml"], out_dir=out, overrides=SMALL)
    assert edited[0].status == "baked"
    np.testing.assert_array_equal(read_table(edited[0].path).data, read_table(result.path).data)  # same terms
    assert lutbake.bake([folder / "dfg_schlick4.toml"], out_dir=out, overrides=SMALL)[0].status == "skipped"


def burley_albedo(nov: float, r: float) -> float:
    """∫ Fd_burley (n.l) dω (rho = 1), Burley 2012 Eq. 3, by scipy (independent of the plugin's Warp code)."""
    sv = np.sqrt(1.0 - nov * nov)

    def f(mu, noh, voh):  # hemisphere_integral passes (n.l, n.h, v.h); l.v = 2 (v.h)^2 - 1, (l.h)^2 = (v.h)^2
        fd90 = 0.5 + 2.0 * r * voh * voh
        return (1 + (fd90 - 1) * (1 - mu) ** 5) * (1 + (fd90 - 1) * (1 - nov) ** 5) / np.pi * mu

    del sv
    return hemisphere_integral(f, nov)


def test_the_custom_diffuse_lobe_matches_an_independent_integral(tmp_path):
    for f in ("burley.py", "diffuse_burley.toml"):
        shutil.copy(EXAMPLES / "custom_diffuse" / f, tmp_path / f)
    (result,) = lutbake.bake([tmp_path / "diffuse_burley.toml"], out_dir=tmp_path / "out", overrides=["size=[8, 4]"])
    assert result.status == "baked", result.message
    view = read_table(result.path)
    sigma, nov = view.axes[0].values(), view.axes[1].values()
    got = view.data[..., 0]
    want = np.array([[burley_albedo(float(n), float(s)) for n in nov] for s in sigma])
    np.testing.assert_allclose(got, want, rtol=0.0, atol=2e-6)
    assert got.max() > 1.0 > got.min()  # rough: more than Lambert's 1 at grazing; smooth: less


NDF_PLUGIN = """
import warp as wp
import lutbake
from lutbake.terms import masking, ndf

@wp.func
def D_mine(h: wp.vec3, alpha: float):
    return ndf.D_ggx(h, alpha)

@wp.func
def Lambda_mine(NoX: float, alpha: float):
    return masking.Lambda_ggx(NoX, alpha)

lutbake.register_ndf("{name}", D_mine, Lambda_mine, description="GGX's terms under another name"{cdf})
"""


@pytest.mark.parametrize("cdf", ["ggx_cdf", "theta"])
def test_a_plugin_ndf_with_ggxs_terms_bakes_lutbakes_ggx_table(tmp_path, cdf):
    """With GGX's CDF pair the plugin bakes the same bits as ndf = "ggx"; without a CDF the panels run in theta_h
    and meet the same tolerance."""
    extra = ", tan2_from_u=ndf.tan2_from_u_ggx, u_from_tan2=ndf.u_from_tan2_ggx" if cdf == "ggx_cdf" else ""
    name = f"my_ggx_{cdf}"
    (tmp_path / "mine.py").write_text(NDF_PLUGIN.format(name=name, cdf=extra))
    lutbake.load_plugin(tmp_path / "mine.py")
    common = {"kind": "dfg", "size": [8, 8], "interpolation": "off"}
    mine, _, _ = lutbake.bake_table(validate_table({"name": "m", "ndf": name, **common}, "<t>", 0))
    ggx, _, _ = lutbake.bake_table(validate_table({"name": "g", **common}, "<t>", 0))
    if cdf == "ggx_cdf":
        np.testing.assert_array_equal(mine.data, ggx.data)
    else:
        np.testing.assert_allclose(mine.data, ggx.data, rtol=0.0, atol=2e-6)
        with pytest.raises(ConfigError, match="samples the NDF's own CDF"):
            validate_table({"name": "m", "ndf": name, "estimator": "sobol_ndf", **common}, "<t>", 0)


def plugin_config(tmp_path, body: str, table: str = 'fresnel = "bad"') -> Path:
    (tmp_path / "bad.py").write_text(textwrap.dedent(body))
    cfg = tmp_path / "bad.toml"
    cfg.write_text(f'plugins = ["bad.py"]\n[[table]]\nname = "t"\nkind = "dfg"\nsize = [4, 4]\n{table}\n')
    return cfg


BAD_PLUGINS = {
    "import": ("import warp as wp\nimport lutbake\nraise ValueError('broken')\n", 3, "cannot be imported: ValueError"),
    "syntax": ("import lutbake\ndef f(:\n", 2, "cannot be imported: SyntaxError"),
    "redefines": (
        "import warp as wp\nimport lutbake\n\n@wp.func\ndef F(f0: float, c: float):\n    return f0\n\n"
        'lutbake.register_fresnel("schlick", F, description="mine")\n',
        8,
        "fresnel 'schlick' is already defined by lutbake",
    ),
    "compile": (
        "import warp as wp\nimport lutbake\n\n@wp.func\ndef F_bad(f0: float, c: float):\n    return f0 + nowhere\n\n"
        'lutbake.register_fresnel("bad", F_bad, description="mine", linear_in_f0=True)\n',
        6,
        "fresnel 'bad' does not compile: Referencing undefined symbol: nowhere",
    ),
    "nothing": ("x = 1\n", None, "registers nothing"),
}


@pytest.mark.parametrize("case", sorted(BAD_PLUGINS))
def test_a_bad_plugin_is_refused_naming_its_file_and_line(tmp_path, case):
    body, line, message = BAD_PLUGINS[case]
    cfg = plugin_config(tmp_path, body)
    with pytest.raises(ConfigError) as e:
        load_configs([cfg])
    text = str(e.value)
    assert str(tmp_path / "bad.py") in text and message in text, text
    if line is not None:
        assert f"line {line}:" in text, text


def test_the_cli_refuses_a_bad_plugin_before_any_work_with_exit_2(tmp_path):
    cfg = plugin_config(tmp_path, BAD_PLUGINS["import"][0])
    r = subprocess.run(
        [sys.executable, "-m", "lutbake", "bake", str(cfg), "--out-dir", str(tmp_path / "out")],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2, r.stderr
    assert f"{tmp_path / 'bad.py'}: line 3: cannot be imported: ValueError: broken" in r.stderr
    assert not (tmp_path / "out").exists()


def test_a_missing_plugin_file_names_the_config_and_key(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('plugins = ["nowhere.py"]\n[[table]]\nname = "t"\nkind = "dfg"\n')
    with pytest.raises(ConfigError, match=r"c.toml: key 'plugins' = 'nowhere.py': no such file"):
        load_configs([cfg])


ENTRY_MODULE = """
import warp as wp
import lutbake

@wp.func
def F_entry(f0: float, c: float):
    return f0 + (1.0 - f0) * (1.0 - c) * (1.0 - c)

lutbake.register_fresnel("entry_sq", F_entry, linear_in_f0=True, description="f0 + (1 - f0)(1 - c)^2")
"""


def test_an_installed_packages_entry_point_registers_its_records(tmp_path):
    """A package installed with ``[project.entry-points."lutbake.plugins"] mine = "entry_pkg"``: a config names its
    Fresnel with no plugins key; ``lutbake list`` lists it."""
    (tmp_path / "entry_pkg.py").write_text(ENTRY_MODULE)
    info = tmp_path / "entry_pkg-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: entry-pkg\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[lutbake.plugins]\nmine = entry_pkg\n")
    cfg = tmp_path / "c.toml"
    cfg.write_text('[[table]]\nname = "t"\nkind = "dfg"\nsize = [4, 4]\nfresnel = "entry_sq"\n')
    code = (
        "import sys; from lutbake.config import load_configs; from lutbake.cli import main\n"
        f"spec, = load_configs([{str(cfg)!r}]); r = spec.records['fresnel']\n"
        "print(r.name, r.origin, r.line)\n"
        "try:\n    main(['list', 'terms'])\nexcept SystemExit:\n    pass\n"
    )
    env = {"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert f"entry_sq {tmp_path / 'entry_pkg.py'} 9" in r.stdout
    assert "entry_sq" in r.stdout.split("Fresnel", 1)[1] and "[plugin" in r.stdout


BRDF_PLUGIN = """
import warp as wp
import lutbake
from lutbake.terms import diffuse

@wp.func
def f_cos_eon(v: wp.vec3, l: wp.vec3, r: float):
    return diffuse.Fd_eon(1.0, l[2], v[2], wp.dot(l, v), r) * l[2]

lutbake.register_brdf("my_eon", f_cos_eon, roughness="alpha", description="EON's terms as a whole BRDF")
"""


def test_a_plugin_brdf_with_eons_terms_fits_eons_ltc(tmp_path):
    """register_brdf: the ltc kind fits a plugin's f(l, v)(n.l) as its own lobes; with EON's terms the matrices and
    the magnitude are lutbake's eon lobe's (whose magnitude the diffuse kind integrates: E = 1, exact albedo)."""
    (tmp_path / "eon.py").write_text(BRDF_PLUGIN)
    lutbake.load_plugin(tmp_path / "eon.py")
    over = ["size=[5, 5]", "fit_samples=16", 'format="exr"', 'dtype="float32"']
    (mine,) = load_configs([preset_path("ltc-ggx")], [*over, 'lobe="my_eon"'])
    (eon,) = load_configs([preset_path("ltc-ggx")], [*over, 'lobe="eon"'])
    a, _, _ = lutbake.bake_table(mine)
    b, _, _ = lutbake.bake_table(eon)
    print("magnitudes", a.data[1, ..., 0], b.data[1, ..., 0])
    print("max |matrix difference|", np.abs(a.data[0] - b.data[0]).max())
    np.testing.assert_allclose(a.data[1, ..., 0], b.data[1, ..., 0], atol=1e-6)  # magnitude: EON's exact albedo
    np.testing.assert_allclose(a.data[0], b.data[0], atol=1e-5)  # the inverse matrices


def test_audit_needs_the_config_that_loads_the_plugin_and_then_names_it(fresnel_example):
    """A fresh process cannot audit the file from its recorded config alone (lutbake runs no code a file names); with
    the config that loads the plugin it passes and names the plugin."""
    from click.testing import CliRunner

    from lutbake.cli import main

    folder, result = fresnel_example
    bare = subprocess.run([sys.executable, "-m", "lutbake", "audit", str(result.path)], capture_output=True, text=True)
    assert bare.returncode == 2 and "baked with a plugin's records" in bare.stderr and "--config" in bare.stderr
    cfg = folder / "dfg_schlick4.toml"
    ok = CliRunner().invoke(main, ["audit", str(result.path), "--config", str(cfg)])
    assert ok.exit_code == 0, ok.output
    assert f"plugin fresnel 'schlick4' from {folder / 'schlick4.py'}" in ok.output and "PASS" in ok.output


def test_specular_3d_with_the_plugins_fresnel_is_its_split_sum(fresnel_example):
    """A Fresnel linear in f0 collapses the f0 slices of specular_3d to the dfg table: E(f0) = f0 R + G."""
    folder, result = fresnel_example
    lutbake.load_plugin(folder / "schlick4.py")
    raw = {"name": "s3", "kind": "specular_3d", "size": [16, 8], "fresnel": "schlick4", "f0_size": 3}
    table, _, _ = lutbake.bake_table(validate_table(raw, "<t>", 0))
    dfg = read_table(result.path).data
    f0 = table.axes[0].values()
    for k, f in enumerate(f0):  # each table within 1e-6 of its integral: the slice, and f0 R + G within (1 + f0) 1e-6
        np.testing.assert_allclose(table.data[k, ..., 0], f * dfg[..., 0] + dfg[..., 1], rtol=0.0, atol=3e-6)


def test_albedo_with_a_plugin_ndf_is_lutbakes_albedo(tmp_path):
    (tmp_path / "mine.py").write_text(
        NDF_PLUGIN.format(name="alb_ggx", cdf=", tan2_from_u=ndf.tan2_from_u_ggx, u_from_tan2=ndf.u_from_tan2_ggx")
    )
    lutbake.load_plugin(tmp_path / "mine.py")
    common = {"kind": "albedo", "size": [8, 8], "interpolation": "off"}
    mine, _, _ = lutbake.bake_table(validate_table({"name": "m", "ndf": "alb_ggx", **common}, "<t>", 0))
    ggx, _, _ = lutbake.bake_table(validate_table({"name": "g", **common}, "<t>", 0))
    np.testing.assert_array_equal(mine.data, ggx.data)
