"""The engine presets load together with every config (as `make luts` bakes them) and keep their conventions."""

from pathlib import Path

import numpy as np
import pytest
from hemisphere_reference import hemisphere_cubature

from lutbake.config import load_configs, presets

REPO = Path(__file__).resolve().parents[1]


def test_make_luts_batch_loads_with_unique_names():
    """configs/*.toml and the Makefile's PRESETS, as `make luts` passes them to one `lutbake bake`."""
    text = (REPO / "Makefile").read_text().replace("\\\n", " ")  # join continued lines
    line = next(x for x in text.splitlines() if x.startswith("PRESETS ?="))
    names = line.split("?=", 1)[1].split()
    assert {"unity-hdrp", "godot", "bevy", "threejs"} <= set(names)
    specs = load_configs(sorted((REPO / "configs").glob("*.toml")) + [presets()[n] for n in names])
    names = [s.name for s in specs]
    assert len(names) == len(set(names))


@pytest.mark.parametrize(
    "preset, expected",
    [
        (
            "unity-hdrp",
            {"size": (64, 64), "texel": "endpoint", "nov_mapping": "square", "layout": "multiscatter_disney"},
        ),
        (
            "godot",
            {
                "size": (128, 128),
                "layout": "multiscatter_cloth",
                "dtype": "half",
                "masking": "schlick_ggx_ibl",
                "row_order": "hi_first",
                "texel": "center",
            },
        ),
        ("bevy", {"layout": "scale_bias", "dtype": "half", "format": "ktx2zst"}),
        (
            "threejs",
            {
                "size": (16, 16),
                "axis_order": "roughness_x",
                "texel": "center",
                "dtype": "half",
                "format": "threejs_dfg",
            },
        ),
    ],
)
def test_engine_preset_conventions(preset, expected):
    (spec,) = load_configs([presets()[preset]])
    assert {k: spec.options[k] for k in expected} == expected  # a list option is a tuple in a TableSpec


# converged lutbake vs the graded cubature (tests/hemisphere_reference.py: a finer rule changes it by < 6e-12 on these
# texels, scipy dblquad at epsabs 1e-10 agrees to 6e-10), float32 storage of the 8 x 8 bake
GODOT_ATOL = 2e-6
GODOT_TEXELS = [(0, 0), (1, 3), (3, 6), (5, 2), (7, 7)]  # (image row, column); row 0 = the roughest (hi_first)


def godot_dfg_reference(rule, nov, r):
    """Godot integrate_dfg.glsl's integrand in numpy: GGX D (a = r²), geometry_smith = Schlick-GGX with k = r²/2 (its
    geometry_schlick_ggx squares the perceptual r it is given) on both directions; returns
    (∫ Fc f/F (n.l) dω, ∫ f/F (n.l) dω, ∫ D_charlie V_ashikhmin (n.l) dω)."""
    a = r * r
    k = r * r / 2.0

    def cloth(mu, noh, voh):
        d = (2.0 + 1.0 / a) * (1.0 - noh**2) ** (0.5 / a) / (2.0 * np.pi)
        return d / (4.0 * (mu + nov - mu * nov)) * mu

    def specular(mu, noh, voh):
        d = a * a / (np.pi * (noh**2 * (a * a - 1.0) + 1.0) ** 2)
        g2 = nov / (nov * (1.0 - k) + k) * mu / (mu * (1.0 - k) + k)
        return d * g2 / (4.0 * nov * mu) * mu

    def fc(mu, noh, voh):
        return specular(mu, noh, voh) * (1.0 - voh) ** 5

    return [hemisphere_cubature(f, nov, rule) for f in (fc, specular, cloth)]


@pytest.fixture(scope="module")
def godot_table():
    import lutbake
    from lutbake.config import load_config, preset_path

    spec = load_config(preset_path("godot"), [(None, "size", [8, 8]), (None, "dtype", "float32")])[0]
    return lutbake.bake_table(spec)[0]


@pytest.mark.parametrize("row, col", GODOT_TEXELS)
def test_godot_table_equals_its_shader_integrand(godot_table, graded_rule, row, col):
    # integrate_dfg.glsl @ e8387d69: roughness = (pos.y + 0.5)/SIZE, NdotV = (pos.x + 0.5)/SIZE, stored at row
    # SIZE - 1 - pos.y; so image row `row` holds r = (7 - row + 0.5)/8
    nov, r = (col + 0.5) / 8, (7 - row + 0.5) / 8
    np.testing.assert_allclose(godot_table.data[row, col], godot_dfg_reference(graded_rule, nov, r), atol=GODOT_ATOL)
