"""The LTC tables' magnitude and fresnel channels (kind ``ltc``, lutbake.kinds.ltc): the exact integrals of a lobe per
texel, from lutbake's integrands and estimators (lutbake.integrands, lutbake.sampling), not fitted; and the texels'
(NoV, alpha) the fit and the integrals take.

magnitude = ∫ f (n.l) dω with F = 1, fresnel = ∫ f (1 - v.h)^5 (n.l) dω: GGX / Beckmann by the ``albedo`` and the
``dfg`` multiscatter integrands (the same integrands and hemisphere estimator as those tables), charlie by the ``dfg``
charlie integrand, the diffuse lobes by the ``diffuse`` tables' integrand and estimator
(lutbake.sampling.diffuse_table), a lobe no integrator has by lutbake.ltc.fit's quadrature of f (n.l).
"""

from __future__ import annotations

import numpy as np

from ..axes import Axis
from ..edge import ALPHA_MIN

MAGNITUDE_SAMPLES = {"ggx": 432, "beckmann": 432, "charlie": 3072, "lambert": 0}  # diffuse lobes: the diffuse kind's


def lobe_parameter(rough: Axis) -> np.ndarray:
    """The lobe's parameter per roughness index: the NDF alpha of the axis, or (EON) the axis value itself."""
    a = rough.alpha()
    return rough.values() if a is None else a


def texel_params(axes: list[Axis], alpha_min: float = ALPHA_MIN) -> tuple[np.ndarray, np.ndarray]:
    """Per texel of one slice, row-major (y = view slowest): (NoV, alpha) as float32, alpha >= alpha_min (the
    alpha fitted: an LTC of a Dirac lobe is not defined)."""
    _, view, rough = axes
    alpha = np.maximum(lobe_parameter(rough), np.float32(alpha_min))
    return np.repeat(view.values(), rough.count), np.tile(alpha, view.count)


def magnitude_alpha(axes: list[Axis], alpha_min: float = ALPHA_MIN) -> np.ndarray:
    """The alpha at which magnitude and fresnel are integrated: the axis alpha itself under lutbake's edge policy
    (alpha -> 0: the exact mirror limit, as the ``albedo`` table), or alpha_min where a larger one is set."""
    _, view, rough = axes
    a = lobe_parameter(rough)
    if alpha_min > ALPHA_MIN:
        a = np.maximum(a, np.float32(alpha_min))
    return np.tile(a, view.count)


def magnitude_fresnel(
    lobe_of,
    nov: np.ndarray,
    alpha: np.ndarray,
    samples: int | None,
    device: str = "cpu",
    estimator: str = "gauss_legendre",
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """(magnitude, fresnel) per texel from lutbake's integrators (``estimator``, default Gauss-Legendre). A plugin's
    lobe: lobe_magnitude. GGX / Beckmann: magnitude is the ``albedo`` kind's integrand (so it equals that table at the
    same texels), fresnel the ``dfg`` multiscatter integrand's Fc channel; charlie: the ``dfg`` charlie layout's B
    channel (the gltf-charlie table), fresnel = magnitude; lambert: 1; gotanda, eon: the ``diffuse`` kind's integrator
    and integrand (its default GL order unless ``samples``; ``alpha`` = sigma resp. EON's r), fresnel = magnitude.
    ``alpha`` goes through the integrands' edge policy (mirror limit at alpha -> 0)."""
    from ..integrands.specular import specular_integrand
    from ..sampling.hemisphere import estimator_for
    from .lobes import lobe

    lb = lobe(lobe_of)  # a Lobe, or the name of one of lutbake's
    if lb.magnitude == "lambert":
        one = np.ones(len(nov))
        return one, one.copy()
    if lb.magnitude == "lobe_adaptive":  # a plugin's lobe: the diffuse kind's rule, orders raised to the tolerance
        m, _, _ = lobe_magnitude(lb, nov, alpha, device)
        return m, m.copy()
    if lb.magnitude == "lobe":  # no other integrator has the lobe: lutbake.ltc.fit's quadrature of f_cos
        from . import fit

        m = fit.lobe_albedo(fit.Problem(lb, nov, alpha, np.zeros(len(nov)), device=device))
        return m, m.copy()
    if lb.magnitude.startswith("diffuse:"):
        m = diffuse_magnitude(lb.magnitude.split(":")[1], nov, alpha, samples, device)
        return m, m.copy()
    if estimator == "gauss_legendre":
        samples = samples or MAGNITUDE_SAMPLES[lb.name]
    est = estimator_for(estimator, samples, seed)
    nov = np.asarray(nov, np.float32)
    zero = np.zeros(len(nov), np.float32)

    def integrate(integrand):
        inputs = {"nov": nov, "alpha": integrand.alpha_input(alpha), "param": zero}
        est.prepare(integrand, device)  # compiled once, whichever table asks first (tables prepare in parallel)
        return est.evaluate(integrand, inputs, device)

    _, which = lb.magnitude.split(":")
    if which == "charlie":
        m = integrate(specular_integrand("ggx", "smith_height_correlated", "charlie"))[:, 2]
        return m, m.copy()
    mag = integrate(specular_integrand(which, "smith_height_correlated", "albedo", "microfacet", 1))[:, 0]
    fres = integrate(specular_integrand(which, "smith_height_correlated", "multiscatter"))[:, 0]
    return mag, fres


LOBE_ORDERS = (24, 32, 48, 64)  # lobe_magnitude's Gauss-Legendre orders per panel and dimension


def lobe_magnitude(lb, nov, x, device: str = "cpu", tolerance=None) -> tuple[np.ndarray, float, bool]:
    """(∫ f (n.l) dω_l per texel, its error estimate, whether it met ``tolerance``) of a plugin's lobe
    (lutbake.integrands.diffuse.lobe_integrand) by the diffuse kind's Gauss-Legendre rule over l (2 x 2 panels split
    at n.l = n.v and phi = pi/2), its order raised through LOBE_ORDERS until two successive agree within the
    tolerance (a lutbake.tolerance.Tolerance: max(absolute, relative |E|); default float32's) at every texel; else
    the last, its estimate that difference."""
    from ..integrands.diffuse import lobe_integrand
    from ..sampling.diffuse import DiffuseGaussLegendre
    from ..sampling.diffuse_table import diffuse_grid
    from ..tolerance import default_tolerance

    integrand = lobe_integrand(lb)
    inputs = diffuse_grid(
        [], np.asarray(nov, np.float32), np.asarray(x, np.float32), np.zeros(len(nov)), "sigma"
    ).inputs
    tol = tolerance or default_tolerance({})
    last = None
    for order in LOBE_ORDERS:
        est = DiffuseGaussLegendre(order)
        est.prepare(integrand, device)
        value = est.evaluate(integrand, inputs, device)[:, 0]
        if last is not None:
            diff = np.abs(value - last)
            met = bool(np.all(diff <= np.maximum(tol.absolute, tol.relative * np.abs(value))))
            if met:
                break
        last = value
    return value, float(np.max(diff)), met


def diffuse_magnitude(model: str, nov, sigma, samples: int | None, device: str = "cpu") -> np.ndarray:
    """E(n.v) = ∫ f (n.l) dω_l (rho = 1, f0 = 0) exactly as the ``diffuse`` kind integrates ``model`` at these
    texels (its grid inputs, its Gauss-Legendre estimator and default order), so the magnitude equals that table."""
    from ..integrands.diffuse import diffuse_integrand
    from ..sampling.diffuse_table import diffuse_grid, estimator_of

    o = {"estimator": "gauss_legendre", "samples": samples, "model": model, "seed": 0}
    nov = np.asarray(nov, np.float32)
    grid = diffuse_grid([], nov, np.asarray(sigma, np.float32), np.zeros(len(nov)), "sigma")
    est = estimator_of(o)
    integrand = diffuse_integrand(model)
    est.prepare(integrand, device)
    return est.evaluate(integrand, grid.inputs, device)[:, 0]
