"""Environment lighting for the split sum's other half: a lat-long (equirectangular) source, cube-map geometry with
its face convention written down once, the exact prefiltered specular and irradiance integrals, and L2 spherical
harmonics.

- ``latlong``: the source's direction convention, each texel's exact solid angle, the box-filtered pyramid (mean,
  min and max per texel) the quadrature descends.
- ``cube``: the cube-map face table (OpenGL / KTX / Vulkan; D3D's left-handed variant), direction <-> (face, s, t),
  exact texel solid angles and footprints.
- ``curves``: the engines' roughness <-> mip curves, as records of data with their sources.
- ``prefilter``: each output texel's integral of the texel-constant source against a lobe (GGX, cosine, the texel's
  own footprint), by deterministic quadrature over an adaptive tree of source texels; Warp kernels, float64 sums.
- ``sh``: L2 spherical harmonics by exact integration over every source texel, and the cosine convolution.
Docs: docs/environment.md.
"""
