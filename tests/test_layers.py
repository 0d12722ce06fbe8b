"""The layers of lutbake, written down once: each module sits on a floor and imports only from its own floor or
below (function-level imports too: the edges are tests/test_pipeline.py's import_edges, from every module's ast).

``LAYERS`` is the one place the floors are written down (docs/architecture.md "Layers" shows them, checked below);
nothing in the package imports it. A name covers that module, or that package and everything in it (the root package
``lutbake`` covers only its own __init__); the longest name that covers a module gives its floor. A module no name
covers fails the test, so a new module is placed on purpose.
"""

from __future__ import annotations

import re
from pathlib import Path

from test_pipeline import PACKAGE, REPO, import_edges

ROOT = PACKAGE.name  # "lutbake"

# bottom to top
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    # domain data and the one edge-case policy; ``lutbake`` itself: __version__ (its API is imported lazily)
    (
        "foundation",
        (
            ROOT,
            "errors",
            "textsafe",
            "limits",
            "edge",
            "metals",
            "axes",
            "tolerance",
            "arguments",
            "registry",
            "records",
            "sources",
        ),
    ),
    # where tiles run: handed a plan (runtime.plan.TexelPlan) or a picklable recipe of one, never a kind or a config
    ("runtime", ("runtime",)),
    ("terms", ("terms",)),
    ("sampling", ("sampling",)),  # every quadrature and the per-texel plan
    (
        "integrands",
        ("integrands", "ltc", "environment"),
    ),  # what is integrated (integrands read their quadratures' nodes)
    ("layouts", ("layouts", "value_bounds")),  # engine layouts as data; the value ranges they declare
    ("io", ("io", "table")),  # the Table record, its writers and readers (engine files read their layouts)
    ("kinds", ("kinds", "plugins")),  # the kinds' declarations; the plugins that add records a config may name
    ("config", ("config", "config_file")),  # TOML -> TableSpecs; the config file's own checks
    ("jobs", ("provenance", "sharing", "values_cache", "pipeline", "batch", "preflight")),  # one table / many
    ("commands", ("commands", "validate")),
    ("api", ("api",)),
    ("cli", ("cli", "_entry", "__main__")),
)


def floor_of(module: str, layers=LAYERS, root: str = ROOT) -> int | None:
    """The index in ``layers`` of the floor of ``module`` (a dotted name under ``root``), or None."""
    best, floor = -1, None
    for i, (_, names) in enumerate(layers):
        for name in names:
            full = root if name == root else f"{root}.{name}"
            covers = module == full or (name != root and module.startswith(full + "."))
            if covers and len(full) > best:
                best, floor = len(full), i
    return floor


def upward_imports(root: Path = PACKAGE, layers=LAYERS) -> list[str]:
    """Every import of a module from a higher floor than its own, and every module on no floor, one line each."""
    problems = []
    for module, deps in sorted(import_edges(root).items()):
        mine = floor_of(module, layers, root.name)
        if mine is None:
            problems.append(f"{module}: on no floor (add it to LAYERS in tests/test_layers.py)")
            continue
        for dep, line in sorted(deps.items()):
            theirs = floor_of(dep, layers, root.name)
            if theirs is not None and theirs > mine:
                problems.append(
                    f"{module} (floor {layers[mine][0]}) line {line} imports {dep} (floor {layers[theirs][0]})"
                )
    return problems


def test_no_module_imports_from_a_higher_layer():
    problems = upward_imports()
    assert not problems, "imports from a higher layer:\n" + "\n".join(problems)


def test_every_floor_holds_a_module():
    edges = import_edges()
    for i, (floor, names) in enumerate(LAYERS):
        for name in names:
            full = ROOT if name == ROOT else f"{ROOT}.{name}"
            assert any(floor_of(m) == i and (m == full or m.startswith(full + ".")) for m in edges), (floor, name)


def test_the_architecture_doc_lists_the_floors_in_order():
    """docs/architecture.md "Layers": one row per floor, bottom to top, naming LAYERS' modules (in backticks; a
    package with its slash; other backticked words in parentheses)."""
    text = (REPO / "docs" / "architecture.md").read_text(encoding="utf-8")
    section = text.split("\n## Layers\n", 1)[1].split("\n## ", 1)[0]
    rows = [line.split("|")[1:3] for line in section.splitlines() if line.startswith("| ") and "---" not in line]
    listed = [
        (floor.strip(), tuple(n.rstrip("/") for n in re.findall(r"`([^`]+)`", re.sub(r"\([^)]*\)", "", names))))
        for floor, names in rows[1:]
    ]
    assert listed == [(floor, names) for floor, names in LAYERS]


def test_the_layer_check_finds_a_function_level_upward_import_and_a_module_on_no_floor(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "low").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "low" / "__init__.py").write_text("")
    (pkg / "low" / "a.py").write_text("X = 1\n")
    (pkg / "high.py").write_text("from .low.a import X\n")
    layers = (("low", ("pkg", "low")), ("high", ("high",)))
    assert upward_imports(pkg, layers) == []
    (pkg / "low" / "a.py").write_text("X = 1\n\n\ndef f():\n    from .. import high\n")  # inside a function
    assert upward_imports(pkg, layers) == ["pkg.low.a (floor low) line 5 imports pkg.high (floor high)"]
    (pkg / "stray.py").write_text("")
    assert "pkg.stray: on no floor (add it to LAYERS in tests/test_layers.py)" in upward_imports(pkg, layers)
