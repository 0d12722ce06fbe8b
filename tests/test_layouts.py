"""Engine layouts as data (lutbake.layouts): one record per layout, one module per engine, presets that hold what their
engine fixes, and no layout-name branch outside the package."""

import dataclasses
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from lutbake.axes import Axis
from lutbake.config import load_config, preset_path, presets
from lutbake.kinds import KINDS
from lutbake.layouts import ENGINES, REGISTRY, TABLES, engine_modules, layouts_of, lookup_layout
from lutbake.layouts.base import Layout
from lutbake.sampling.plan import Grid, StoredMap, per_texel_plan

PACKAGE = Path(__file__).resolve().parent.parent / "lutbake"
# the environment presets (bevy-ibl, gltf-ibl) name no environment file of their own: a test gives them this one
ENVIRONMENT = Path(__file__).resolve().parent / "data" / "env_studio_64x32.exr"
# Blender EEVEE's brdf_ggx reconstruction as baseline outputs recorded it before the records (uv rendered from the axes)
EEVEE_RECONSTRUCTION = (
    "uv = vec2((roughness) * 63/64 + 0.5/64, (sqrt(1 - NoV)) * 63/64 + 0.5/64); t = texture(lut, uv).rg; specular = "
    "prefiltered * (f0 * t.r + t.g); F82 tint (Blender EEVEE): b = mix(f0, 1, (6/7)^5) * 7/(6/7)^6 * (1 - f82_tint), "
    "specular = prefiltered * (f0 * t.r + f90 * t.g - b * t.b)"
)


@pytest.mark.parametrize("kind", ["dfg", "dielectric", "dielectric_avg"])
def test_every_layout_key_value_has_one_record(kind):
    """The kind's ``layout`` key documents exactly the registered records of that kind."""
    assert set(KINDS[kind].keys["layout"].choices) == set(layouts_of(kind))
    assert all(lay.kind == kind and lay.name == name for name, lay in layouts_of(kind).items())


def test_lookup_names_the_valid_layouts_and_the_nearest():
    with pytest.raises(KeyError, match=r"did you mean 'scale_bias'\?.*layouts: .*multiscatter_cloth"):
        lookup_layout("dfg", "scale_bais")
    assert lookup_layout("dielectric", "openpbr").kind == "dielectric"


def test_layout_records_are_frozen():
    lay = lookup_layout("dfg", "scale_bias")
    with pytest.raises(dataclasses.FrozenInstanceError):
        lay.name = "other"


def test_engine_modules_are_found_by_existing_with_lutbakes_own_first():
    names = [m.__name__.rsplit(".", 1)[1] for m in engine_modules()]
    assert names[0] == "plain" and names[1:] == sorted(names[1:]) and "base" not in names
    assert len(ENGINES) == len(names)


@pytest.mark.parametrize("table", TABLES, ids=lambda t: f"{t.preset}:{t.table}")
def test_each_engine_tables_preset_holds_the_keys_its_engine_fixes(table):
    """The preset named by an engine's table record bakes that table with every grid and storage key the record
    fixes (and in the record's layout)."""
    spec = next(s for s in load_config(preset_path(table.preset), environment=ENVIRONMENT) if s.name == table.table)
    assert spec.kind == table.kind
    for key, want in table.keys.items():
        got = spec.options[key] if key != "kind" else spec.kind
        assert (list(got) if isinstance(got, (list, tuple)) else got) == want, (table.preset, key)
    if table.layout is not None:
        assert lookup_layout(table.kind, spec.options["layout"]).name == table.layout


def test_every_preset_table_has_an_engine_record():
    """Adding an engine is a module in lutbake/layouts with its presets: no preset table is left undeclared."""
    declared = {(t.preset, t.table) for t in TABLES}
    for name, path in presets().items():
        for spec in load_config(path, environment=ENVIRONMENT):
            assert (name, spec.name) in declared, (name, spec.name)


def test_reconstruction_renders_the_uv_of_the_tables_axes():
    """Blender EEVEE's brdf_ggx text, with endpoint texels and a roughness x axis, is the one outputs carried."""
    from lutbake.kinds.dfg import axes_for

    spec = next(iter(load_config(preset_path("blender-eevee"))))
    assert lookup_layout("dfg", "scale_bias_f82").reconstruction(axes_for(spec.options)) == EEVEE_RECONSTRUCTION
    assert "{uv}" not in lookup_layout("dfg", "multiscatter_disney").reconstruction(axes_for(spec.options))


def test_no_layout_name_branch_outside_the_layouts_package():
    """Kinds, value bounds, the commands and the writers read the records: no ``layout == "..."`` or
    ``layout in ("...")`` test on a layout's name survives outside lutbake/layouts."""
    pattern = re.compile(r"layout\W{0,3} *(==|!=|in \(|not in \()")
    bad = [
        f"{f.relative_to(PACKAGE)}:{i}"
        for f in PACKAGE.rglob("*.py")
        if "layouts" not in f.relative_to(PACKAGE).parts
        for i, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1)
        if pattern.search(line)
    ]
    assert not bad, bad


def test_dielectric_engine_layouts_fix_their_grid_and_terms():
    for name in ("eevee_btdf", "eevee_bsdf", "openpbr"):
        lay = lookup_layout("dielectric", name)
        assert lay.grid is not None and lay.texels is not None
        assert (lay.terms.ndf, lay.terms.masking) == ("ggx", "smith_separable")
    assert lookup_layout("dielectric", "energy").grid is None


class _Rows:
    """A fixed estimator (the per_texel_plan protocol): texel i's values are row i of ``values``; refined: itself."""

    name = "rows"

    def __init__(self, values):
        self.values, self.prepared = values, []

    def samples(self, inputs):
        return np.ones(len(inputs["i"]))

    def prepare(self, integrand, device):
        self.prepared.append("estimator")

    def evaluate(self, integrand, inputs, device):
        return self.values[inputs["i"]]

    def refined(self):
        return self, "refined - nominal"


class _RowsWithError(_Rows):
    """_Rows as an adaptive estimator: each value's own error estimate is 1/8 of it (the tiles' aux columns)."""

    absolute, relative = 1.0, 0.0

    def evaluate_with_error(self, integrand, inputs, device):
        values = self.values[inputs["i"]]
        return values, values * 0.125


def test_stored_channels_map_the_values_and_the_estimate_sees_the_integrals():
    """per_texel_plan(stored=...): a layout's map, then an engine's added channel, apply to each tile's channels when
    the plan is built (no plan patched afterwards); the error estimate receives the integrals back through the
    inverses (a difference of 0 against the refined estimator: the stored values would differ from them)."""
    base = np.arange(8, dtype=np.float64).reshape(4, 2) + 1.0  # 4 texels, 2 channels
    est = _Rows(base)
    swap = StoredMap.of_values(lambda v: v[:, ::-1], lambda v: v[:, ::-1])
    added = StoredMap(
        lambda v, texels, d: np.concatenate([v / 2.0, np.arange(4.0)[texels, None]], axis=1),
        lambda t: t[:, :-1] * 2.0,
        added=1,
        prepare=lambda d: est.prepared.append("added"),
    )
    grid = Grid([Axis("i", "x", 4)], {"i": np.arange(4)})
    kw = dict(channels={"a": "", "b": "", "c": ""}, reconstruction="", terms={})
    plan = per_texel_plan(SimpleNamespace(nch=2), est, grid, stored=(swap, added), **kw)
    assert plan.n_channels == 3 and plan.tile_width == 3
    tile = plan.run_tile(1, 4, "cpu")
    np.testing.assert_array_equal(tile, np.concatenate([base[1:, ::-1] / 2.0, np.arange(1.0, 4.0)[:, None]], 1))
    plan.prepare("cpu")
    assert est.prepared == ["estimator", "added"]
    err, _ = plan.error_estimate(plan.run_tile(0, 4, "cpu"), "cpu")
    assert err == 0.0
    plain = per_texel_plan(SimpleNamespace(nch=2), est, grid, **kw)
    assert plain.n_channels == 2 and plain.error_estimate(swap.to_stored(base, slice(0, 4), "cpu"), "cpu")[0] > 0
    # an adaptive estimator's aux columns (its per-texel estimates) pass untouched; its estimate sees the integrals
    adaptive = per_texel_plan(SimpleNamespace(nch=2), _RowsWithError(base), grid, stored=(swap, added), **kw)
    tile = adaptive.run_tile(0, 4, "cpu")
    assert adaptive.aux_channels == 2 and tile.shape == (4, 5)
    np.testing.assert_array_equal(tile[:, 3:], base * 0.125)
    kw["relative_error"] = True
    adaptive = per_texel_plan(SimpleNamespace(nch=2), _RowsWithError(base), grid, stored=(swap, added), **kw)
    assert adaptive.error_estimate(adaptive.run_tile(0, 4, "cpu"), "cpu")[0] == 0.125


def test_records_declare_a_range_and_its_reason():
    for lay in REGISTRY.values():
        assert isinstance(lay, Layout)
        assert lay.unit_range or lay.above_one, lay.name


def test_shipped_tables_named_by_engine_records_are_in_tests_data():
    data = Path(__file__).resolve().parent / "data"
    named = [t.shipped for t in TABLES if t.shipped]
    assert named and all((data / name).is_file() for name in named), named
