"""Bad configs are rejected before any kernel runs, with the file, key, value and allowed values."""

from types import MappingProxyType

import numpy as np
import pytest

from lutbake.config import TableSpec, load_config, load_configs, parse_overrides, preset_path, validate_table
from lutbake.errors import ConfigError

GOOD = """
[[table]]
name = "dfg"
kind = "dfg"
size = [16, 8]
"""


def write(tmp_path, text, name="c.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_defaults_are_filled_in(tmp_path):
    (spec,) = load_configs([write(tmp_path, GOOD)])
    assert spec.options["size"] == (16, 8)  # frozen: a tuple
    assert spec.options["ndf"] == "ggx"
    assert spec.options["masking"] == "smith_height_correlated"
    assert spec.options["layout"] == "scale_bias"
    assert spec.options["roughness"] == "perceptual"
    assert spec.options["texel"] == "center"
    assert spec.options["samples"] is None


@pytest.mark.parametrize(
    "line, key, fragment",
    [
        ('kind = "dfgg"', "kind", "dfg"),
        ('ndf = "phong"', "ndf", "ggx, beckmann"),
        ('masking = "smith"', "masking", "smith_height_correlated"),
        ('layout = "rgba"', "layout", "scale_bias, multiscatter"),
        ('dtype = "float16"', "dtype", "float32, half"),
        ('roughness = "linear"', "roughness", "perceptual, alpha"),
        ("samples = 0", "samples", ">= 1"),
        ("samples = -5", "samples", ">= 1"),
        ("samples = 1.5", "samples", "integer"),
        ("size = [0, 128]", "size", ">= 1"),
        ("size = [128]", "size", "two integers"),
        ("nov_range = [0.0, 1.5]", "nov_range", "<= 1"),
        ("roughness_range = [-0.1, 1.0]", "roughness_range", "0 <="),
        ("bogus = 1", "bogus", "not a key"),
        ('name = "../../x"', "name", "letters"),
        ("size = [100000, 100000]", "size", "GiB"),
    ],
)
def test_bad_key_names_file_key_and_allowed(tmp_path, line, key, fragment):
    text = (
        GOOD.replace('kind = "dfg"', line)
        if line.startswith("kind")
        else (GOOD.replace('name = "dfg"', line) if line.startswith("name") else GOOD + line + "\n")
    )
    if line.startswith("size"):
        text = GOOD.replace("size = [16, 8]", line)
    p = write(tmp_path, text)
    with pytest.raises(ConfigError) as e:
        load_configs([p])
    msg = str(e.value)
    assert str(p) in msg and f"'{key}'" in msg and fragment in msg, msg


def test_missing_file_and_invalid_toml(tmp_path):
    with pytest.raises(ConfigError, match="no such config file"):
        load_configs([tmp_path / "nope.toml"])
    with pytest.raises(ConfigError, match="invalid TOML"):
        load_configs([write(tmp_path, "[[table]\nname=")])


def test_duplicate_names_across_files_are_rejected(tmp_path):
    a, b = write(tmp_path, GOOD, "a.toml"), write(tmp_path, GOOD, "b.toml")
    with pytest.raises(ConfigError, match="duplicate table name"):
        load_configs([a, b])


def test_overrides_apply_to_all_or_one_table(tmp_path):
    two = GOOD + GOOD.replace('name = "dfg"', 'name = "other"')
    p = write(tmp_path, two)
    specs = load_configs([p], ["samples=64", "other.layout=multiscatter"])
    assert [s.options["samples"] for s in specs] == [64, 64]
    assert [s.options["layout"] for s in specs] == ["scale_bias", "multiscatter"]
    with pytest.raises(ConfigError, match="names no table"):
        load_configs([p], ["nothere.samples=3"])
    assert parse_overrides(["size=[4, 4]"]) == [(None, "size", [4, 4])]


def test_vndf_needs_ggx(tmp_path):
    p = write(tmp_path, GOOD + 'ndf = "beckmann"\nestimator = "sobol_vndf"\n')
    with pytest.raises(ConfigError, match="visible-normal"):
        load_configs([p])


def test_spec_toml_round_trips(tmp_path):
    import tomllib

    (spec,) = load_configs([write(tmp_path, GOOD)])
    again = tomllib.loads(spec.toml())["table"][0]
    assert again["size"] == [16, 8] and again["kind"] == "dfg"


def test_every_key_of_every_kind_is_documented():
    from pathlib import Path

    from lutbake.kinds import KINDS

    docs = Path(__file__).parent.parent / "docs"
    for kind in KINDS.values():  # its page (docs/config-<kind>.md) and its key page rendered from the declarations
        page = (docs / f"config-{kind.name}.md").read_text()
        assert page.startswith(f"# Kind `{kind.name}`"), kind.name
        doc = page + (docs / "config.md").read_text() + (docs / "keys" / f"{kind.name}.md").read_text()
        for key in kind.keys:
            assert f"`{key}`" in doc, (kind.name, key)


def test_shipped_configs_are_valid():
    from pathlib import Path

    paths = sorted((Path(__file__).parent.parent / "configs").glob("*.toml"))
    specs = load_configs(paths)
    assert {s.kind for s in specs} >= {"dfg", "albedo", "albedo_avg", "specular_3d"}


def test_unknown_names_get_the_nearest_name(tmp_path):
    """Issue 39: `--preset filamnet` listed 23 names without "did you mean"; the same for kinds, keys and values."""
    with pytest.raises(ConfigError, match=r"unknown preset 'filamnet'; did you mean 'filament'\?"):
        preset_path("filamnet")
    for line, fragment in (
        ('kind = "dgf"', "did you mean 'dfg'?"),
        ("sampels = 64", "did you mean 'samples'?"),
        ('layout = "multiscater"', "did you mean 'multiscatter'?"),
    ):
        p = tmp_path / "c.toml"
        p.write_text(f'[[table]]\nname = "t"\n{line}\n' + ("" if "kind" in line else 'kind = "dfg"\n'))
        with pytest.raises(ConfigError) as e:
            load_config(p)
        assert fragment in str(e.value), str(e.value)


def test_a_bad_set_argument_is_blamed_not_the_preset():
    """`--set sampels=2048` named presets/default.toml, a file the user never wrote."""
    with pytest.raises(ConfigError) as e:
        load_configs([preset_path("default")], ["sampels=2048"])
    text = str(e.value)
    assert text.startswith("--set sampels=2048: ") and "default.toml" not in text, text
    assert "did you mean 'samples'?" in text
    with pytest.raises(ConfigError) as e:
        load_configs([preset_path("default")], ["samples=0"])
    assert str(e.value).startswith("--set samples=0: "), str(e.value)


# ----------------------------------------------------------------- the Python API checks what it is handed

SMALL = '[[table]]\nname = "t"\nkind = "dfg"\nsize = [8, 4]\nsamples = 48\n'


def test_a_loaded_spec_is_immutable_all_the_way_down(tmp_path):
    """A validated spec's size list was mutable: [16384, 16384] after load_config bypassed the 2^26-texel cap."""
    import dataclasses

    (spec,) = load_config(write(tmp_path, SMALL))
    with pytest.raises(TypeError):
        spec.options["size"][0] = 16384
    with pytest.raises(TypeError):
        spec.options["size"] = [16384, 16384]
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.name = "../x"
    handmade = TableSpec("h", "dfg", {"size": [8, 4], "nested": {"a": [1]}}, "<api>", 0)
    with pytest.raises(TypeError):
        handmade.options["nested"]["a"][0] = 2


def test_a_spec_past_the_texel_cap_is_refused_at_the_api_before_any_kernel(tmp_path, monkeypatch):
    """A spec whose values were swapped after validation (or made by hand) goes through the config's checks where it
    enters bake / bake_table: the texel cap (lowered here so the old code's bake of it stays cheap) refuses it."""
    import lutbake
    from lutbake import config

    (spec,) = load_config(write(tmp_path, SMALL))
    object.__setattr__(spec, "options", MappingProxyType({**spec.options, "size": (16, 8)}))
    monkeypatch.setattr(config, "MAX_TEXELS", 64)
    for call in (lambda: lutbake.bake([spec], write=False), lambda: lutbake.bake_table(spec)):
        with pytest.raises(ConfigError, match=r"key 'size' = \[16, 8\].*128 texels"):
            call()


@pytest.mark.parametrize("name", ["../../x", "a/b", "", "NUL", "con", "Com1", "lpt9", "nul.txt", "x.", "x "])
def test_a_hand_made_spec_is_named_as_a_config_is(name):
    """TableSpec("../../x", ...) was written at out_dir/../../../../x.npy; names Windows reserves are refused too."""
    with pytest.raises(ConfigError, match="name"):
        TableSpec(name, "dfg", {"size": [8, 4]}, "<api>", 0)


@pytest.mark.parametrize("name, why", [("NUL", "Windows reserves"), ("com7", "Windows reserves"), ("a.b", "letters")])
def test_a_config_name_windows_cannot_use_is_refused_saying_why(tmp_path, name, why):
    with pytest.raises(ConfigError, match=why):
        load_config(write(tmp_path, SMALL.replace('"t"', f'"{name}"')))


def test_bake_takes_one_config_path_as_a_str_and_fills_a_hand_made_spec(tmp_path):
    """bake("cfg.toml") read each character as a config path; a hand-made spec without its defaults: KeyError."""
    import lutbake

    cfg = write(tmp_path, SMALL)
    (r,) = lutbake.bake(str(cfg), write=False)
    assert r.name == "t" and r.table.data.shape == (4, 8, 2)
    (h,) = lutbake.bake(TableSpec("h", "dfg", {"size": [8, 4], "samples": 48}, "<api>", 0), write=False)
    assert h.spec.options["ndf"] == "ggx" and np.array_equal(h.table.data, r.table.data)


def _api_calls(cfg):
    import lutbake

    return {
        "bake(5)": lambda: lutbake.bake(5),
        "bake([5])": lambda: lutbake.bake([cfg, 5]),
        "bake(b'')": lambda: lutbake.bake(b"c.toml"),
        "bake(out_dir=5)": lambda: lutbake.bake(cfg, out_dir=5),
        "bake(workers='4')": lambda: lutbake.bake(cfg, workers="4"),
        "bake(workers=0)": lambda: lutbake.bake(cfg, workers=0),
        "bake(device='gpu')": lambda: lutbake.bake(cfg, device="gpu"),
        "bake(overrides=5)": lambda: lutbake.bake(cfg, overrides=5),
        "bake(overrides=[5])": lambda: lutbake.bake(cfg, overrides=[5]),
        "bake(write='no')": lambda: lutbake.bake(cfg, write="no"),
        "bake(on_result=3)": lambda: lutbake.bake(cfg, on_result=3),
        "bake(fmt=3)": lambda: lutbake.bake(cfg, fmt=3),
        "bake(scheduler=3)": lambda: lutbake.bake(cfg, scheduler=3),
        "bake(report=3)": lambda: lutbake.bake(cfg, report=3),
        "bake_table(path)": lambda: lutbake.bake_table(str(cfg)),
        "bake_table(workers=-1)": lambda: lutbake.bake_table(load_config(cfg)[0], workers=-1),
        "load_config(5)": lambda: load_config(5),
        "load_config(None)": lambda: load_config(None),
        "load_config(overrides=[1])": lambda: load_config(cfg, overrides=[1]),
        "load_configs(5)": lambda: load_configs(5),
        "load_configs([None])": lambda: load_configs([None]),
        "TableSpec(options=list)": lambda: TableSpec("a", "dfg", [1, 2], "<api>", 0),
        "TableSpec(kind=3)": lambda: TableSpec("a", 3, {}, "<api>", 0),
        "TableSpec(name != options)": lambda: TableSpec("a", "dfg", {"name": "b"}, "<api>", 0),
        "TableSpec(unknown key)": lambda: lutbake.bake_table(TableSpec("a", "dfg", {"sizes": [8, 4]}, "<api>", 0)),
        "TableSpec(unknown kind)": lambda: lutbake.bake_table(TableSpec("a", "dgf", {}, "<api>", 0)),
        "validate_table(list)": lambda: validate_table([1, 2], "<api>", 0),
    }


CALLS = list(_api_calls(None))


@pytest.mark.parametrize("call", CALLS)
def test_every_wrong_input_of_the_api_raises_one_documented_error(tmp_path, call):
    """Wrong types raised bare TypeError / KeyError / AttributeError from deep inside; now lutbake.ConfigError (what
    docs/batch.md documents), one line naming what is wrong, before any kernel runs."""
    import lutbake

    fn = _api_calls(write(tmp_path, SMALL))[call]
    with pytest.raises(lutbake.ConfigError) as e:
        fn()
    text = str(e.value)
    assert "\n" not in text and len(text) < 400, text
    assert "lutbake." in text or "TableSpec" in text or "<api>" in text, text
