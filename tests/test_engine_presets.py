"""The engine presets load together with every config (as `make luts` bakes them) and keep their conventions."""

from pathlib import Path

import pytest

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
            {"size": [64, 64], "texel": "endpoint", "nov_mapping": "square", "layout": "multiscatter_disney"},
        ),
        ("godot", {"size": [128, 128], "layout": "multiscatter_cloth", "dtype": "half"}),
        ("bevy", {"layout": "scale_bias", "dtype": "half", "format": "ktx2zst"}),
        (
            "threejs",
            {"size": [16, 16], "axis_order": "roughness_x", "texel": "center", "dtype": "half", "format": "js"},
        ),
    ],
)
def test_engine_preset_conventions(preset, expected):
    (spec,) = load_configs([presets()[preset]])
    assert {k: spec.options[k] for k in expected} == expected
