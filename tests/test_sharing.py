"""Compute once, write many (lutbake.sharing): tables of a batch that differ only in name and their kind's layout
keys are computed once and written per table, and every file is bit-identical to baking that table alone; a key
that steers the computation (a storage-derived tolerance) is never a layout key."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from lutbake import batch
from lutbake.config import load_configs
from lutbake.io.exr import read_exr
from lutbake.kinds import KINDS
from lutbake.sharing import layout_keys, values_key
from lutbake.sources import sources_digest
from lutbake.values_cache import open_cache

SMALL_LTC = {"kind": "ltc", "lobe": "ggx", "size": [6, 6], "fit_samples": 4}
# one small valid table per kind that declares layout keys; every value each layout key allows is tried on it
# (dielectric_avg declares none since its mu rule reaches the tolerance that format / dtype set)
SMALL = {"ltc": SMALL_LTC, "ltc_aniso": {"kind": "ltc_aniso", "size": 2, "fit_samples": 4, "samples": 256}}
# layout values a kind's own cross-key check refuses with these small specs (they pair with other keys)
# (babylon_fuzz: a normal-frame lobe's only, refused for ggx; tests/test_babylon.py checks the refusal)
REFUSED: set = {("ltc", "format", "babylon_fuzz")}


def plan_records(plan) -> dict:
    """Everything a plan says about its values except the callables (the values themselves: the bakes below)."""
    return {
        "axes": repr(plan.axes),
        "channels": plan.channels,
        "reconstruction": plan.reconstruction,
        "n_texels": plan.n_texels,
        "samples": plan.samples,
        "estimator": plan.estimator,
        "terms": plan.terms,
        "extra": plan.extra,
        "aux_channels": plan.aux_channels,
    }


def test_every_kind_with_layout_keys_is_covered_here():
    assert {k for k, kind in KINDS.items() if kind.layout_keys} == set(SMALL)


@pytest.mark.parametrize("kind", sorted(SMALL))
def test_a_plans_records_do_not_depend_on_its_kinds_layout_keys(spec, kind):
    base = spec(SMALL[kind])
    ref = plan_records(KINDS[kind].plan(base))
    digest = sources_digest()
    for key in KINDS[kind].layout_keys:
        choices = KINDS[kind].keys[key].choices
        assert choices, f"{kind}.{key}: a layout key with free values is not tried here"
        for value in choices:
            if (kind, key, value) in REFUSED:
                continue
            other = spec(SMALL[kind], **{key: value}, name="other")
            assert plan_records(KINDS[kind].plan(other)) == ref, (kind, key, value)
            assert values_key(other, digest) == values_key(base, digest)


def test_values_key_follows_the_values_not_the_file(spec):
    digest = sources_digest()
    ltc = spec(SMALL_LTC)
    assert values_key(spec(SMALL_LTC, name="x", format="js", dtype="half"), digest) == values_key(ltc, digest)
    assert values_key(spec(SMALL_LTC, alpha_min=1e-3), digest) != values_key(ltc, digest)
    assert values_key(ltc, digest) != values_key(ltc, digest + b"other sources")
    # dfg: the storage sets the default tolerance its adaptive quadrature stops at, so format is not a layout key
    dfg = {"kind": "dfg", "size": [4, 4]}
    assert "format" not in layout_keys("dfg")
    assert values_key(spec(dfg, format="png16"), digest) != values_key(spec(dfg), digest)
    assert values_key(spec(dfg, name="y"), digest) == values_key(spec(dfg), digest)
    # so is kind dielectric's (adaptive since issue 13): dtype half sets a relative tolerance
    diel = {"kind": "dielectric", "size": [4, 3], "ior_size": 2}
    assert "dtype" not in layout_keys("dielectric")
    assert values_key(spec(diel, dtype="half"), digest) != values_key(spec(diel), digest)


def write_config(path: Path, tables: list[dict]) -> Path:
    path.write_text("".join("[[table]]\n" + "".join(f"{k} = {json.dumps(v)}\n" for k, v in t.items()) for t in tables))
    return path


def output_files(out: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(out.iterdir()) if p.is_file()}


@pytest.fixture
def computed(monkeypatch):
    """The names of the specs the batch computes (lutbake.batch.compute calls that return), in order of completion: a
    call that steps back before any tile ran (ModuleBusy, another thread compiling its module) is retried, not a
    second computation."""
    names = []
    real = batch.compute

    def counting(spec, *a, **k):
        out = real(spec, *a, **k)
        names.append(spec.name)
        return out

    monkeypatch.setattr(batch, "compute", counting)
    return names


def test_shared_tables_are_computed_once_and_bit_identical_to_baking_each_alone(tmp_path, computed):
    tables = [
        {"name": "ltc_exr", **SMALL_LTC},
        {"name": "ltc_js", **SMALL_LTC, "format": "js"},
        {"name": "ltc_dds", **SMALL_LTC, "format": "ltc_dds", "dtype": "half"},
        {"name": "ltc_other", **SMALL_LTC, "alpha_min": 1e-3},  # other values: its own computation
        {"name": "ltc_npy", **SMALL_LTC, "format": "npy", "dtype": "half"},
    ]
    together = tmp_path / "together"
    jobs = batch.schedule(load_configs([write_config(tmp_path / "all.toml", tables)]), together)
    assert batch.run(jobs, workers=2) is None
    assert sorted(computed) == ["ltc_exr", "ltc_other"]
    by_name = {j.name: j for j in jobs}
    assert all(j.status == "baked" for j in jobs)
    assert by_name["ltc_js"].values_from == by_name["ltc_dds"].values_from == "ltc_exr"
    assert by_name["ltc_npy"].values_from == "ltc_exr" and by_name["ltc_other"].values_from is None
    assert by_name["ltc_js"].cpu_seconds == 0.0 and by_name["ltc_exr"].cpu_seconds > 0.0

    alone = tmp_path / "alone"
    for i, t in enumerate(tables):  # each table in its own batch, from a config of the same file name (recorded)
        if t["name"] == "ltc_other":  # computed on its own in the batch too
            continue
        (tmp_path / str(i)).mkdir()
        one = batch.schedule(load_configs([write_config(tmp_path / str(i) / "all.toml", [t])]), alone)
        assert batch.run(one, workers=1) is None and one[0].status == "baked"
    shared, single = output_files(together), output_files(alone)
    assert sorted(shared) == sorted([*single, "ltc_other.exr"]) and len(single) >= len(tables) - 1
    for name, data in single.items():
        if name.endswith(".exr"):  # OpenEXR stamps capDate (the time of writing), and data_hash hashes the file
            (pa, ha), (pb, hb) = read_exr(alone / name), read_exr(together / name)
            ha.pop("data_hash"), hb.pop("data_hash")
            assert np.array_equal(pa, pb) and ha == hb, name
        else:
            assert data == shared[name], name


def test_the_values_cache_lays_out_known_values_without_computing_and_never_trusts_a_bad_entry(tmp_path, computed):
    cache_dir = tmp_path / "out" / ".cache"

    def run(table: dict, out: Path, cache=True, force=False) -> batch.Job:
        """Bake ``table`` into ``out`` after deleting its output (so that it is never up to date)."""
        for p in out.glob(f"{table['name']}.*"):
            p.unlink()
        (job,) = batch.schedule(load_configs([write_config(tmp_path / "c.toml", [table])]), out, force=force)
        assert batch.run([job], workers=2, cache=open_cache(cache_dir if cache else None, force)) is None
        assert job.status == "baked", job.message
        return job

    first = run({"name": "lut", **SMALL_LTC}, tmp_path / "out")
    assert computed == ["lut"] and first.values_from is None
    (entry,) = cache_dir.glob("*.npy")
    assert entry.stem == first.values_key and (cache_dir / f"{entry.stem}.json").is_file()

    # the output deleted: written again from the cache, the same pixels and attributes as the first bake
    data0, attrs0 = read_exr(first.path)
    again = run({"name": "lut", **SMALL_LTC}, tmp_path / "out")
    data1, attrs1 = read_exr(again.path)
    attrs0.pop("data_hash"), attrs1.pop("data_hash")
    assert computed == ["lut"] and again.values_from == "cache"
    np.testing.assert_array_equal(data1, data0)
    assert attrs1 == attrs0

    # a layout-only change (another format and dtype): no computation, the file of a bake without the cache
    npy = {"name": "lut", **SMALL_LTC, "format": "npy", "dtype": "half"}
    cached = run(npy, tmp_path / "out").path.read_bytes()
    assert computed == ["lut"]
    assert run(npy, tmp_path / "fresh", cache=False).path.read_bytes() == cached and computed == ["lut"] * 2

    # a corrupt entry (one flipped byte) is a miss: computed again, the entry rewritten whole
    blob = bytearray(entry.read_bytes())
    blob[-1] ^= 1
    entry.write_bytes(bytes(blob))
    assert run(npy, tmp_path / "out").values_from is None and len(computed) == 3
    assert run(npy, tmp_path / "out", force=True).values_from is None and len(computed) == 4  # --force reads none
    assert run(npy, tmp_path / "out").values_from == "cache" and len(computed) == 4

    # entries of other sources are removed at the start of a run; files the cache did not write stay
    meta = json.loads((cache_dir / f"{entry.stem}.json").read_text())
    old = "0" * 64
    (cache_dir / f"{old}.json").write_text(json.dumps({**meta, "values_key": old, "sources": "other sources"}))
    (cache_dir / f"{old}.npy").write_bytes(entry.read_bytes())
    (cache_dir / "notes.json").write_text("{}")
    assert {p.name for p in open_cache(cache_dir).prune()} == {f"{old}.json", f"{old}.npy"}
    assert sorted(p.name for p in cache_dir.iterdir()) == sorted([entry.name, entry.stem + ".json", "notes.json"])
