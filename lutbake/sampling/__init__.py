"""Quadratures: every way lutbake turns a per-texel integral into a weighted sum, and the one texel plan.

:mod:`.plan` composes integrand x estimator x grid (``per_texel_plan``); :mod:`.points` builds deterministic
point sets; :mod:`.hemisphere` (specular, over h), :mod:`.anisotropic` (3D Sobol'), :mod:`.diffuse` (over l, and
point evaluation), :mod:`.swapped` (the swapped-integral diffuse albedo), :mod:`.facets` (the microfacet diffuse
m-integral) and :mod:`.panels` (their shared panel rules) hold the estimators: kernel factories that close over an
integrand's ``@wp.func``s. Integrands live in :mod:`lutbake.integrands`, grids in :mod:`lutbake.axes`.
"""
