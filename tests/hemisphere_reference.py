"""scipy reference integrals over the light hemisphere, shared by the engine-preset tests (independent of lutbake)."""

import numpy as np
from scipy import integrate


def hemisphere_integral(f, nov):
    """∫ f(n.l, n.h, v.h) dω_l over the upper hemisphere by scipy's dblquad in (mu = n.l, phi), v = (sqrt(1 - nov²), 0,
    nov); f is even in phi (isotropic), so 2 ∫_0^pi. ``f`` includes any (n.l) factor."""
    sv = np.sqrt(1.0 - nov * nov)

    def g(phi, mu):
        sl = np.sqrt(1.0 - mu * mu)
        h = np.array([sv + sl * np.cos(phi), sl * np.sin(phi), nov + mu])
        h /= np.linalg.norm(h)
        return f(mu, h[2], sv * h[0] + nov * h[2])

    return 2.0 * integrate.dblquad(g, 0.0, 1.0, 0.0, np.pi, epsabs=1e-10, epsrel=1e-8)[0]


def hemisphere_cubature(f, nov, rule, mu_singular=(), **grading):
    """The integral of ``hemisphere_integral`` by a tensor graded Gauss-Legendre rule in (mu, phi), vectorised:
    ``rule`` is conftest's graded_rule (graded_gauss_legendre); it grades toward mu = 0, 1 (|n.l|^c fits,
    sqrt(1 - mu²)), the mirror direction (mu = nov, phi = pi: the lobes' peak, a cone of sin(θ_h)^(1/alpha)),
    phi = 0 and ``mu_singular`` (a fit's branch). ``f`` takes numpy arrays (mu column, phi row broadcast)."""
    mu, w_mu = rule(0.0, 1.0, [0.0, 1.0, nov, *mu_singular], **grading)
    phi, w_phi = rule(0.0, np.pi, [0.0, np.pi], **grading)
    sv, sl, mu = np.sqrt(1.0 - nov * nov), np.sqrt(1.0 - mu * mu)[:, None], mu[:, None]
    hx, hy, hz = sv + sl * np.cos(phi), sl * np.sin(phi), nov + mu
    norm = np.sqrt(hx * hx + hy * hy + hz * hz)
    return 2.0 * float(np.einsum("i,ij,j->", w_mu, f(mu, hz / norm, (sv * hx + nov * hz) / norm), w_phi))
