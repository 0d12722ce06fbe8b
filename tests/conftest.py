"""Shared test setup and the helpers every test file uses (request them as fixtures; never copy them).

- ``spec(defaults={}, **keys)``: one ``[[table]]`` mapping, ``{**defaults, **keys}``, validated as a config
  would be (``name`` defaults to "t"); a test file keeps its common keys in one dict and passes it first.
- ``bake(defaults={}, workers=2, **keys)``: that spec baked to a Table (nothing written).
- ``bake_preset(name, *overrides)``: a preset, with ``--set``-style overrides, as ``(spec, Table)``.
- ``shipped(name)``: a published engine table from tests/data/ (values as float64; provenance in its .json).
- ``graded_rule(a, b, singular)``: nodes and weights of a Gauss-Legendre rule graded toward the points
  where an integrand is not analytic (a converged reference in a few thousand nodes, not a brute-force grid).
- ``charlie_reference(alpha, nov, visibility, clamp=False)``: ∫ D_charlie V (n.l) dω_l by that rule in
  numpy, independent of lutbake's @wp.funcs (the sheen and Filament cloth tests compare with it).
- ``terminal_sigint``: SIGINT raises KeyboardInterrupt during the test, also under ``make test &``.
"""

import os
import signal
import sys
from pathlib import Path

# One OpenBLAS thread in the xdist workers and the processes tests start (they inherit this; numpy is already loaded
# in this process by a plugin, so it keeps its pool). With every core busy, a threaded dot of ~1e4 elements waits for
# its helper thread to be scheduled: harmonic.kernel_coefficients' 1535 dots took 16 s instead of 0.3 s beside two
# busy cores, in both workers of `make test`. The values are those of any thread count to the dot's rounding.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pytest
import warp as wp

from lutbake.api import bake_table
from lutbake.config import load_config, parse_overrides, preset_path, validate_table

DATA = Path(__file__).resolve().parent / "data"

# pytest keeps each test module's assertion-rewritten bytecode in tests/__pycache__ (gitignored), unless bytecode is
# not written (PYTHONDONTWRITEBYTECODE=1); without it every xdist worker rewrites and compiles all ~90 test modules
# again in every run: ~4 s of each worker's ~8 s collection. Written atomically, read back only while up to date.
sys.dont_write_bytecode = False


# The modules with the most test time, longest first (measured with `make test`'s invocation on 2 cores: the web
# modules' time is mostly Chromium's). `make test` runs whole modules per xdist worker in collection order (--dist
# loadscope --no-loadscope-reorder), each worker taking the next module as it finishes one, so the long ones start
# first and both workers finish together (longest-processing-time-first); every other module keeps its file order.
SLOW_FIRST = (
    "test_web_rectarea", "test_audit", "test_outputs", "test_environment", "test_web_threejs", "test_dielectric",
    "test_web_filament", "test_cluster", "test_environment_kinds", "test_validate", "test_web_babylon_environment",
    "test_integrity", "test_web_babylon", "test_interpolation", "test_ltc", "test_pipeline", "test_cube_audit",
    "test_babylon", "test_quiet_lazy", "test_environment_render", "test_ltc_shaded", "test_batch",
)  # fmt: skip


def pytest_collection_modifyitems(items):
    rank = {name: i for i, name in enumerate(SLOW_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.stem, len(SLOW_FIRST)))


@pytest.fixture(scope="session", autouse=True)
def warp_quiet():
    wp.config.quiet = True
    wp.init()


# ---------------------------------------------------------------------------------- specs and bakes


def make_spec(defaults=None, /, **keys):
    return validate_table({"name": "t", **(defaults or {}), **keys}, "<test>", 0)


def bake_spec(defaults=None, /, workers=2, **keys):
    return bake_table(make_spec(defaults, **keys), workers=workers)[0]


def bake_named_preset(name, *overrides):
    (spec,) = load_config(preset_path(name), parse_overrides(list(overrides)))
    return spec, bake_table(spec)[0]


@pytest.fixture(scope="session")
def spec():
    """``spec(defaults={}, **keys)`` -> TableSpec: the keys of one [[table]] (``name`` defaults to "t"), validated."""
    return make_spec


@pytest.fixture(scope="session")
def bake():
    """``bake(defaults={}, workers=2, **keys)`` -> Table: that spec baked (the output is the same for any workers)."""
    return bake_spec


@pytest.fixture(scope="session")
def bake_preset():
    """``bake_preset(name, *overrides)`` -> (TableSpec, Table); overrides as ``--set`` takes them ("size=[32, 32]")."""
    return bake_named_preset


# ------------------------------------------------------------------------- published engine tables


def load_shipped(name):
    """tests/data/<name>.npz (array ``table``) as float64 values: 8-bit codes (uint8) become code / 255."""
    a = np.load(DATA / f"{name}.npz")["table"]
    return a / 255.0 if a.dtype == np.uint8 else a.astype(np.float64)


@pytest.fixture(scope="session")
def shipped():
    """``shipped(name)`` -> float64 array of an engine's published table, rows/channels as that engine stores them."""
    return load_shipped


# ------------------------------------------------------------- a converged reference for the sheen lobe


def graded_gauss_legendre(a, b, singular, ratio=0.25, levels=18, order=12):
    """Nodes and weights of a composite Gauss-Legendre rule on [a, b] whose panels shrink geometrically
    (by ``ratio``, ``levels`` times) toward each point of ``singular`` from both sides: an hp-graded rule
    that converges exponentially for integrands analytic between those points (kinks, |x|^c endpoint
    behaviour and sharp peaks at the points are resolved by the grading)."""
    cuts = {a, b}
    for p in singular:
        if a <= p <= b:
            cuts.add(p)
            for end in (a, b):
                cuts.update(p + (end - p) * ratio**k for k in range(1, levels + 1))
    cuts = np.array(sorted(cuts))
    cuts = cuts[np.concatenate([[True], np.diff(cuts) > 1e-14])]
    x, w = np.polynomial.legendre.leggauss(order)
    lo, hi = cuts[:-1, None], cuts[1:, None]
    return ((lo + hi) / 2 + (hi - lo) / 2 * x).ravel(), ((hi - lo) / 2 * w).ravel()


def lambda_sheen(c, alpha):
    """KHR_materials_sheen README, "Sheen visibility" (Estevez & Kulla 2017 fit), written out from the spec."""
    t = (1 - alpha) ** 2
    A, B, C = 21.5473 + 3.7772 * t, 3.82987 - 0.50552 * t, 0.19823 - 0.03022 * t
    D, E = -1.97760 + 0.70367 * t, -4.32054 - 0.53913 * t

    def l(x):
        return A / (1 + B * np.abs(x) ** C) + D * x + E

    return np.where(np.abs(c) < 0.5, np.exp(l(c)), np.exp(2 * l(0.5) - l(1 - c)))


def sheen_visibility(nol, nov, alpha, visibility, clamp=False):
    """V of the KHR spec's GLSL: "ashikhmin" 1 / (4 (NoL + NoV - NoL NoV)); "charlie" the Lambda-fit form.
    ``clamp``: min(V, 1), as the glTF Sample Viewer's V_Ashikhmin / V_Sheen."""
    if visibility == "ashikhmin":
        v = 1 / (4 * (nol + nov - nol * nov))
    else:
        v = 1 / ((1 + lambda_sheen(nov, alpha) + lambda_sheen(nol, alpha)) * 4 * nov * nol)
    return np.minimum(v, 1.0) if clamp else v


def integrate_charlie(alpha, nov, visibility, clamp=False, **rule):
    """∫ D_charlie(h) V (n.l) dω_l over the hemisphere, D_charlie = (2 + 1/alpha) sin(θ_h)^(1/alpha) / (2π)
    (Estevez & Kulla 2017), in (θ_l, φ_l) ∈ [0, π/2] x [0, π], doubled by the mirror symmetry φ -> -φ.

    Graded Gauss-Legendre (``graded_gauss_legendre``) toward every place the integrand is not analytic:
    θ_l = π/2 (the Charlie Lambda fit has |n.l|^0.2; the peak of sin(θ_h)^(1/alpha) for small alpha lies
    there), the mirror direction θ_l = acos(NoV) with φ_l = π (sin θ_h = 0, a cone for alpha > 1/2),
    n.l = 1/2 (the fit's branch), the kinks of min(V, 1) where V(n.l) = 1, and φ_l = 0, π.

    Converged: with ratio 0.15, 30 levels, order 20 instead it changes by < 3e-11 relative on every texel
    the tests use, and scipy's dblquad (epsrel 1e-11) agrees to 1e-11. The 3000x3000 midpoint rule these
    tests used before agrees to its own error (2.5e-4 at alpha = 1.4e-4, NoV = 1/256; <= 5e-6 elsewhere).
    """
    theta_singular = [0.0, np.pi / 2, np.arccos(nov), np.pi / 3]
    if clamp:  # V depends on n.l only: min(V, 1) kinks at the roots of V(n.l) = 1, bracketed on a fine grid
        mu = np.linspace(0.0, 1.0, 20001)[1:]
        f = sheen_visibility(mu, nov, alpha, visibility) - 1
        for i in np.nonzero(np.sign(f[1:]) != np.sign(f[:-1]))[0]:
            lo, hi = mu[i], mu[i + 1]
            for _ in range(60):  # bisection to double precision
                mid = (lo + hi) / 2
                same_side = np.sign(sheen_visibility(mid, nov, alpha, visibility) - 1) == np.sign(f[i])
                lo, hi = (mid, hi) if same_side else (lo, mid)
            theta_singular.append(np.arccos((lo + hi) / 2))
    th, w_th = graded_gauss_legendre(0.0, np.pi / 2, theta_singular, **rule)
    ph, w_ph = graded_gauss_legendre(0.0, np.pi, [0.0, np.pi], **rule)
    nol, sin_l = np.cos(th)[:, None], np.sin(th)[:, None]
    hx, hy, hz = sin_l * np.cos(ph) + np.sqrt(1 - nov * nov), sin_l * np.sin(ph), nol + nov  # h = l + v, unnormalised
    sin2_h = (hx * hx + hy * hy) / (hx * hx + hy * hy + hz * hz)
    d = (2 + 1 / alpha) * sin2_h ** (0.5 / alpha) / (2 * np.pi)
    v = sheen_visibility(nol, nov, alpha, visibility, clamp)
    return 2 * float(np.einsum("i,ij,j->", w_th, d * v * nol * sin_l, w_ph))


@pytest.fixture(scope="session")
def graded_rule():
    """``graded_rule(a, b, singular)`` -> (nodes, weights) of graded_gauss_legendre on [a, b]."""
    return graded_gauss_legendre


@pytest.fixture(scope="session")
def charlie_reference():
    """``charlie_reference(alpha, nov, "ashikhmin" | "charlie", clamp=False)`` -> float (see integrate_charlie)."""
    return integrate_charlie


@pytest.fixture
def terminal_sigint():
    """SIGINT raises KeyboardInterrupt, as in a terminal (a shell's background job inherits SIG_IGN for it)."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)
