"""lutbake.catalog holds the names a config may choose; the Warp modules that implement them cover exactly those
names, with the same descriptions (one table per name; the kind registry and `lutbake list` read the catalog)."""

from lutbake import catalog
from lutbake.integrands import diffuse, fresnel
from lutbake.ltc.lobes import LOBES
from lutbake.sampling import hemisphere
from lutbake.terms import distributions


def test_every_ndf_record_matches_its_catalog_entry():
    assert {k: d.description for k, d in distributions.NDFS.items()} == catalog.NDF_DESCRIPTIONS
    assert catalog.SMITH_NDFS == tuple(k for k, d in distributions.NDFS.items() if d.Lambda is not None)
    assert catalog.VNDF_NDFS == tuple(k for k, d in distributions.NDFS.items() if d.sample_vndf is not None)
    for nd, d in distributions.NDFS.items():
        for mk in catalog.MASKINGS:
            assert catalog.masking_allowed(nd, mk) == d.masking_allowed(mk), (nd, mk)


def test_every_ltc_lobe_record_matches_its_catalog_entry():
    assert {k: lb.description for k, lb in LOBES.items()} == catalog.LTC_LOBES


def test_the_implementations_cover_exactly_the_catalog_names():
    assert set(diffuse.FACET_FUNCS) == set(catalog.FACET_FRESNEL)
    assert fresnel.COLUMNS == tuple(catalog.FRESNELS)
    assert set(hemisphere.DEFAULT_SAMPLES) == set(catalog.HEMISPHERE_ESTIMATORS)
    assert [hemisphere.estimator_for(name, 12).name for name in catalog.HEMISPHERE_ESTIMATORS] == list(
        catalog.HEMISPHERE_ESTIMATORS
    )
