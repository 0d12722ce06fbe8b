"""The documentation as a reference: every kind, key and value documented in docs/config.md; the README gives the two
commands and one table engine -> preset -> files -> shader line whose uv formulas are the code's; no page is a diary
(no dates, issue numbers, machine names or load figures outside docs/benchmarks.md); sizes; every relative link and
anchor resolves; docs/benchmarks.md is rendered from the benchmarks' JSON."""

import json
import re
import sys
import unicodedata
from pathlib import Path

import numpy as np
import pytest

from lutbake.kinds import KINDS
from lutbake.kinds.reference import documented

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md"))
README_MAX_BYTES = 10 * 1024
PAGE_MAX_BYTES = 30 * 1024
# the check: dates, issue numbers, machine names and load figures belong to docs/benchmarks.md alone
DIARY = re.compile(r"issue [0-9]+|20[0-9]{2}-[0-9]{2}-[0-9]{2}|EPYC|Xeon|load [0-9]", re.IGNORECASE)
MEASURED_PAGE = DOCS / "benchmarks.md"
ENVIRONMENT = ROOT / "tests" / "data" / "env_studio_64x32.exr"


def test_every_kind_key_and_value_is_documented():
    """In the config pages (docs/config.md, docs/config-<kind>.md) or the key pages rendered from the declarations."""
    doc = "".join(p.read_text() for p in [DOCS / "config.md", *DOCS.glob("config-*.md"), *DOCS.glob("keys/*.md")])
    for kind in KINDS.values():
        assert f"`{kind.name}`" in doc, kind.name
        for key in kind.keys.values():
            assert f"`{key.name}`" in doc, (kind.name, key.name)
            for value in documented(key.choices) or ():  # lutbake's own records (not a plugin another test loaded)
                assert f"`{value}`" in doc, (kind.name, key.name, value)


def test_readme_gives_the_two_commands_and_the_kernel_cache():
    readme = (ROOT / "README.md").read_text()
    assert "make luts" in readme and "make test" in readme
    assert "WARP_CACHE_PATH" in readme and "~/.cache/warp" in readme


@pytest.mark.parametrize("page", [ROOT / "README.md", *PAGES], ids=lambda p: p.name)
def test_reference_pages_are_no_diary(page):
    if page == MEASURED_PAGE:
        pytest.skip("docs/benchmarks.md names machine and date: make bench writes it")
    hits = [m.group(0) for m in DIARY.finditer(page.read_text())]
    assert not hits, f"{page.name}: {hits[:5]} (measured figures go to docs/benchmarks.md, history to git)"


def test_page_sizes():
    assert (ROOT / "README.md").stat().st_size <= README_MAX_BYTES
    too_big = {p.name: p.stat().st_size for p in PAGES if p.stat().st_size > PAGE_MAX_BYTES}
    assert not too_big, f"pages over {PAGE_MAX_BYTES} bytes: {too_big} (split them by topic)"


def slug(heading: str) -> str:
    """GitHub's anchor of a Markdown heading: lower case, punctuation dropped (letters, digits, '_', '-' and spaces
    kept, any script), spaces to '-'."""
    text = heading.strip().lower()
    kept = "".join(c for c in text if c in " -_" or unicodedata.category(c)[0] in "LN")
    return kept.replace(" ", "-")


def anchors(page: Path) -> set[str]:
    seen: dict[str, int] = {}
    out = set()
    in_code = False
    for line in page.read_text().splitlines():
        if line.startswith("```"):
            in_code = not in_code
        if in_code or not line.startswith("#"):
            continue
        base = slug(line.lstrip("#"))
        n = seen.get(base, 0)
        seen[base] = n + 1
        out.add(base if n == 0 else f"{base}-{n}")
    return out


LINK = re.compile(r"\]\(([^)\s]+)\)")


@pytest.mark.parametrize("page", [ROOT / "README.md", *PAGES], ids=lambda p: p.name)
def test_relative_links_and_anchors_resolve(page):
    text = re.sub(r"```.*?```", "", page.read_text(), flags=re.S)
    for target in LINK.findall(text):
        if target.startswith(("http://", "https://", "mailto:")):
            continue
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        assert dest.exists(), f"{page.name}: link to {target}: no such file"
        if anchor and dest.suffix == ".md":
            assert anchor in anchors(dest), f"{page.name}: link to {target}: no such heading in {dest.name}"


def test_no_references_outside_the_repository():
    readme = (ROOT / "README.md").read_text()
    docs = "".join(p.read_text() for p in PAGES)
    for text in (readme, docs):
        # the sibling folder of the development checkout, spelled in two parts so no tool mistakes it for a read
        for outside in ("/".join(("..", "shared")), "seeds/", "lecture 003", "issue-6", "the seed's", "EQUATIONS.md"):
            assert outside not in text, outside


def makefile_presets() -> list[str]:
    text = (ROOT / "Makefile").read_text()
    m = re.search(r"^PRESETS \?=((?:.*\\\n)*.*)$", text, re.M)
    return m.group(1).replace("\\\n", " ").split()


def preset_files(name: str) -> list[str]:
    from lutbake.config import load_config, preset_path
    from lutbake.io.formats import EXTENSIONS

    files = []
    for spec in load_config(preset_path(name)):
        fmt = spec.options.get("format") or "exr"
        files.append(f"{spec.name}_1.dds" if fmt == "ltc_dds" else f"{spec.name}{EXTENSIONS[fmt]}")
    return files


def readme_rows() -> dict[str, str]:
    """The README's engine table: preset name -> its row."""
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Which file for my engine", 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in section.splitlines():
        cells = line.split(" | ")
        if line.startswith("| ") and len(cells) >= 4:
            for preset in re.findall(r"`([a-z0-9-]+)`", cells[1]):
                rows[preset] = line
    return rows


def test_readme_table_names_every_make_luts_preset_and_its_files():
    rows = readme_rows()
    for preset in makefile_presets():
        assert preset in rows, f"README's engine table has no row for preset {preset}"
        for file in preset_files(preset):
            assert file in rows[preset], f"README: preset {preset} writes {file}, its row does not say so"


class V:
    """Just enough of GLSL's vec2 to evaluate the README's uv expressions on numpy arrays."""

    def __init__(self, x, y):
        self.x, self.y = np.asarray(x, np.float64), np.asarray(y, np.float64)

    def _op(self, o, f):
        return V(f(self.x, o.x), f(self.y, o.y)) if isinstance(o, V) else V(f(self.x, o), f(self.y, o))

    def __add__(self, o):
        return self._op(o, np.add)

    def __mul__(self, o):
        return self._op(o, np.multiply)

    def __truediv__(self, o):
        return self._op(o, np.divide)

    __radd__, __rmul__ = __add__, __mul__


def uv_expression(row: str) -> str:
    """The first vec2(...) / float2(...) of a README row's shader line, with a trailing '* a/b + c/d' if any."""
    shader = row.split(" | ")[3]
    m = re.search(r"(vec2<f32>|vec2|float2)\(", shader)
    assert m, row
    depth, i = 0, m.end() - 1
    for i in range(m.end() - 1, len(shader)):
        depth += {"(": 1, ")": -1}.get(shader[i], 0)
        if depth == 0:
            break
    tail = re.match(r"(\s*[*+]\s*[0-9.]+\s*/\s*[0-9.]+)*", shader[i + 1 :]).group(0)
    return "vec2(" + shader[m.end() : i + 1] + tail


UV_PRESETS = [
    "default",
    "filament",
    "filament-corrected",
    "gltf",
    "gltf-charlie",
    "gltf-sheen-e",
    "blender-eevee",
    "unreal",
    "unity-hdrp",
    "unity-hdrp-charlie",
    "godot",
    "bevy",
    "threejs",
    "ltc-ggx",
    "babylon",
    "babylon-openpbr",
    "babylon-fuzz",
]
ROUGHNESS_NAMES = (
    "r",
    "roughness",
    "Roughness",
    "perceptual_roughness",
    "sheenRoughness",
    "perceptualRoughness",
    "alpha",
)
NOV_NAMES = ("NoV", "NdotV", "dotNV")


@pytest.mark.parametrize("preset", UV_PRESETS)
def test_readme_uv_formula_is_the_files_own(preset):
    """The README's uv for a preset, evaluated, equals the axes' uv (lutbake:axes uv_formula, what the GL test samples
    with) at interior points: one formula everywhere, the code's."""
    from lutbake.config import load_config, preset_path
    from lutbake.kinds import lookup_kind

    spec = load_config(preset_path(preset))[0]
    axes = lookup_kind(spec.kind).plan(spec).axes
    rng = np.random.default_rng(7)
    nov, r = rng.uniform(0.1, 0.9, 64), rng.uniform(0.1, 0.9, 64)
    value = {"NoV": nov}
    expect = {}
    for axis in axes:
        if axis.dim in ("x", "y"):
            expect[axis.dim] = axis.uv(value.get(axis.name, r))
    names = {
        "vec2": V,
        "float2": V,
        "sqrt": np.sqrt,
        **dict.fromkeys(ROUGHNESS_NAMES, r),
        **dict.fromkeys(NOV_NAMES, nov),
    }
    expr = uv_expression(readme_rows()[preset]).replace("vec2<f32>", "vec2")
    got = eval(expr, {"__builtins__": {}}, names)  # noqa: S307 - the README's own arithmetic on arrays
    np.testing.assert_allclose(got.x, expect["x"], atol=1e-12, err_msg=f"{preset}: u of {expr}")
    np.testing.assert_allclose(got.y, expect["y"], atol=1e-12, err_msg=f"{preset}: v of {expr}")


def test_benchmarks_page_is_rendered_from_the_json(tmp_path):
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import write_benchmarks_md

    (tmp_path / "luts.json").write_text(
        json.dumps({"machine": "test box", "tables": 3, "computations": 2, "clean": {"wall_s": 1.5, "cpu_s": 2.5}})
    )
    (tmp_path / "report.json").write_text(
        json.dumps({"targets": {"dfg kernel <= 0.3 s": {"value": 0.25, "limit": 0.3, "met": True}}, "cases": {}})
    )
    text = write_benchmarks_md.render(tmp_path)
    assert text.count("**Machine:**") == 1 and text.count("**Date:**") == 1
    assert "test box" in text and "| every table baked, kernels compiled | 1.5 | 2.5 |" in text
    assert "dfg kernel <= 0.3 s" in text
    assert "`ltc.json` missing" in text  # a benchmark not run says so
    assert MEASURED_PAGE.read_text().startswith("# Benchmarks"), "docs/benchmarks.md is the writer's output"
    make = (ROOT / "Makefile").read_text()
    bench = make.split("\nbench:", 1)[1].split("\n\n", 1)[0]
    assert bench.rstrip().endswith("benchmarks/write_benchmarks_md.py"), "make bench renders the page last"


def test_benchmarks_page_renders_the_ltc_area_benchmark_and_the_shaded_fits(tmp_path):
    """bench_ltc's area-light benchmark (every table through the shader, per band, both reflectances) and the other
    lobes' shaded fits reach the page (shapes as bench_ltc and lutbake.validate.ltc_bench.report write them)."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import write_benchmarks_md

    def band(x):
        return {"rel_median": x, "rel_p90": 2 * x, "abs_p90": x / 10}

    tables = {
        n: {"all": band(x), "r 0.05-0.3 / θ 0-30°": band(x)} for n, x in (("published", 0.05), ("two_lobe", 0.02))
    }
    ratio = {"rel_median": 0.4, "abs_p90": 0.2, "bands_worse_in_rel_median_or_abs_p90": []}
    area = {"cases": 4, "lights": 64, "truth": {"estimator": "GGX VNDF"}, "fit_times": {"l3_fit_64x64": {"seconds": 9}}}
    area |= {"f0=1": {"tables": tables, "two_lobe_over_published": ratio}}
    summary = {"all": {"rel_median": 0.1, "rel_p90": 0.3, "abs_max": 0.05}}
    doc = {"lobes": {}, "area_benchmark": area, "area_lights": {"eon": summary}}
    doc["area_lights_shaded"] = {"eon": summary | {"cpu_seconds": 40.0}}
    (tmp_path / "ltc.json").write_text(json.dumps(doc))
    text = write_benchmarks_md.render(tmp_path)
    assert "| all | 0.05 / 0.1 / 0.005 | 0.02 / 0.04 / 0.002 |" in text, text
    assert "two_lobe over published: median relative 0.4, |error| / albedo p90 0.2" in text
    assert "| eon | 0.1 | 0.3 | 0.05 | 0.1 | 0.3 | 0.05 | 40 |" in text, text


CHECK_NAME = re.compile(r"`([a-z_0-9]+\[[a-z_0-9,]+\])`")


def test_every_check_the_docs_name_is_a_registered_check():
    """A parametrised check cited in a page (`weak_white_furnace[ggx]`) is one ``lutbake validate`` runs."""
    from lutbake.validate.checks import CHECKS

    for page in [ROOT / "README.md", *PAGES]:
        for name in CHECK_NAME.findall(page.read_text()):
            if name.split("[", 1)[0] in {n.split("[", 1)[0] for n in CHECKS}:
                assert name in CHECKS, f"{page.name} cites check {name}: lutbake validate has no such check"


def test_models_page_says_what_the_loader_does_with_blinn_phong_and_smith(tmp_path):
    """docs/models.md: Blinn–Phong with a Smith masking is refused at load, and v_cavity is the masking it takes."""
    from lutbake.config import load_config
    from lutbake.errors import ConfigError

    doc = " ".join((DOCS / "models.md").read_text().split())
    assert 'pairing `ndf = "blinn_phong"` with a Smith `masking` is refused at load' in doc
    cfg = tmp_path / "bp.toml"
    for masking, refused in (("smith_height_correlated", True), ("smith_separable", True), ("v_cavity", False)):
        cfg.write_text(f'[[table]]\nname = "bp"\nkind = "dfg"\nndf = "blinn_phong"\nmasking = "{masking}"\n')
        if refused:
            with pytest.raises(ConfigError, match="v_cavity"):
                load_config(cfg)
        else:
            assert load_config(cfg)[0].options["masking"] == "v_cavity"


# a code span that is shader code: a texture read, or arithmetic on what one returned
SHADER_CODE = re.compile(r"texture\w*\(|SampleLevel\(|\b(?:t|AB|fab|t1|t2)\.[xyzwrgb]{1,4}\b|\b(?:mix|lerp)\([xR],")
CODE_SPAN = re.compile(r"`([^`\n]+)`")


def shader_spans(text: str) -> list[str]:
    return [span for span in CODE_SPAN.findall(text) if SHADER_CODE.search(span)]


def engine_lines(presets) -> list[str]:
    """The engine tables' own shader lines (lutbake.layouts EngineTable.shader) of ``presets``, in record order."""
    from lutbake.layouts import TABLES

    return [t.shader for t in TABLES if t.preset in presets and t.shader]


@pytest.fixture(scope="module")
def rendered() -> dict[str, str]:
    """Preset -> the reconstruction text of each of its tables, as the bake records it (lutbake.pipeline.assemble:
    the engine's line first, then the layout's), joined by newlines."""
    from lutbake.config import load_config, presets
    from lutbake.kinds import lookup_kind
    from lutbake.kinds.environment import reconstruction
    from lutbake.layouts import reconstruction_with_engine_line
    from lutbake.pipeline import Computed, assemble

    out = {}
    for name, path in presets().items():
        texts = []
        for spec in load_config(path, environment=ENVIRONMENT):  # the ibl presets name no environment of their own
            if lookup_kind(spec.kind).bake is not None:  # an environment cube (lutbake.pipeline.assemble_cube)
                texts.append(reconstruction_with_engine_line(spec.kind, spec.name, spec.options, reconstruction(spec)))
                continue
            plan = lookup_kind(spec.kind).plan(spec)
            texts.append(assemble(spec, Computed(plan, np.zeros(plan.shape), {}, 0.0, 0.0)).reconstruction)
        out[name] = "\n".join(texts)
    return out


def test_readme_shader_lines_are_the_engine_records(rendered):
    """README's engine table: each row's shader cell holds, as code, every line its presets' engine records declare
    and no other shader code; each such line is the first line of that table's reconstruction (what `lutbake inspect`
    prints first)."""
    seen = set()
    for line in set(readme_rows().values()):
        presets = re.findall(r"`([a-z0-9-]+)`", line.split(" | ")[1])
        cell = line.split(" | ")[3]
        want = engine_lines(presets)
        spans = CODE_SPAN.findall(cell)
        assert all(shader in spans for shader in want), f"README row {presets}: {spans} lacks one of {want}"
        assert set(shader_spans(cell)) <= set(want), f"README row {presets}: {shader_spans(cell)} != records {want}"
        for preset in presets:
            for shader in engine_lines([preset]):
                assert f": {shader}\n" in rendered[preset], (preset, shader)
        seen.update(presets)
    assert seen >= set(UV_PRESETS)


def preset_page_rows() -> dict[str, str]:
    """docs/presets.md's first table (preset, engine, file, how to load it): preset -> its row."""
    rows = {}
    table = (DOCS / "presets.md").read_text().split("| preset | engine | file | how to load it |", 1)[1]
    for line in table.split("\n\n", 1)[0].splitlines():
        m = re.match(r"\| `([a-z0-9-]+)` \| ", line)
        if m and m.group(1) not in rows:
            rows[m.group(1)] = line
    return rows


def test_presets_page_quotes_each_presets_own_reconstruction(rendered):
    """docs/presets.md: a preset row holds its engine record's line, and every piece of shader code in it is part of
    that preset's recorded reconstruction."""
    rows = preset_page_rows()
    for preset, row in rows.items():
        for shader in engine_lines([preset]):
            assert f"`{shader}`" in row, f"docs/presets.md row {preset}: no `{shader}`"
        for span in shader_spans(row):
            assert span in rendered[preset], f"docs/presets.md row {preset}: `{span}` is not in its reconstruction"


def test_engines_page_shader_code_is_a_recorded_reconstruction(rendered):
    """docs/engines.md: every piece of shader code it quotes is part of some preset's recorded reconstruction."""
    text = re.sub(r"```.*?```", "", (DOCS / "engines.md").read_text(), flags=re.S)
    everything = "\n".join(rendered.values())
    wrong = [span for span in shader_spans(text) if span not in everything]
    assert not wrong, f"docs/engines.md quotes shader code no layout record holds: {wrong}"


@pytest.mark.parametrize("preset, fmt", [("unreal", "dds"), ("godot", "exr"), ("blender-eevee", "h")])
def test_inspect_prints_the_engine_line_first(tmp_path, capsys, preset, fmt):
    """`lutbake inspect` of a preset's file (any format: the EXR header, a DDS's or header's sidecar) prints the
    engine record's shader line as the first line of the reconstruction: the README's line for that preset."""
    from lutbake.cli import main
    from lutbake.config import load_config, preset_path
    from lutbake.io.formats import write_table
    from lutbake.kinds import lookup_kind
    from lutbake.pipeline import Computed, assemble

    spec = load_config(preset_path(preset))[0]
    plan = lookup_kind(spec.kind).plan(spec)
    table = assemble(spec, Computed(plan, np.full(plan.shape, 0.5), {}, 0.0, 0.0))
    path = write_table(table, tmp_path, fmt, "half" if fmt == "dds" else "float32")
    with pytest.raises(SystemExit) as ended:
        main(["inspect", str(path)])
    assert ended.value.code == 0
    out = capsys.readouterr().out.splitlines()
    (shader,) = engine_lines([preset])
    assert out[out.index("reconstruction:") + 1].endswith(f": {shader}"), out[out.index("reconstruction:") + 1]
    assert f"`{shader}`" in readme_rows()[preset]


CONFIG_PAGES = [DOCS / "config.md", *sorted(DOCS.glob("config-*.md"))]
KEY_PAGES = DOCS / "keys"


def config_sections() -> dict[str, str]:
    """'common' -> the keys of every kind; kind name -> that kind's section, from the config pages."""
    text = "\n".join(p.read_text() for p in CONFIG_PAGES)
    sections = {}
    for part in re.split(r"^#+ ", text, flags=re.M):
        m = re.match(r"Kind `([a-z_0-9]+)`", part)
        if m:
            sections[m.group(1)] = part
        elif part.startswith("Keys of every kind"):
            sections["common"] = part
    return sections


def key_rows(section: str) -> dict[str, list[list[str]]]:
    """A section's one-key table rows: key -> the rows naming it alone (cells: key, type, default, allowed, meaning)."""
    rows: dict[str, list[list[str]]] = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split(" | ")]
        m = re.fullmatch(r"`([a-z_0-9]+)`", cells[0]) if line.startswith("| `") and len(cells) == 5 else None
        if m:
            rows.setdefault(m.group(1), []).append(cells)
    return rows


def test_config_pages_agree_with_the_key_declarations():
    """Each key row of docs/config*.md (a kind's section, or the keys of every kind, which are `dfg`'s) appears once
    and lists exactly the key's declared values and its declared default: the prose reference cannot drift."""
    import tomllib

    sections = config_sections()
    assert set(KINDS) <= set(sections), set(KINDS) - set(sections)
    for where, section in sections.items():
        kind = KINDS["dfg" if where == "common" else where]
        for name, found in key_rows(section).items():
            assert len(found) == 1, f"config: {where} lists key {name} {len(found)} times"
            key = kind.keys.get(name)
            assert key is not None, f"config: {where} documents key {name}, which kind {kind.name} does not declare"
            _, _, default, allowed, _ = found[0]
            own = documented(key.choices)
            if own and not allowed.startswith("as "):
                values = set(re.findall(r"`([^`]+)`", allowed))
                assert values == set(own), (where, name, sorted(values ^ set(own)))
            try:
                written = tomllib.loads(f"x = {default.strip('`')}")["x"]
            except tomllib.TOMLDecodeError:
                continue  # prose ("required", "from the storage")
            declared = list(key.default) if isinstance(key.default, tuple) else key.default
            assert written == declared, (where, name, default, key.default)


def test_key_pages_are_rendered_from_the_declarations():
    """docs/keys/<kind>.md is lutbake.kinds.reference.markdown(kind) (`python -m lutbake.kinds.reference docs/keys`),
    one page per kind, and names every key and value (what `lutbake list keys KIND` prints)."""
    from lutbake.kinds.reference import markdown

    assert {p.stem for p in KEY_PAGES.glob("*.md")} == set(KINDS)
    for kind in KINDS.values():
        page = (KEY_PAGES / f"{kind.name}.md").read_text()
        assert page == markdown(kind), f"docs/keys/{kind.name}.md is stale: python -m lutbake.kinds.reference docs/keys"
        for key in kind.keys.values():
            assert f"| `{key.name}` |" in page
            assert all(f"`{value}`" in page for value in documented(key.choices) or ())


def test_every_entry_lutbake_list_prints_is_documented():
    """Each preset (`lutbake list presets`) has its row in docs/presets.md or a page of its own family, each format
    (`lutbake list formats`) is in docs/formats.md, each kind (`lutbake list kinds`) in docs/kinds.md and has its key
    page."""
    from lutbake.config import presets
    from lutbake.io.formats import ALL_FORMATS

    pages = {name: (DOCS / name).read_text() for name in ("presets.md", "formats.md", "kinds.md", "ltc.md")}
    for preset in presets():
        assert f"`{preset}`" in pages["presets.md"] + pages["ltc.md"], preset
    for fmt in ALL_FORMATS:
        assert f"`{fmt}`" in pages["formats.md"], fmt
    for kind in KINDS:
        assert f"`{kind}`" in pages["kinds.md"] and (KEY_PAGES / f"{kind}.md").is_file(), kind
