"""The declared value ranges (lutbake.value_bounds) that let png16 be refused before a bake (issue 11,
item 6) are checked against bakes: every declaration "within [0, 1]" holds on a small table of that
kind/layout/model, every "may exceed 1" is shown to exceed 1 by more than PNG_SLACK, and every layout and
model a kind offers is declared one way or the other."""

import pytest

from lutbake import value_bounds as vb
from lutbake.api import bake_table
from lutbake.config import validate_table
from lutbake.io.png import PNG_SLACK
from lutbake.kinds import KINDS
from lutbake.kinds.dfg import LAYOUTS
from lutbake.records import ANISO_MODEL, DIFFUSE, MODEL

ANISO_MODELS, DIFFUSE_MODELS, MODELS = ANISO_MODEL.names(), DIFFUSE.names(), MODEL.names()

SMALL = {
    "dfg": {"size": [16, 16]},
    "albedo": {"size": [16, 16]},
    "albedo_avg": {"roughness_size": 16},
    "specular_3d": {"size": [8, 8], "f0_size": 3},
    "specular_aniso": {"size": [8, 8], "anisotropy_size": 3},
    "diffuse": {"size": [16, 16]},
    "diffuse_3d": {"size": [8, 8], "f0_size": 3},
    "btf": {"size": [8, 8], "phi_size": 4, "sigma_size": 3},
    "dielectric": {"size": [8, 8], "ior_size": 4},
}
UNIT = (
    [("dfg", {"layout": lay}) for lay in sorted(vb.UNIT_LAYOUTS)]
    + [
        (k, {"model": m})
        for k in ("dfg", "albedo", "albedo_avg", "specular_3d")
        for m in sorted(vb.UNIT_SPECULAR_MODELS)
    ]
    + [("specular_aniso", {"model": m}) for m in sorted(ANISO_MODELS)]
    + [(k, {"model": m}) for k in ("diffuse", "diffuse_3d") for m in sorted(vb.UNIT_DIFFUSE_MODELS)]
    + [("dielectric", {"layout": "energy"})]
)
ABOVE = (
    # multiscatter_disney leaves [0, 1] only where its endpoint texels reach NoV = 0 (unity-hdrp's convention)
    [
        ("dfg", {"layout": lay, **({"texel": "endpoint"} if lay == "multiscatter_disney" else {})})
        for lay in sorted(vb.ABOVE_ONE_LAYOUTS)
    ]
    + [(k, {"model": m}) for k in ("dfg", "albedo") for m in sorted(vb.ABOVE_ONE_SPECULAR_MODELS)]
    + [(k, {"model": m}) for k in ("diffuse", "diffuse_3d") for m in sorted(vb.ABOVE_ONE_DIFFUSE_MODELS)]
    + [("btf", {"model": "microfacet"})]
)


# the adaptive estimators' error target: the bounds hold or fail by far more (PNG_SLACK = 1e-3; every "above one"
# table leaves [-PNG_SLACK, 1 + PNG_SLACK] by more than 0.02), and min/max move by < 1e-4 from the default tolerance
TOL = 1.0e-4
# the microfacet diffuse model's fixed GL order (default 12): at 8 its tables' min/max move by < 4e-6, at 5x less cost
DIFFUSE_MICROFACET = {"samples": 8}


def spec(kind, opts):
    coarse = DIFFUSE_MICROFACET if kind in vb.DIFFUSE_KINDS and opts.get("model") == "microfacet" else {}
    raw = {"name": "t", "kind": kind, **SMALL[kind], "tolerance": TOL, **coarse, **opts}
    return validate_table(raw, "<test>", 0)


def test_every_kind_layout_and_model_is_declared():
    assert set(KINDS) == vb.SPECULAR_KINDS | vb.DIFFUSE_KINDS | vb.DIELECTRIC_KINDS | set(vb.UNBOUNDED_KINDS)
    assert vb.UNIT_LAYOUTS | vb.ABOVE_ONE_LAYOUTS == set(LAYOUTS) and not vb.UNIT_LAYOUTS & vb.ABOVE_ONE_LAYOUTS
    assert vb.UNIT_SPECULAR_MODELS | vb.ABOVE_ONE_SPECULAR_MODELS == set(MODELS)
    assert set(ANISO_MODELS) <= vb.UNIT_SPECULAR_MODELS
    assert vb.UNIT_DIFFUSE_MODELS | vb.ABOVE_ONE_DIFFUSE_MODELS == set(DIFFUSE_MODELS)


@pytest.mark.parametrize("kind, opts", UNIT, ids=[f"{k}-{'-'.join(o.values())}" for k, o in UNIT])
def test_declared_unit_range_holds(kind, opts):
    s = spec(kind, opts)
    assert vb.unit_range(s) is None
    table, _, _ = bake_table(s, workers=1)
    assert table.data.min() >= -PNG_SLACK and table.data.max() <= 1.0 + PNG_SLACK, (table.data.min(), table.data.max())


@pytest.mark.parametrize("kind, opts", ABOVE, ids=[f"{k}-{'-'.join(o.values())}" for k, o in ABOVE])
def test_declared_above_one_does_exceed_one(kind, opts):
    s = spec(kind, opts)
    assert vb.unit_range(s) is not None
    table, _, _ = bake_table(s, workers=1)
    assert table.data.max() > 1.0 + PNG_SLACK or table.data.min() < -PNG_SLACK
