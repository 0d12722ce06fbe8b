"""The one edge-case policy of lutbake: every guard against grazing angles, alpha -> 0 and
back-facing samples uses a constant from here, so the behaviour is written down in one place.

- ``ALPHA_MIN``: the smallest NDF alpha ever integrated. alpha = 0 makes D a Dirac delta that no
  quadrature can resolve; alpha is clamped to ALPHA_MIN (mitsuba3 uses the same 1e-4). The change to
  any table is O(ALPHA_MIN^2) ~ 1e-8. The clamped value is what the EXR's axis metadata lists.
- ``NOV_MIN``: the smallest n.v integrated. At n.v = 0 the view lies in the surface; every term is
  continuous there but the per-sample weights divide by n.v. Clamped, and recorded as the axis value.
- ``COS_EPS``: below this, a cosine is treated as zero (the sample is back-facing or on the horizon):
  the masking functions return 0 and integrands contribute nothing. No term ever divides by a cosine
  that has not passed this test, so no NaN or Inf can reach a table.
"""

ALPHA_MIN = 1.0e-4
NOV_MIN = 1.0e-4
COS_EPS = 1.0e-7
