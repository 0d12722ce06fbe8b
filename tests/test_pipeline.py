"""The one pipeline: every kind bakes under two estimators that agree; the reported config bugs exit 2 naming the
key before any kernel runs; api.bake skips up-to-date outputs like the CLI; the import layers point one way."""

from __future__ import annotations

import ast
import dataclasses
import json
import pickle
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import lutbake
from lutbake import pipeline
from lutbake.cli import main
from lutbake.kinds import KINDS
from lutbake.runtime.executor import execute_tiles

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "lutbake"


# Two estimators per kind, on small grids at moderate roughness (QMC noise ~ 1/N there). Each entry:
# (kind, options, estimator a, estimator b, tolerance on max |a - b|).
AGREEMENT_TOL_QMC = 2.0e-3  # 4096 scrambled Sobol' points of a bounded integrand, worst texel
AGREEMENT_TOL_ANISO = 5.0e-3  # lobe sampling vs cosine-weighted l, 65536 points each (measured 1.9e-3)
AGREEMENT_TOL_LTC_ANISO = 1.0e-2  # measured 6.2e-3 (magnitude, the grazing row's cosine-weighted l), 2.3e-3 on M
AGREEMENT = [
    ("dfg", {"size": [6, 4], "roughness_range": [0.3, 1.0]}, "gauss_legendre", "sobol_vndf", AGREEMENT_TOL_QMC),
    (
        "albedo",
        {"size": [6, 4], "roughness_range": [0.3, 1.0], "nov_range": [0.3, 1.0], "samples": 16384},
        "gauss_legendre",
        "sobol_ndf",
        AGREEMENT_TOL_QMC,
    ),
    (
        "albedo_avg",
        {"roughness_size": 4, "roughness_range": [0.3, 1.0], "mu_order": 8},
        "gauss_legendre",
        "sobol_vndf",
        AGREEMENT_TOL_QMC,
    ),
    (
        "specular_3d",
        {"size": [4, 3], "f0_size": 2, "roughness_range": [0.3, 1.0]},
        "gauss_legendre",
        "sobol_vndf",
        AGREEMENT_TOL_QMC,
    ),
    # the panelled rule (view azimuth averaged inside the integrand) vs the lobe-sampling QMC
    (
        "specular_aniso",
        {"size": [4, 3], "anisotropy_size": 2, "roughness_range": [0.4, 1.0], "samples": 65536},
        "gauss_legendre",
        "sobol",
        AGREEMENT_TOL_ANISO,
    ),
    # cosine-weighted l converges slowly for the peaked lobe at grazing view: measured 2.0e-2 at 4096 points,
    # 1.9e-3 at 65536 (2.7e-3 for Ashikhmin-Shirley)
    (
        "specular_aniso",
        {"size": [4, 3], "anisotropy_size": 2, "roughness_range": [0.4, 1.0], "samples": 65536},
        "sobol",
        "sobol_cosine",
        AGREEMENT_TOL_ANISO,
    ),
    (
        "diffuse",
        {"size": [4, 3], "model": "oren_nayar", "sigma_range": [0.2, 1.0], "samples": 4096},
        "gauss_legendre",
        "sobol_cosine",
        AGREEMENT_TOL_QMC,
    ),
    (
        "diffuse_3d",
        {"size": [3, 2], "f0_size": 2, "sigma_range": [0.3, 1.0], "samples": 1024},
        "gauss_legendre",
        "sobol_cosine",
        5.0e-3,
    ),
    # LTC: magnitude / fresnel by GL panels vs Sobol' NDF sampling (16384 points), and the fits that depend on them
    # through Heitz's metric: measured 2.0e-3 (magnitude at the grazing row), 1.6e-3 on the matrix coefficients
    ("ltc", {"size": [4, 4], "samples": 16384}, "gauss_legendre", "sobol_ndf", 5.0e-3),
    # anisotropic LTC: the anisotropic texels' magnitude / fresnel by VNDF Sobol' vs cosine-weighted Sobol' (65536
    # each; the isotropic ones are GL in both), alpha >= 0.3, and the fits that depend on them (frame "average": the
    # "free" frame's two extra parameters leave the grazing texels' L3 objective flat, their M moves by 0.07)
    (
        "ltc_aniso",
        {"size": 3, "alpha_min": 0.3, "samples": 65536, "fit_frame": "average"},
        "sobol",
        "sobol_cosine",
        AGREEMENT_TOL_LTC_ANISO,
    ),
    # f itself (values 0.09 .. 0.6): the m-integral by GL panels vs Sobol' facet normals (measured 2.0e-3 at 65536)
    (
        "btf",
        {"size": [4, 4], "phi_size": 2, "sigma_size": 2, "sigma_range": [0.3, 1.0], "samples": 65536},
        "gauss_legendre",
        "sobol_ndf",
        AGREEMENT_TOL_ANISO,
    ),
    # the dielectric kinds: panelled GL split at every kink vs GGX visible-normal Sobol' (16384 points; the averages
    # 4096, AGREEMENT_TOL_QMC's count: measured 9.0e-5 over three seeds), eta both sides
    (
        "dielectric",
        {"size": [4, 3], "ior_size": 2, "ior_range": [0.7, 1.5], "roughness_range": [0.3, 1.0]},
        "gauss_legendre",
        "sobol_vndf",
        AGREEMENT_TOL_QMC,
    ),
    (
        "dielectric_avg",
        {
            "roughness_size": 3,
            "ior_size": 2,
            "ior_range": [0.7, 1.5],
            "roughness_range": [0.3, 1.0],
            "mu_order": 6,
            "samples": 4096,
        },
        "gauss_legendre",
        "sobol_vndf",
        AGREEMENT_TOL_QMC,
    ),
]


@pytest.mark.parametrize("kind, options, a, b, tol", AGREEMENT, ids=[f"{k}-{a}-{b}" for k, _, a, b, _ in AGREEMENT])
def test_two_estimators_agree(bake, kind, options, a, b, tol):
    gl = {k: v for k, v in options.items() if k != "samples" or a != "gauss_legendre"}
    ta = bake(gl, kind=kind, estimator=a)
    tb = bake(options, kind=kind, estimator=b)
    assert ta.attributes["estimator"] != tb.attributes["estimator"]
    np.testing.assert_allclose(tb.data, ta.data, rtol=0, atol=tol)


# kinds with one estimator: the environment cubes' exact quadrature (its recorded per-mip error estimate is checked
# against a finer bake in tests/test_environment.py)
# kinds whose two estimators are compared elsewhere (the environment's harmonics against its pyramid quadrature)
ELSEWHERE = {
    "environment_specular": "tests/test_environment.py::test_harmonic_and_quadrature_agree_on_a_real_environment",
    "environment_irradiance": "tests/test_environment.py::test_harmonic_and_quadrature_agree_on_a_real_environment",
}


def test_every_kind_is_checked_under_two_estimators():
    assert {k for k, *_ in AGREEMENT} == set(KINDS) - set(ELSEWHERE)
    assert all({"harmonic", "quadrature"} <= set(KINDS[k].keys["estimator"].choices) for k in ELSEWHERE)


def test_dfg_mirror_branch_is_exact(bake):
    """alpha -> 0 is the mirror: E = 1 for F = 1 (albedo) at any NoV > 0, grazing included (the ALPHA_MIN clamp gave
    0.89 at NoV = 1e-4); the split-sum channels are (1 - Fc(NoV), Fc(NoV))."""
    t = bake(kind="albedo", size=[8, 4], roughness="alpha", texel="endpoint", nov_range=[0.0, 1.0])
    np.testing.assert_array_equal(t.data[0, :, 0], 1.0)
    d = bake(kind="dfg", size=[8, 4], roughness="alpha", texel="endpoint")
    nov = d.axes[1].values().astype(np.float64)
    fc = (1.0 - nov) ** 5
    np.testing.assert_allclose(d.data[0, :, 0], 1.0 - fc, rtol=0, atol=1e-6)
    np.testing.assert_allclose(d.data[0, :, 1], fc, rtol=0, atol=1e-6)
    assert "mirror" in d.attributes["alpha_policy"]


def test_btf_edge_policy_is_the_same_on_light_and_view(bake):
    """Endpoint texels: the light and view axes list (and integrate) the same clamped cosine, so every block is
    symmetric (reciprocity) up to the edge."""
    t = bake(kind="btf", size=[5, 5], phi_size=2, sigma_size=1, model="oren_nayar", texel="endpoint")
    axes = {a.name: a for a in t.axes}
    np.testing.assert_array_equal(axes["NoL"].values(), axes["NoV"].values())
    block = t.data[0, :5, :, 0]
    np.testing.assert_allclose(block, block.T, rtol=1e-6, atol=0)
    assert float(block[0, 0]) > 0.0  # the grazing corner is the BRDF there, not a stored 0


def test_sigma_axis_lists_alpha_per_index(bake):
    t = bake(kind="diffuse", size=[2, 3], model="lambert", sigma_to_alpha="sigma_squared")
    sig = next(a for a in t.axes if a.name == "sigma").describe()
    np.testing.assert_allclose(sig["alpha"], np.asarray(sig["values"]) ** 2, rtol=1e-6)


def test_diffuse_bakes_as_npy_from_the_cli(tmp_path):
    """`lutbake bake configs/diffuse.toml --format npy` (reported: exit 2, 'not a key of kind diffuse')."""
    cfg = tmp_path / "d.toml"
    cfg.write_text('[[table]]\nname = "d"\nkind = "diffuse"\nsize = [4, 3]\nmodel = "lambert"\n')
    r = CliRunner().invoke(main, ["bake", str(cfg), "--format", "npy", "--out-dir", str(tmp_path / "o")])
    assert r.exit_code == 0, r.output
    assert np.load(tmp_path / "o" / "d.npy").shape == (3, 4, 1)
    assert json.loads((tmp_path / "o" / "d.npy.json").read_text())["lutbake"]["kind"] == "diffuse"


def test_aniso_with_a_sheen_layout_exits_2_naming_the_key(tmp_path, monkeypatch):
    """kind = "specular_aniso" + layout = "charlie" (reported: KeyError while planning, exit 1)."""
    import lutbake.kinds.specular_aniso as aniso

    monkeypatch.setattr(aniso, "plan", None)  # no kernel may run: validation alone must refuse it
    cfg = tmp_path / "a.toml"
    cfg.write_text('[[table]]\nname = "a"\nkind = "specular_aniso"\nlayout = "charlie"\n')
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(tmp_path / "o")])
    assert r.exit_code == 2, r.output
    assert "key 'layout'" in r.output and "charlie" in r.output
    assert not (tmp_path / "o").exists()


def test_api_bake_skips_up_to_date_outputs_unless_forced(spec, tmp_path):
    s = spec(kind="diffuse", size=[3, 2], model="lambert")
    first = lutbake.bake([s], out_dir=tmp_path)
    assert [r.status for r in first] == ["baked"] and first[0].path.is_file()
    again = lutbake.bake([s], out_dir=tmp_path)
    assert [r.status for r in again] == ["skipped"]
    forced = lutbake.bake([s], out_dir=tmp_path, force=True)
    assert [r.status for r in forced] == ["baked"]
    np.testing.assert_array_equal(forced[0].table.data, first[0].table.data)


def test_a_table_is_planned_once_per_process(spec, monkeypatch, tmp_path):
    """The png16 shape check before the run, the bake and a --cache hit share one plan per table
    (lutbake.batch.Job.plan), built by its kind through lutbake.config.kind_of (lutbake.pipeline.plan_of)."""
    real, built = pipeline.kind_of, []

    def counting(s):
        kind = real(s)

        def plan(s, **kw):
            built.append(s.name)
            return kind.plan(s, **kw)

        return dataclasses.replace(kind, plan=plan)

    monkeypatch.setattr(pipeline, "kind_of", counting)
    s = spec(kind="diffuse", size=[3, 2], model="lambert", format="png16")
    first = lutbake.bake([s], out_dir=tmp_path / "a", cache_dir=tmp_path / "cache")
    assert [r.status for r in first] == ["baked"] and built == ["t"]
    again = lutbake.bake([s], out_dir=tmp_path / "b", cache_dir=tmp_path / "cache")  # its values from the cache
    assert [r.status for r in again] == ["baked"] and built == ["t", "t"]


def test_a_plan_source_ships_each_kinds_plan_function_by_reference(spec):
    """A cluster worker builds a table's plan from what the client pickled (lutbake.runtime.plan.PlanSource): the
    kind's module-level plan function bound to the spec, no kind looked up by its name there. Every kind's plan
    function pickles by reference, and the plan built from the shipped source bakes the client's bits."""
    for name, kind in KINDS.items():
        assert pickle.loads(pickle.dumps(kind.plan)) is kind.plan, name
    s = spec(kind="dfg", size=[4, 3])
    shipped = pickle.loads(pickle.dumps(pipeline.plan_source(s)))
    assert shipped.name == "t" and shipped.build.func is KINDS["dfg"].plan
    np.testing.assert_array_equal(execute_tiles(shipped.build()), execute_tiles(pipeline.plan_of(s)))


# ---- imports: no cycle, module by module ------------------------------------------------------------------------


def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def import_edges(root: Path = PACKAGE) -> dict[str, dict[str, int]]:
    """Module -> {a module of the package it imports: the line of the first statement that does}: every ``import`` /
    ``from ... import`` statement of the file, at any depth (function-level imports too), relative or absolute;
    ``from pkg import mod`` is an edge to pkg.mod. An import of a.b.c also runs the packages a.b and a (their
    __init__): edges to those, except the importer's own packages (already initialised when it runs)."""
    files = {_module_name(p, root): p for p in sorted(root.rglob("*.py"))}
    edges: dict[str, dict[str, int]] = {}
    for me, path in files.items():
        is_pkg = path.name == "__init__.py"
        targets = []
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets += [(a.name, node.lineno) for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = me.split(".")[: len(me.split(".")) - node.level + (1 if is_pkg else 0)]
                    module = ".".join(base + ([node.module] if node.module else []))
                else:
                    module = node.module or ""
                targets += [
                    (f"{module}.{a.name}" if f"{module}.{a.name}" in files else module, node.lineno) for a in node.names
                ]
        deps: dict[str, int] = {}
        for t, line in targets:
            while t and t not in files:
                t = t.rpartition(".")[0]  # an attribute of a module: the module
            while t:
                if t != me and not me.startswith(t + "."):
                    deps[t] = min(deps.get(t, line), line)
                t = t.rpartition(".")[0]
        edges[me] = deps
    return edges


def import_graph(root: Path = PACKAGE) -> dict[str, set[str]]:
    """Module -> the package's modules it imports (import_edges without the lines)."""
    return {me: set(deps) for me, deps in import_edges(root).items()}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle [a, b, ..., a] of ``graph``, or None (depth-first search, white/grey/black)."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(v: str) -> list[str] | None:
        state[v] = 1
        stack.append(v)
        for w in sorted(graph[v]):
            if state.get(w) == 1:
                return stack[stack.index(w) :] + [w]
            if w not in state and (found := visit(w)):
                return found
        stack.pop()
        state[v] = 2
        return None

    for v in sorted(graph):
        if v not in state and (found := visit(v)):
            return found
    return None


def import_depth(graph: dict[str, set[str]]) -> int:
    """The longest chain of imports (modules on it) of an acyclic ``graph``."""
    memo: dict[str, int] = {}

    def depth(v: str) -> int:
        if v not in memo:
            memo[v] = 1 + max((depth(w) for w in graph[v]), default=0)
        return memo[v]

    return max(depth(v) for v in graph)


def test_the_import_graph_of_lutbake_has_no_cycle():
    graph = import_graph()
    assert len(graph) > 100 and graph["lutbake.api"] >= {"lutbake.batch", "lutbake.pipeline"}
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + " -> ".join(cycle)
    assert import_depth(graph) >= 5


def test_the_cycle_check_finds_a_function_level_and_a_package_cycle(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from . import b\n")
    (pkg / "b.py").write_text("def f():\n    from .sub import c\n")
    (pkg / "sub" / "__init__.py").write_text("from .c import X\n")
    (pkg / "sub" / "c.py").write_text("X = 1\n")
    graph = import_graph(pkg)
    assert graph["pkg.b"] == {"pkg.sub", "pkg.sub.c"} and find_cycle(graph) is None
    (pkg / "sub" / "c.py").write_text("def g():\n    from ..a import b\n")  # c -> a (-> b -> c), inside a function
    assert find_cycle(import_graph(pkg)) == ["pkg.a", "pkg.b", "pkg.sub", "pkg.sub.c", "pkg.a"]
