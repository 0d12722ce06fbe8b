"""The ground truth a split sum approximates: per pixel (normal n, view v) the BRDF integrated against the
texel-constant lat-long environment, deterministically, by a sum over every source texel.

    L_o(n, v) = ∫ L(l) f(l, v) (n.l)+ dω_l = Σ_texels L_texel ∫_texel f(l, v) (n.l)+ dω_l

Each texel's integral is a q x q Gauss–Legendre product rule in (cos theta, phi) over the texel's cell
(lutbake.environment.latlong's convention: dω = d(cos theta) dphi, so the weights are the cell's exact measure and
q = 1 gives its exact solid angle). q grows where the weight varies across the texel: with Δ = pi / H the texel's
angular size, d the angle from its centre to the lobe's peak (the mirror direction R for the specular lobe, n for the
diffuse ones), λ the lobe's width and S its relative slope (lutbake.environment.lobes: λ = 2 atan(alpha), S = 4 for
GGX; π / 3, 2 for a diffuse lobe) and K the geometric factor,

    q = min(1 + floor(K S Δ / (max(d - Δ, 0) + λ)), Q_MAX) + extra,   (at least 2 where the texel may meet the horizon)

so the rule resolves the lobe's peak, and a texel far from it takes one node (two with the default extra = 1). The
horizon n.l = 0 is no kink inside a rule: on each meridian phi of a node the cos theta interval is clipped exactly
where n.l changes sign (``visible``), and a cell the horizon may cross is split in phi where it crosses the cell's
edges (``horizon_breaks``), so every piece's clipped length is smooth in phi. Sums in float64, in a fixed order: the
same bits on every run. **Error**: evaluate probe pixels again with ``Quality.refined()`` (K x 2, one node more per
axis in every texel; lutbake.commands.spheres does, every 4th pixel, and the pictures state the difference). A lobe
narrower than K S Δ / Q_MAX is under-resolved at its peak, and the refined rule shows it.

**Lobes** (each returns (a, b) per direction, summed separately):
- ``specular``: GGX D (Walter et al. 2007, Eq. 33), height-correlated Smith G2 (Heitz 2014, Eq. 99), Schlick's F
  (1994), f = D G2 F / (4 (n.l)(n.v)); F = f0 (1 - Fc) + Fc with Fc = (1 - v.h)^5 is linear in f0, so one sum gives
  the pair (∫ L f/F (1 - Fc) (n.l), ∫ L f/F Fc (n.l)) and L_o = f0 a + b for every f0 (the split sum's DFG pair:
  lutbake's dfg table holds the same two integrals for L = 1). alpha < ALPHA_MIN (lutbake.edge) takes the mirror
  limit exactly: L(R) (f0 (1 - Fc(n.v)) + Fc(n.v)), L(R) the texel holding R.
- ``diffuse``: a diffuse record's BRDF (lutbake.integrands.diffuse.brdf_for: Lambert, Oren–Nayar, Gotanda's
  microfacet model ...) in the frame (t, b, n), t along v's tangent part, for rho = 1: a = ∫ L f (n.l).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
import warp as wp

from ..edge import ALPHA_MIN, COS_EPS
from ..runtime.warp_runtime import kernel_factory, load_module, unique_kernel
from ..sampling import points
from ..terms.fresnel import Fc_schlick
from ..terms.masking import G2_smith_height_correlated, Lambda_ggx
from ..terms.ndf import D_ggx
from . import latlong
from .lobes import LOBES, lobe_width
from .render import reflect

Q_MAX = 128  # nodes per axis and texel, before ``extra``


@dataclass(frozen=True)
class Quality:
    """The texel rule's controls (module docstring): ``k`` the geometric factor K, ``extra`` nodes added per axis
    in every texel."""

    k: float = 8.0
    extra: int = 1

    def refined(self) -> Quality:
        return Quality(self.k * 2, self.extra + 1)


@wp.func
def ggx_pair(
    l: wp.vec3d, n: wp.vec3d, v: wp.vec3d, t: wp.vec3d, b: wp.vec3d, p: wp.vec4, rule: wp.array(dtype=wp.vec2d)
):
    """(f/F (1 - Fc) (n.l), f/F Fc (n.l)) of GGX, height-correlated Smith, Schlick at alpha = p[0] (module
    docstring): f/F (n.l) = D G2 / (4 n.v); 0 below either horizon."""
    NoL = wp.dot(n, l)
    NoV = wp.dot(n, v)
    if NoL <= wp.float64(COS_EPS) or NoV <= wp.float64(COS_EPS):
        return wp.vec2d(wp.float64(0.0), wp.float64(0.0))
    h = wp.normalize(l + v)
    d = D_ggx(wp.vec3(float(wp.length(wp.cross(n, h))), 0.0, float(wp.dot(n, h))), p[0])
    g2 = G2_smith_height_correlated(Lambda_ggx(float(NoV), p[0]), Lambda_ggx(float(NoL), p[0]))
    fc = wp.float64(Fc_schlick(float(wp.dot(v, h))))
    common = wp.float64(d * g2) / (wp.float64(4.0) * NoV)
    return wp.vec2d(common * (wp.float64(1.0) - fc), common * fc)


@kernel_factory
def diffuse_pair(brdf):
    """The lobe (f (n.l), 0) of a diffuse BRDF ``brdf(l, v, sigma, alpha, f0, rule)`` (shading frame, n = +z;
    lutbake.integrands.diffuse.brdf_for) at sigma = p[1], alpha = p[0], f0 = p[2]."""

    @wp.func
    def pair(
        l: wp.vec3d, n: wp.vec3d, v: wp.vec3d, t: wp.vec3d, b: wp.vec3d, p: wp.vec4, rule: wp.array(dtype=wp.vec2d)
    ):
        NoL = wp.dot(n, l)
        if NoL <= wp.float64(COS_EPS):
            return wp.vec2d(wp.float64(0.0), wp.float64(0.0))
        ll = wp.vec3(float(wp.dot(l, t)), float(wp.dot(l, b)), float(NoL))
        vv = wp.vec3(float(wp.dot(v, t)), float(wp.dot(v, b)), float(wp.dot(v, n)))
        return wp.vec2d(brdf(ll, vv, p[1], p[0], p[2], rule) * NoL, wp.float64(0.0))

    return pair


@wp.func
def tangent(n: wp.vec3d, v: wp.vec3d):
    """t: v's part across n, normalised; any unit vector across n where v is along it."""
    t = v - wp.dot(n, v) * n
    if wp.length(t) < wp.float64(1.0e-9):
        t = wp.cross(n, wp.vec3d(wp.float64(1.0), wp.float64(0.0), wp.float64(0.0)))
        if wp.length(t) < wp.float64(1.0e-6):
            t = wp.cross(n, wp.vec3d(wp.float64(0.0), wp.float64(0.0), wp.float64(1.0)))
    return wp.normalize(t)


@wp.func
def texel_order(c: wp.vec3d, n: wp.vec3d, peak: wp.vec3d, control: wp.vec4d, qmax: int):
    """q of the texel centred at c (module docstring); control = (Δ, λ, K, extra); 0: the texel lies wholly below
    the horizon."""
    delta = control[0]
    nc = wp.dot(c, n)
    if nc < -wp.sin(delta):
        return 0
    ang = wp.acos(wp.clamp(wp.dot(c, peak), wp.float64(-1.0), wp.float64(1.0)))
    q = 1 + int(control[2] * delta / (wp.max(ang - delta, wp.float64(0.0)) + control[1]))
    if nc < wp.sin(delta):
        q = wp.max(q, 2)
    return wp.min(q, qmax) + int(control[3])


@wp.func
def visible(mu_lo: wp.float64, mu_hi: wp.float64, n: wp.vec3d, cp: wp.float64, sp: wp.float64):
    """The part of [mu_lo, mu_hi] on the meridian phi (cos, sin = cp, sp) above the horizon n.l >= 0: with
    A = n_x cos phi + n_z sin phi, R = sqrt(n_y^2 + A^2), n.l = n_y mu + A sin theta vanishes once on the meridian,
    at mu = -A / R (n_y >= 0: visible above it) or A / R (n_y < 0: below it). (lo, hi), empty when lo >= hi."""
    a = n[0] * cp + n[2] * sp
    r = wp.sqrt(n[1] * n[1] + a * a)
    if r <= wp.float64(0.0):
        return wp.vec2d(mu_hi, mu_hi)
    if n[1] >= wp.float64(0.0):
        return wp.vec2d(wp.max(mu_lo, -a / r), mu_hi)
    return wp.vec2d(mu_lo, wp.min(mu_hi, a / r))


Breaks = wp.types.vector(length=5, dtype=wp.float64)  # phi0 and at most four crossings


@wp.func
def horizon_breaks(mu_lo: wp.float64, mu_hi: wp.float64, phi0: wp.float64, phi1: wp.float64, n: wp.vec3d):
    """The azimuths in (phi0, phi1) where the horizon n.l = 0 crosses the cell's edges mu = mu_lo, mu_hi (where
    ``visible``'s clipped length has a kink), sorted, after phi0: (breaks, count including phi0). On the edge mu,
    n.l = 0 where n_x cos phi + n_z sin phi = -n_y mu / sqrt(1 - mu^2)."""
    bp = Breaks()
    bp[0] = phi0
    count = wp.int32(1)  # dynamic (a literal is a constant to Warp)
    rad = wp.sqrt(n[0] * n[0] + n[2] * n[2])
    base = wp.atan2(n[2], n[0])
    two_pi = wp.float64(2.0 * math.pi)
    for e in range(2):
        mu = mu_lo
        if e == 1:
            mu = mu_hi
        s = wp.sqrt(wp.max(wp.float64(1.0) - mu * mu, wp.float64(0.0)))
        if s > wp.float64(1.0e-12) and rad > wp.float64(1.0e-15):
            c = -n[1] * mu / (s * rad)
            if wp.abs(c) < wp.float64(1.0):
                half = wp.acos(c)
                for sign in range(2):
                    phi = base + half
                    if sign == 1:
                        phi = base - half
                    phi = phi - two_pi * wp.floor((phi - phi0) / two_pi)
                    if phi > phi0 and phi < phi1:
                        bp[count] = phi
                        count += 1
    for a in range(1, count):  # insertion sort
        k = a
        while k > 0 and bp[k - 1] > bp[k]:
            tmp = bp[k]
            bp[k] = bp[k - 1]
            bp[k - 1] = tmp
            k -= 1
    return bp, count


@kernel_factory
def truth_kernel(pair):
    """The kernel summing ``pair`` (ggx_pair or a diffuse_pair) against every texel per pixel: out[i] = (Σ L a,
    Σ L b) as 6 float64 (module docstring)."""

    @wp.func
    def panel(
        mu_lo: wp.float64,
        mu_hi: wp.float64,
        phi0: wp.float64,
        phi1: wp.float64,
        q: int,
        nodes: wp.array(dtype=wp.vec2d),
        n: wp.vec3d,
        v: wp.vec3d,
        t: wp.vec3d,
        b: wp.vec3d,
        params: wp.vec4,
        rule: wp.array(dtype=wp.vec2d),
    ):
        """(∫ a dω, ∫ b dω) over the cell [mu_lo, mu_hi] x [phi0, phi1] above the horizon: q x q GL, each meridian's
        mu interval clipped by ``visible``."""
        first = q * (q - 1) // 2  # the q-point rule's rows in ``nodes``
        zero = wp.float64(0.0)
        total = wp.vec2d(zero, zero)
        for c in range(q):
            nc = nodes[first + c]
            phi = phi0 + (phi1 - phi0) * nc[0]
            cp = wp.cos(phi)
            sp = wp.sin(phi)
            span = visible(mu_lo, mu_hi, n, cp, sp)
            dmu = span[1] - span[0]
            if dmu > zero:
                inner = wp.vec2d(zero, zero)
                for a in range(q):
                    na = nodes[first + a]
                    mu = span[0] + dmu * na[0]
                    s = wp.sqrt(wp.max(wp.float64(1.0) - mu * mu, zero))
                    inner += na[1] * pair(wp.vec3d(s * cp, mu, s * sp), n, v, t, b, params, rule)
                total += nc[1] * dmu * inner
        return total * (phi1 - phi0)

    @unique_kernel
    def kernel(
        normals: wp.array(dtype=wp.vec3d),
        views: wp.array(dtype=wp.vec3d),
        peaks: wp.array(dtype=wp.vec3d),
        radiance: wp.array(dtype=wp.vec3d),
        centres: wp.array(dtype=wp.vec3d),
        mu_edges: wp.array(dtype=wp.float64),
        phi_edges: wp.array(dtype=wp.float64),
        nodes: wp.array(dtype=wp.vec2d),
        rule: wp.array(dtype=wp.vec2d),
        params: wp.vec4,
        control: wp.vec4d,
        qmax: int,
        out: wp.array2d(dtype=wp.float64),
    ):
        i = wp.tid()
        n = normals[i]
        v = views[i]
        t = tangent(n, v)
        b = wp.cross(n, t)
        width = phi_edges.shape[0] - 1
        zero = wp.float64(0.0)
        sin_delta = wp.sin(control[0])
        sa = wp.vec3d(zero, zero, zero)
        sb = wp.vec3d(zero, zero, zero)
        for row in range(mu_edges.shape[0] - 1):
            mu_hi = mu_edges[row]
            mu_lo = mu_edges[row + 1]
            for col in range(width):
                L = radiance[row * width + col]
                c = centres[row * width + col]
                q = texel_order(c, n, peaks[i], control, qmax)
                if L[0] + L[1] + L[2] > zero and q > 0:
                    phi0 = phi_edges[col]
                    phi1 = phi_edges[col + 1]
                    f = wp.vec2d(zero, zero)
                    if wp.abs(wp.dot(c, n)) < sin_delta:  # the horizon may cross the cell
                        bp, count = horizon_breaks(mu_lo, mu_hi, phi0, phi1, n)
                        for k in range(count):
                            right = phi1
                            if k + 1 < count:
                                right = bp[k + 1]
                            f += panel(mu_lo, mu_hi, bp[k], right, q, nodes, n, v, t, b, params, rule)
                    else:
                        f = panel(mu_lo, mu_hi, phi0, phi1, q, nodes, n, v, t, b, params, rule)
                    sa += L * f[0]
                    sb += L * f[1]
        for k in range(3):
            out[i, k] = sa[k]
            out[i, 3 + k] = sb[k]

    return kernel


@functools.lru_cache(maxsize=4)
def node_table(orders: int) -> np.ndarray:
    """The GL rules of 1 .. ``orders`` points on [0, 1], (node, weight) rows, the q-point rule at row q (q - 1) / 2."""
    return np.concatenate([np.stack(points.gauss_legendre(q), axis=1) for q in range(1, orders + 1)])


@dataclass(frozen=True)
class Environment:
    """A texel-constant lat-long environment (h, 2h, 3) and what the kernel reads of it."""

    image: np.ndarray

    @functools.cached_property
    def arrays(self) -> dict[str, np.ndarray]:
        h, w = self.image.shape[:2]
        theta, phi = latlong.row_edges(h), latlong.column_edges(w)
        tc, pc = np.meshgrid((theta[:-1] + theta[1:]) / 2, (phi[:-1] + phi[1:]) / 2, indexing="ij")
        return {
            "radiance": np.ascontiguousarray(self.image, np.float64).reshape(-1, 3),
            "centres": latlong.directions(tc, pc).reshape(-1, 3),
            "mu_edges": np.cos(theta),
            "phi_edges": phi,
        }

    @property
    def delta(self) -> float:
        """Δ = pi / h: a texel's angular size (its height; its width sin theta 2 pi / w is no larger)."""
        return math.pi / self.image.shape[0]


def _launch(
    pair, env: Environment, n, v, peaks, params, lobe: str, alpha: float, quality: Quality, rule_order: int, device
):
    qmax = Q_MAX + quality.extra
    arrays = env.arrays
    inputs = [
        wp.array(np.ascontiguousarray(n, np.float64), dtype=wp.vec3d, device=device),
        wp.array(np.ascontiguousarray(v, np.float64), dtype=wp.vec3d, device=device),
        wp.array(np.ascontiguousarray(peaks, np.float64), dtype=wp.vec3d, device=device),
        wp.array(arrays["radiance"], dtype=wp.vec3d, device=device),
        wp.array(arrays["centres"], dtype=wp.vec3d, device=device),
        wp.array(arrays["mu_edges"], dtype=wp.float64, device=device),
        wp.array(arrays["phi_edges"], dtype=wp.float64, device=device),
        wp.array(node_table(qmax), dtype=wp.vec2d, device=device),
        wp.array(np.stack(points.gauss_legendre(rule_order), axis=1), dtype=wp.vec2d, device=device),
        wp.vec4(*[float(x) for x in params]),
        wp.vec4d(env.delta, lobe_width(lobe, alpha), quality.k * LOBES[lobe][1], float(quality.extra)),
        Q_MAX,
    ]
    kernel = truth_kernel(pair)
    load_module(kernel.module, device)
    out = wp.zeros((len(n), 6), dtype=wp.float64, device=device)
    wp.launch(kernel, dim=len(n), inputs=[*inputs, out], device=device)
    return out.numpy()


def specular(
    image: np.ndarray, n: np.ndarray, v: np.ndarray, alpha: float, quality: Quality = Quality(), device: str = "cpu"
) -> tuple[np.ndarray, np.ndarray]:
    """(a, b), each (N, 3): the GGX pair of every pixel (module docstring) under the lat-long ``image``; the
    specular radiance of f0 is f0 a + b."""
    env = image if isinstance(image, Environment) else Environment(np.asarray(image, np.float64))
    n, v = np.asarray(n, np.float64), np.asarray(v, np.float64)
    if alpha < ALPHA_MIN:  # the mirror limit, exact
        nov = np.sum(n * v, axis=-1)
        fc = np.where(nov > COS_EPS, np.clip(1 - nov, 0, 1) ** 5, 0.0)[:, None]
        L = latlong.lookup(env.image, reflect(n, v)) * (nov > COS_EPS)[:, None]
        return L * (1 - fc), L * fc
    out = _launch(ggx_pair, env, n, v, reflect(n, v), (alpha, 0, 0, 0), "ggx", alpha, quality, 1, device)
    return out[:, :3], out[:, 3:]


def diffuse(
    image: np.ndarray,
    n: np.ndarray,
    v: np.ndarray,
    model,
    sigma: float = 0.0,
    f0: float = 0.0,
    facet_fresnel: str = "eq6",
    sigma_to_alpha: str = "sigma",
    quality: Quality = Quality(),
    rule_order: int = 8,
    device: str = "cpu",
) -> np.ndarray:
    """(N, 3): ∫ L f (n.l) dω of diffuse model ``model`` (a record of family ``diffuse`` or the name of one of
    lutbake's) for rho = 1 at every pixel; its microfacet model's m-integral by ``rule_order`` GL points
    (lutbake.sampling.facets)."""
    from ..axes import sigma_alpha
    from ..edge import effective_alpha
    from ..integrands.diffuse import diffuse_integrand

    env = image if isinstance(image, Environment) else Environment(np.asarray(image, np.float64))
    n, v = np.asarray(n, np.float64), np.asarray(v, np.float64)
    alpha = float(effective_alpha(sigma_alpha(np.float32(sigma), sigma_to_alpha), False))
    pair = diffuse_pair(diffuse_integrand(model, facet_fresnel).brdf)
    params = (alpha, sigma, f0, 0)
    return _launch(pair, env, n, v, n, params, "cosine", 0.0, quality, rule_order, device)[:, :3]
