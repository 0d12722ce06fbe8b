"""L2 spherical harmonics of the lat-long source, by exact integration over every source texel, and the cosine
convolution that turns radiance coefficients into irradiance.

**Basis** (real SH, Ramamoorthi & Hanrahan 2001, "An Efficient Representation for Irradiance Environment Maps",
Eq. 3; the order and constants of three.js' ``SphericalHarmonics3``), on the world direction (x, y, z) of
lutbake.environment.latlong (y up), index k = l^2 + l + m:

    k  (l, m)   Y_k(x, y, z)
    0  (0, 0)   0.282095                       = 1 / (2 sqrt(pi))
    1  (1,-1)   0.488603 y                     = sqrt(3 / (4 pi)) y
    2  (1, 0)   0.488603 z
    3  (1, 1)   0.488603 x
    4  (2,-2)   1.092548 x y                   = sqrt(15 / (4 pi)) x y
    5  (2,-1)   1.092548 y z
    6  (2, 0)   0.315392 (3 z^2 - 1)           = sqrt(5 / (16 pi)) (3 z^2 - 1)
    7  (2, 1)   1.092548 x z
    8  (2, 2)   0.546274 (x^2 - y^2)           = sqrt(15 / (16 pi)) (x^2 - y^2)

orthonormal: ∫ Y_k Y_k' dω = δ_kk'. (R&H write (x, y, z) with z up; three.js and lutbake apply the same
polynomials to the y-up world's (x, y, z), so "z" here is a horizontal axis.)

**Coefficients**: L_k = ∫ L(ω) Y_k(ω) dω (radiance). With L texel-constant, L_k = Σ_texels L_texel ∫_texel Y_k dω,
and each monomial of Y_k over a lat-long cell is a product of a theta and a phi integral in closed form
(``_theta_integrals``, ``_phi_integrals``): exact, not the texel centre's value times its solid angle.

**Cosine convolution** (R&H 2001, Eqs. 8-9): irradiance E(n) = ∫ L (n.l)+ dω = Σ_k Â_l L_k Y_k(n), Â_0 = pi,
Â_1 = 2 pi / 3, Â_2 = pi / 4 (exact for L of bands <= 2; the band-2 truncation of the clamped cosine leaves a
residual of at most ~3% of E for arbitrary L, R&H §3). The forms an engine may take:
``radiance`` L_k; ``irradiance`` Â_l L_k (E = Σ c_k Y_k(n)); ``irradiance_over_pi`` Â_l L_k / pi (the diffuse
radiance of a white Lambertian surface, E / pi). three.js' ``SphericalHarmonics3.getIrradianceAt`` folds Â_l into
its constants (0.886227 = pi x 0.282095, ...) and takes the **radiance** coefficients (``LightProbeGenerator``).

``filament``: Â_l L_k K_k / pi with K_k the constant of Y_k above (``POLYNOMIAL_CONSTANTS``), so that
E(n) / pi = Σ c_k p_k(n) over the bare polynomials p_k = 1, y, z, x, xy, yz, 3z^2 - 1, xz, x^2 - y^2: what
Filament's shader evaluates (``Irradiance_SphericalHarmonics``: ``iblSH[0] + iblSH[1] * n.y + iblSH[2] * n.z + ...``),
``IndirectLight::Builder::irradiance(3, sh)`` takes, and cmgen writes (``--sh-shader``, its KTX's ``sh`` and
``sh.txt``: ``CubemapSH::preprocessSHForShader`` multiplies its coefficients by A_k = ±K_k Â_l / pi, the sign undoing
its basis's Condon-Shortley phase, so the products are the numbers above). Checked in closed form: L = a + b.ω gives
c = (a, 2/3 b_y, 2/3 b_z, 2/3 b_x, 0, ...); L = z^2 gives c_0 = 1/3, c_6 = 1/12. cmgen by default also windows its
coefficients against ringing (``--sh-window``, auto); lutbake writes them unwindowed.
"""

from __future__ import annotations

import math

import numpy as np

from .latlong import column_edges, row_edges

CONSTANTS = (
    1 / (2 * math.sqrt(math.pi)),
    math.sqrt(3 / (4 * math.pi)),
    math.sqrt(15 / (4 * math.pi)),
    math.sqrt(5 / (16 * math.pi)),
    math.sqrt(15 / (16 * math.pi)),
)
BAND = (0, 1, 1, 1, 2, 2, 2, 2, 2)
A_HAT = (math.pi, 2 * math.pi / 3, math.pi / 4)
# K_k: Y_k = K_k p_k(x, y, z), the constants of ``basis`` per index
POLYNOMIAL_CONSTANTS = tuple(CONSTANTS[i] for i in (0, 1, 1, 1, 2, 2, 3, 2, 4))
FORMS = {
    "radiance": "L_k = ∫ L Y_k dω",
    "irradiance": "Â_l L_k: E(n) = Σ c_k Y_k(n)",
    "irradiance_over_pi": "Â_l L_k / pi: E(n) / pi = Σ c_k Y_k(n)",
    "filament": "Â_l L_k K_k / pi: E(n) / pi = Σ c_k p_k(n), p = 1, y, z, x, xy, yz, 3z^2 - 1, xz, x^2 - y^2 "
    "(Filament's iblSH, cmgen's KTX 'sh')",
}


def basis(d: np.ndarray) -> np.ndarray:
    """(..., 9) Y_k at unit directions ``d`` (..., 3), the order above."""
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    c0, c1, c2, c20, c22 = CONSTANTS
    one = np.ones_like(x)
    return np.stack(
        [
            c0 * one,
            c1 * y,
            c1 * z,
            c1 * x,
            c2 * x * y,
            c2 * y * z,
            c20 * (3 * z * z - 1),
            c2 * x * z,
            c22 * (x * x - y * y),
        ],
        axis=-1,
    )


def _theta_integrals(h: int) -> dict[str, np.ndarray]:
    """Per row: ∫ f(theta) sin(theta) dtheta over the row for f in 1, cos, sin, cos^2, sin cos, sin^2."""
    t = row_edges(h)
    s, c = np.sin(t), np.cos(t)
    anti = {
        "1": -c,
        "c": s * s / 2,
        "s": t / 2 - np.sin(2 * t) / 4,
        "cc": -(c**3) / 3,
        "sc": s**3 / 3,
        "ss": -c + c**3 / 3,
    }
    return {k: np.diff(v) for k, v in anti.items()}


def _phi_integrals(w: int) -> dict[str, np.ndarray]:
    """Per column: ∫ g(phi) dphi over the column for g in 1, cos, sin, cos^2, sin cos, sin^2."""
    p = column_edges(w)
    anti = {
        "1": p,
        "c": np.sin(p),
        "s": -np.cos(p),
        "cc": p / 2 + np.sin(2 * p) / 4,
        "sc": np.sin(p) ** 2 / 2,
        "ss": p / 2 - np.sin(2 * p) / 4,
    }
    return {k: np.diff(v) for k, v in anti.items()}


def texel_integrals(h: int, w: int) -> np.ndarray:
    """(9, h, w) ∫_texel Y_k dω, exact: x = sin t cos p, y = cos t, z = sin t sin p, each monomial separable."""
    T, P = _theta_integrals(h), _phi_integrals(w)

    def mono(tf: str, pf: str) -> np.ndarray:
        return np.outer(T[tf], P[pf])

    c0, c1, c2, c20, c22 = CONSTANTS
    xx, yy, zz = mono("ss", "cc"), mono("cc", "1"), mono("ss", "ss")
    return np.stack(
        [
            c0 * mono("1", "1"),
            c1 * mono("c", "1"),
            c1 * mono("s", "s"),
            c1 * mono("s", "c"),
            c2 * mono("sc", "c"),
            c2 * mono("sc", "s"),
            c20 * (3 * zz - mono("1", "1")),
            c2 * mono("ss", "sc"),
            c22 * (xx - yy),
        ]
    )


def project(image: np.ndarray) -> np.ndarray:
    """(9, 3) radiance coefficients L_k of a texel-constant lat-long image (h, 2h, 3): Σ L_texel ∫_texel Y_k dω."""
    img = np.asarray(image, np.float64)
    h, w = img.shape[:2]
    return np.einsum("khw,hwc->kc", texel_integrals(h, w), img)


def convolve(coefficients: np.ndarray, form: str = "irradiance") -> np.ndarray:
    """The coefficients in ``form`` (FORMS) from radiance coefficients (9, C)."""
    if form not in FORMS:
        raise ValueError(f"SH form must be one of {sorted(FORMS)}, got {form!r}")
    if form == "radiance":
        return np.array(coefficients, np.float64)
    scale = np.array([A_HAT[b] for b in BAND]) / (1.0 if form == "irradiance" else math.pi)
    if form == "filament":
        scale = scale * np.array(POLYNOMIAL_CONSTANTS)
    return coefficients * scale[:, None]


def polynomials(d: np.ndarray) -> np.ndarray:
    """(..., 9) the bare polynomials p_k at directions ``d`` (..., 3): Y_k / K_k, what form ``filament`` multiplies."""
    return basis(np.asarray(d, np.float64)) / np.array(POLYNOMIAL_CONSTANTS)


def evaluate(coefficients: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Σ c_k Y_k(d): (..., C)."""
    return basis(np.asarray(d, np.float64)) @ coefficients
