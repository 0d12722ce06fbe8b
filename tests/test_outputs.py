"""`lutbake inspect` and `lutbake preview` read every file `make luts` writes: every table of configs/*.toml and
of the Makefile's PRESETS, baked here at small sizes (their kinds, layouts, formats and conventions unchanged),
plus the formats `make luts` does not use (npy, ktx2); every data file and every .json sidecar."""

import re
import tomllib
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake.api import bake_table
from lutbake.cli import main
from lutbake.config import preset_path, validate_table
from lutbake.io.formats import write_table
from lutbake.kinds import lookup_kind

ROOT = Path(__file__).resolve().parents[1]
# files, conventions and previews are checked here, not accuracy: 4 IOR slices (Turquin's symmetric mapping needs an
# even count) and an 8 x 8 LTC fit metric (its fit and accuracy: tests/test_ltc.py)
SMALL = {"size": [8, 6], "roughness_size": 8, "f0_size": 3, "anisotropy_size": 3, "phi_size": 3, "sigma_size": 3}
SMALL |= {"ior_size": 4, "fit_samples": 8}
# the glass layouts have fixed sizes (EEVEE 16 x 64^2, OpenPBR 32^3), so they get the lowest order and a loose
# tolerance (their adaptive rules and accuracy: tests/test_dielectric.py); the diffuse tables a GL order of 4, not 12
SMALL_GLASS = {"samples": 4, "mu_order": 2, "tolerance": 1e-1}
SMALL_KIND = {"dielectric": SMALL_GLASS, "dielectric_avg": SMALL_GLASS, "diffuse": {"samples": 4}}
SMALL_KIND["diffuse_3d"] = SMALL_KIND["diffuse"]
PREVIEW_DPI = 40  # the layout is what is checked here, not the pixels
RENDERED = (  # one file per kind of picture, drawn to a PNG
    "dfg.exr",
    "lut_charlie.exr",
    "albedo_avg.exr",
    "specular_3d_dielectric_f0.exr",
    "btf_fitted.exr",
    "ltc_ggx_1.dds",
    "openpbr_energy_avg.h.json",
    "eevee_bsdf_ggx.h",
)


def make_luts_sources() -> list[Path]:
    """The configs and presets `make luts` bakes (the Makefile's CONFIGS and PRESETS)."""
    makefile = (ROOT / "Makefile").read_text().replace("\\\n", " ")  # join continued lines
    presets = re.search(r"^PRESETS \?=(.*)$", makefile, re.M).group(1).split()
    return sorted((ROOT / "configs").glob("*.toml")) + [preset_path(p) for p in presets]


@pytest.fixture(scope="module")
def luts(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("luts")
    for src in make_luts_sources():
        for i, raw in enumerate(tomllib.loads(src.read_text())["table"]):
            keys = lookup_kind(raw["kind"]).keys
            raw.update({k: v for k, v in SMALL.items() if k in keys})
            raw.update({k: v for k, v in SMALL_KIND.get(raw["kind"], {}).items() if k in keys})
            spec = validate_table(raw, src, i)
            table = bake_table(spec, workers=1)[0]
            write_table(table, out, spec.options.get("format", "exr"), spec.options.get("dtype", "float32"))
            if spec.name == "dfg":  # the formats make luts does not write, each in its own folder
                for fmt in ("exr", "npy", "png16", "dds", "ktx2", "h"):
                    write_table(table, out / fmt, fmt, "half")
    return out


def test_the_small_set_has_every_kind_and_format(luts):
    from lutbake.io.readers import read

    loaded = {p: read(p) for p in luts.rglob("*.*")}  # each file read once for both checks
    top = [p for p in luts.glob("*") if p.is_file() and not p.name.endswith(".json")]
    kinds = {(loaded[p] if p in loaded else read(p)).attrs.get("kind") for p in top}
    assert {"dfg", "albedo", "albedo_avg", "specular_3d", "specular_aniso", "diffuse", "diffuse_3d", "btf"} <= kinds
    formats = {f.format for f in loaded.values()}
    assert {"exr", "npy", "png", "dds", "ktx2", "h", "sidecar"} <= formats


def test_inspect_reads_every_file_make_luts_writes(luts):
    from lutbake.io.readers import read

    files = sorted(p for p in luts.rglob("*.*") if not p.name.endswith(".preview.png"))
    assert len(files) > 40
    for p in files:
        r = CliRunner().invoke(main, ["inspect", str(p)])
        assert r.exit_code == 0, (p, r.output)
        loaded = read(p)
        assert loaded.data is not None and "metadata only" not in r.output, (p, r.output)  # engine layouts too
        if not loaded.attrs:  # the second file of a two-file output (ltc_ggx_2.dds): its pixels only
            assert "no lutbake metadata" in r.output and "statistics:" in r.output, (p, r.output)
        else:
            assert "kind:" in r.output and "axes:" in r.output and "statistics:" in r.output, (p, r.output)


def test_preview_draws_every_file_make_luts_writes(luts, tmp_path, monkeypatch):
    """Every file, sidecars and engine layouts included, gets its preview figure (a sidecar's is its data file's:
    it reads as the same view); one file per kind of picture (2D and 3D with and without the sphere row, 1D, the
    BTF blocks, an LTC pair, a glass table, a sidecar) is drawn to a PNG as well."""
    plt = pytest.importorskip("matplotlib.pyplot")
    from lutbake.commands import preview
    from lutbake.commands.preview import figure, render
    from lutbake.io.readers import read_table

    files = sorted(p for p in luts.rglob("*.*") if not p.name.endswith(".preview.png"))
    assert {p.suffix for p in files} >= {".js", ".cc", ".cs", ".h", ".dds", ".json"}
    sidecars = {p for p in files if p.suffix == ".json" and p.with_suffix("") in files}
    for p in sidecars:
        a, b = read_table(p), read_table(p.with_suffix(""))
        assert np.array_equal(a.data, b.data) and (a.axes, a.channel_names, a.meanings) == (
            b.axes,
            b.channel_names,
            b.meanings,
        ), p
        assert (a.kind, a.name, a.terms, a.reconstruction) == (b.kind, b.name, b.terms, b.reconstruction), p
    drawn = {}

    def kept(path):  # render() draws with this: its figure is the one the titles are checked on below
        drawn[path] = fig = figure(path)
        return fig

    monkeypatch.setattr(preview, "figure", kept)
    for name in RENDERED:
        out = render(luts / name, tmp_path / f"{name.replace('/', '_')}.png", dpi=PREVIEW_DPI)
        assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
    for p in sorted(set(files) - sidecars):
        fig = drawn.get(p) or figure(p)
        titles = [t for ax in fig.axes for t in (ax.get_title(), ax.get_title(loc="left")) if t]
        plt.close(fig)
        assert p.name in fig.get_suptitle() and titles, p
