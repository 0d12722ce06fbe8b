"""Fresnel terms against numpy references written here (complex arithmetic, Snell's law), published
values, and each approximation's maximum error against the exact curve (printed: pytest -s)."""

import numpy as np
import pytest

from lutbake.integrands.fresnel import evaluate, f_avg
from lutbake.metals import LAZANYI_ALPHA, METALS, fit_lazanyi_a, lookup_metal

F32_TOL = 2e-6  # float32 evaluation of an O(1) expression
C = np.concatenate([np.linspace(0.0, 1.0, 401), [1e-6, 1e-3, 0.999999]])


def fresnel_complex_ref(eta, c):
    """Unpolarised reflectance vacuum -> eta (complex), Snell's law sin_t = sin_i / eta in complex
    arithmetic, r_s = (c - eta c_t)/(c + eta c_t), r_p = (eta c - c_t)/(eta c + c_t)."""
    eta = np.complex128(eta)
    ct = np.sqrt(1 - (1 - c**2) / eta**2 + 0j)
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return 0.5 * (abs(rs) ** 2 + abs(rp) ** 2)


def eta_from_f0(f0):
    s = np.sqrt(f0)
    return (1 + s) / (1 - s)


def f0_of(n, k=0.0):
    return ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)


@pytest.mark.parametrize("metal", sorted(METALS))
def test_F_conductor_matches_complex_fresnel(metal):
    m = METALS[metal]
    for n, k in zip(m.n, m.k):
        got = evaluate(C, n=n, k=k)["conductor"]
        # float32: <= 2.2e-7 for every metal (silver's a2b2 + t0 cancelled to 2.1e-6 before F_conductor's k > n form)
        np.testing.assert_allclose(got, fresnel_complex_ref(n + 1j * k, C), atol=3e-7)


@pytest.mark.parametrize("n", [1.1, 1.33, 1.5, 2.4, 4.0])
def test_F_conductor_with_k0_is_the_dielectric(n):
    got = evaluate(C, f0=f0_of(n), n=n, k=0.0)
    ref = fresnel_complex_ref(n, C)
    np.testing.assert_allclose(got["conductor"], ref, atol=F32_TOL)
    np.testing.assert_allclose(got["dielectric_f0"], ref, atol=1e-5)  # Eq. 2 with f0 from the same n


def test_approximations_match_their_formulas():
    f0 = np.linspace(0.0, 1.0, 11)[:, None]
    got = evaluate(C[None, :], f0=f0, n=0.5, k=3.0, a=0.7)
    np.testing.assert_allclose(got["schlick"], f0 + (1 - f0) * (1 - C) ** 5, atol=F32_TOL)
    np.testing.assert_allclose(got["schlick_sg"], f0 + (1 - f0) * 2.0 ** ((-5.55473 * C - 6.98316) * C), atol=F32_TOL)
    np.testing.assert_allclose(got["improved_sg"], f0 + (1 - f0) * 2.0 ** (-9.60232 * C**8 - 8.58092 * C), atol=F32_TOL)
    n, k, a = 0.5, 3.0, 0.7
    ref = ((n - 1) ** 2 + 4 * n * (1 - C) ** 5 + k**2) / ((n + 1) ** 2 + k**2) - a * C * (1 - C) ** LAZANYI_ALPHA
    np.testing.assert_allclose(got["lazanyi"][0], ref, atol=F32_TOL)


def test_every_term_is_one_at_grazing_and_f0_at_normal():
    got = evaluate(np.array([0.0, 1.0]), f0=0.2, n=2.0, k=1.0, a=0.3)
    for name, F in got.items():
        assert F[0] == pytest.approx(1.0, abs=1e-6), name
    for name in ("schlick", "improved_sg", "dielectric_f0"):
        assert got[name][1] == pytest.approx(0.2, abs=1e-5), name
    assert got["schlick_sg"][1] == pytest.approx(0.2 + 0.8 * 2**-12.54, abs=1e-6)
    assert got["conductor"][1] == pytest.approx(f0_of(2.0, 1.0), abs=1e-6)
    assert got["lazanyi"][1] == pytest.approx(f0_of(2.0, 1.0), abs=1e-6)


LECTURE_F0 = {  # lecture 003, "Fresnel reflections at 0° for some materials" (linear)
    "copper": (0.95, 0.64, 0.54),
    "gold": (1.00, 0.71, 0.29),
    "aluminium": (0.91, 0.92, 0.92),
    "silver": (0.95, 0.93, 0.88),
}


@pytest.mark.parametrize("metal", sorted(METALS))
def test_metal_table_f0_is_near_the_lectures_f0(metal):
    np.testing.assert_allclose(METALS[metal].f0(), LECTURE_F0[metal], atol=0.15)
    assert lookup_metal("Aluminum") is METALS["aluminium"]


def test_F_avg_of_schlick_is_closed_form():
    for f0 in (0.0, 0.04, 0.5, 1.0):
        assert f_avg("schlick", f0=f0) == pytest.approx((20 * f0 + 1) / 21, abs=1e-6)
    assert f_avg("conductor", n=1.5, k=0.0) == pytest.approx(f_avg("dielectric_f0", f0=0.04), abs=1e-6)


DIELECTRIC_F0 = [0.02, 0.04, 0.08, 0.17]  # water, eta = 1.5, high glass, diamond


def test_approximation_errors_table():
    """Max |F_approx - F_exact| over theta per f0; the table is the issue's 'printed table'."""
    rows = []
    for f0 in DIELECTRIC_F0:
        exact = fresnel_complex_ref(eta_from_f0(f0), C)
        got = evaluate(C, f0=f0)
        rows.append(
            (
                f"dielectric f0={f0:.2f} (eta={eta_from_f0(f0):.3f})",
                {k: np.max(np.abs(got[k] - exact)) for k in ("schlick", "schlick_sg", "improved_sg", "dielectric_f0")},
            )
        )
    for name, m in sorted(METALS.items()):
        for ch, (n, k) in zip("RGB", zip(m.n, m.k)):
            exact = fresnel_complex_ref(n + 1j * k, C)
            f0 = f0_of(n, k)
            a = fit_lazanyi_a(n, k)
            got = evaluate(C, f0=f0, n=n, k=k, a=a)
            rows.append(
                (
                    f"{name} {ch} {n}+{k}i f0={f0:.3f} a={a:.3f}",
                    {
                        k_: np.max(np.abs(got[k_] - exact))
                        for k_ in ("schlick", "schlick_sg", "improved_sg", "dielectric_f0", "lazanyi")
                    },
                )
            )
    cols = ("schlick", "schlick_sg", "improved_sg", "dielectric_f0", "lazanyi")
    print("\n" + f"{'max |F - F_exact|':<44}" + "".join(f"{c:>14}" for c in cols))
    for label, errs in rows:
        print(f"{label:<44}" + "".join(f"{errs[c]:>14.2e}" if c in errs else f"{'-':>14}" for c in cols))
    by = dict(rows)
    eta15 = by[[r for r in by if r.startswith("dielectric f0=0.04")][0]]
    assert eta15["dielectric_f0"] < 1e-5  # Eq. 2 is exact
    assert eta15["improved_sg"] < eta15["schlick"]  # Eq. 3 is fitted to eta = 1.5
    for label, errs in rows:
        if "lazanyi" in errs:
            assert errs["lazanyi"] < errs["schlick"], label  # the fit improves on Schlick for every metal channel
