"""AakashKT/LTC-Anisotropic (Kt, Heitz, Dupuy & Narayanan 2022, "Bringing Linearly Transformed Cosines to Anisotropic
GGX", I3D): the paper's table of anisotropic GGX LTCs, LUT/alphax_alphay_theta_phi.npy (M[a, b, theta, phi], 8^4 x 3 x
3 float32), baked by preset ``ltc-aniso`` as kind ltc_aniso's ``ltc_aniso_npy`` (lutbake.kinds.ltc_aniso; the
preset's KTX 2.0 textures are lutbake's own layout: lutbake.layouts.plain)."""

from __future__ import annotations

from .base import EngineTable

SOURCE = "AakashKT/LTC-Anisotropic @ aa4db7c LUT/alphax_alphay_theta_phi.npy (fitting/fit_alphax_alphay_theta_phi.py)"
LAYOUTS = ()
TABLES = (
    EngineTable(
        "LTC-Anisotropic",
        "ltc-aniso",
        "ltc_aniso_paper",
        "ltc_aniso",
        None,
        {"parametrisation": "alphax_alphay", "size": 8, "dtype": "float32", "format": "ltc_aniso_npy"},
        SOURCE,
        "LUT/alphax_alphay_theta_phi.npy: M (8, 8, 8, 8, 3, 3) float32, no magnitude",
        shipped="ltc_aniso_alphax_alphay_theta_phi.npy",
    ),
)
