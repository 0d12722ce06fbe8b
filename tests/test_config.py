"""Bad configs are rejected before any kernel runs, with the file, key, value and allowed values."""

import pytest

from lutbake.config import load_config, load_configs, parse_overrides, preset_path
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
    assert spec.options["size"] == [16, 8]
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
