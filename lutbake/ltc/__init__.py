"""Linearly Transformed Cosines (Heitz et al. 2016): the lobes (``lobes``), the per-texel fit (``fit``), the
sphere/disk table (``sphere``), polygon integrals on the CPU (``polygon``) (the engine layouts: lutbake.io.ltc).
The kind ``ltc`` that bakes them is declared in lutbake.kinds.ltc; its tile engine (table.py), magnitude and fresnel
integrals (magnitude.py) and metadata records (metadata.py) are here."""
