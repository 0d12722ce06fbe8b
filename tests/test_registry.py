"""The registry (lutbake.registry): every name a config may choose is one record of one family, its object loaded
lazily; the implementations cover exactly the records; names resolve once, at the config."""

import pytest

from lutbake.config import validate_table
from lutbake.errors import ConfigError
from lutbake.integrands import diffuse, fresnel
from lutbake.ltc.lobes import LOBES
from lutbake.records import DIFFUSE, FACET_FRESNEL, FRESNEL, HEMISPHERE_ESTIMATOR, LTC_LOBE, MASKING, MODEL, NDF
from lutbake.registry import Lazy, Record, RegistryError, family
from lutbake.sampling import hemisphere
from lutbake.terms import distributions


def own(fam) -> list:
    """lutbake's own records of a family (a plugin loaded by another test in this process may add its own)."""
    return [r for r in fam if r.plugin is None]


def test_every_ndf_record_names_its_distribution():
    assert [r.name for r in own(NDF)] == list(distributions.NDFS)
    for r in own(NDF):
        d = r.obj
        assert d is distributions.NDFS[r.name] and d.name == r.name
        assert r.fields["smith"] == (d.Lambda is not None), r.name
        assert r.fields["vndf"] == (d.sample_vndf is not None), r.name
        for m in own(MASKING):
            assert (not m.fields["smith"] or r.fields["smith"]) == d.masking_allowed(m.name), (r.name, m.name)


def test_every_ltc_lobe_record_names_its_lobe():
    assert [r.name for r in own(LTC_LOBE)] == list(LOBES)
    assert all(r.obj is LOBES[r.name] for r in own(LTC_LOBE))


def test_fresnel_records_load_their_terms_and_linear_ones_factor_f0():
    import numpy as np

    c = np.linspace(0.0, 1.0, 9)
    values = fresnel.evaluate(c, f0=0.3, n=1.5, k=2.0, a=0.5, fresnels=own(FRESNEL))
    assert list(values) == [r.name for r in own(FRESNEL)]
    zero = fresnel.evaluate(c, f0=0.0, fresnels=own(FRESNEL))
    for r in own(FRESNEL):
        assert callable(r["F"]) and r.fields["param"] in ("f0", "nk", "nka")
        if r.fields["linear_in_f0"]:  # F = f0 + (1 - f0) Fc, Fc = F(0, c)
            np.testing.assert_allclose(values[r.name], 0.3 + 0.7 * zero[r.name], atol=2e-7)


def test_the_implementations_cover_exactly_the_records():
    assert set(diffuse.FACET_F0_SCALE) == set(FACET_FRESNEL.names())
    assert all(r.get("Fd") is not None for r in own(DIFFUSE) if r.name not in ("lambert", "microfacet"))
    assert set(hemisphere.DEFAULT_SAMPLES) == set(HEMISPHERE_ESTIMATOR.names())
    assert [hemisphere.estimator_for(r.name, 12).name for r in HEMISPHERE_ESTIMATOR] == HEMISPHERE_ESTIMATOR.names()
    assert all(r.fields["form"] in ("microfacet", "blinn_phong", "ashikhmin_shirley") for r in MODEL)


def test_every_record_has_a_description_and_a_citation():
    for fam in (NDF, MASKING, FRESNEL, MODEL, DIFFUSE, FACET_FRESNEL, LTC_LOBE, HEMISPHERE_ESTIMATOR):
        for r in own(fam):
            assert r.description and r.citation, (fam.name, r.name)


def test_a_family_refuses_a_name_another_origin_holds_and_suggests_the_nearest():
    from lutbake.registry import Plugin

    fam = family("test_family")
    fam.add(Record("test_family", "mine", "one", aliases=("alias",)))
    other = Plugin("/x/plugin.py", "text", "m")
    with pytest.raises(RegistryError, match="'mine' is already defined by lutbake"):
        fam.add(Record("test_family", "mine", "two", plugin=other, line=3))
    with pytest.raises(RegistryError, match="'alias' is already defined"):
        fam.add(Record("test_family", "new", "two", aliases=("alias",), plugin=other))
    with pytest.raises(RegistryError, match="did you mean 'mine'"):
        fam.lookup("mien")
    assert fam.lookup("alias").name == "mine"


def test_lazy_fields_load_once_on_first_use():
    r = Record("test_lazy", "x", "d", fields={"obj": Lazy("lutbake.terms.distributions:NDFS", "ggx")})
    assert r.obj is distributions.GGX and r.obj is r.obj


def test_config_resolves_every_name_to_its_record_once():
    raw = {"name": "t", "kind": "split_sum", "model": "cook_torrance", "estimator": "sobol_ndf", "size": [4, 4]}
    spec = validate_table(raw, "c.toml", 0)
    assert spec.kind == "dfg" and spec.records["kind"].obj.name == "dfg"
    assert spec.records["model"] is MODEL.lookup("cook_torrance")
    assert spec.records["fresnel"] is FRESNEL.lookup("schlick")
    assert spec.records["estimator"] is HEMISPHERE_ESTIMATOR.lookup("sobol_ndf")


def test_a_record_outside_a_keys_filter_is_refused_with_the_reason():
    raw = {"name": "t", "kind": "dfg", "fresnel": "dielectric_f0", "size": [4, 4]}
    with pytest.raises(ConfigError, match="cannot be used here: the split sum factors f0 out"):
        validate_table(raw, "c.toml", 0)
    with pytest.raises(ConfigError, match="did you mean 'schlick'"):
        validate_table({**raw, "fresnel": "schlik"}, "c.toml", 0)


def test_specs_pickle_with_their_records():
    import pickle

    spec = validate_table({"name": "t", "kind": "dfg", "size": [4, 4]}, "c.toml", 0)
    again = pickle.loads(pickle.dumps(spec))
    assert again == spec and again.records["ndf"] is spec.records["ndf"]
