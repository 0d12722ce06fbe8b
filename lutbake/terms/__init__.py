"""BRDF terms as ``@wp.func``s, one module per family (ndf, masking, fresnel, frame).

Naming follows the math: ``D_`` normal distributions, ``Lambda_``/``G1_``/``G2_`` masking-shadowing,
``F_`` Fresnel, ``Fd_`` diffuse. Arguments are cosines named ``NoV``, ``NoL``, ``NoH``, ``VoH``
(docs/notation.md); ``alpha`` is always the NDF parameter, never a perceptual roughness.
Host code picks terms by name: one ``Distribution`` object per NDF in :mod:`.distributions`
(with the masking forms), composed into integrands by :mod:`lutbake.integrands`.
"""

from ..runtime.warp_runtime import init_warp

# Every lutbake kernel is composed of these terms, so any module that can launch one has imported this
# package first: Warp starts here, quietly unless LUTBAKE_VERBOSE is set (lutbake.runtime.warp_runtime).
init_warp()
