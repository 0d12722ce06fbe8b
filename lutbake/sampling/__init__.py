"""Estimators: how an integral over the hemisphere is turned into a weighted sum.

Host side (:mod:`.points`) builds deterministic point sets; device side (:mod:`.estimators`) is a
set of kernel factories that take an integrand ``@wp.func`` and return a kernel integrating it per
texel. Integrands live in :mod:`lutbake.tables`, grids in :mod:`lutbake.axes`.
"""
