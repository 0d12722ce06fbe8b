"""Environment lighting for the split sum's other half: a lat-long (equirectangular) source, cube-map geometry with
its face convention written down once, the exact prefiltered specular and irradiance integrals, and L2 spherical
harmonics.

- ``latlong``: the source's direction convention, each texel's exact solid angle, the box-filtered pyramid (mean,
  min and max per texel) the quadrature descends.
- ``cube``: the cube-map face table (OpenGL / KTX / Vulkan; D3D's left-handed variant), direction <-> (face, s, t),
  exact texel solid angles and footprints.
- ``curves``: the engines' roughness <-> mip curves, as records of data with their sources.
- ``lobes``: the weights a texel integrates the source against (GGX with and without n.l, cosine, a footprint).
- ``quadrature``: one texel's exact integral of the texel-constant source against a lobe, by a deterministic descent
  of the pyramid with exact clipping (a Warp kernel factory; float64 sums).
- ``prefilter``: the cube's texels and mips through lutbake.runtime's executor, and the per-mip error estimate.
- ``sh``: L2 spherical harmonics by exact integration over every source texel, and the cosine convolution.
Docs: docs/environment.md.
"""
