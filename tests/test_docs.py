"""Every registered kind, key and allowed value is documented in docs/config.md; README has the two commands."""

from pathlib import Path

from lutbake.kinds import KINDS

ROOT = Path(__file__).resolve().parents[1]


def test_every_kind_key_and_value_is_documented():
    doc = (ROOT / "docs" / "config.md").read_text()
    for kind in KINDS.values():
        assert f"`{kind.name}`" in doc, kind.name
        for key in kind.keys.values():
            assert f"`{key.name}`" in doc, (kind.name, key.name)
            for value in key.choices or ():
                assert f"`{value}`" in doc, (kind.name, key.name, value)


def test_readme_gives_the_two_commands():
    readme = (ROOT / "README.md").read_text()
    assert "make luts" in readme and "make test" in readme
