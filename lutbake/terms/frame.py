"""Shading-frame helpers: n = +z, v in the xz-plane with v.x >= 0 (docs/notation.md)."""

import warp as wp


@wp.func
def view_dir(NoV: float):
    """v = (sqrt(1 - NoV^2), 0, NoV): the view direction of a table texel, n = (0, 0, 1)."""
    return wp.vec3(wp.sqrt(wp.max(1.0 - NoV * NoV, 0.0)), 0.0, NoV)


@wp.func
def reflect(v: wp.vec3, h: wp.vec3):
    """l = 2 (v.h) h - v: mirror v about the microfacet normal h."""
    return 2.0 * wp.dot(v, h) * h - v


@wp.func
def spherical_dir(cos_theta: float, sin_theta: float, phi: float):
    """Unit vector at polar angle theta (given by its cosine and sine) and azimuth phi about +z."""
    return wp.vec3(sin_theta * wp.cos(phi), sin_theta * wp.sin(phi), cos_theta)
