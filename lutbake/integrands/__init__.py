"""Integrands: the functions of the microfacet normal h that a table kind integrates (one module per family).
Each is a ``@wp.func (v, h, alpha, param) -> vec`` in the half-vector measure dω_h, composed from lutbake.terms."""
