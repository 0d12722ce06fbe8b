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
