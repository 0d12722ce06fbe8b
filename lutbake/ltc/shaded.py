"""The shaded fit: LTC texels refined to the polygon-light integrals a shader computes, not to the lobe's L3 distance.

A shader shows, for a polygon light P and Schlick reflectance f0, value(P) = (f0 magnitude + (1 - f0) fresnel) I_P,
I_P the clamped-cosine integral of the polygon transformed by M^-1 and clipped to the horizon (Heitz et al. 2016,
Eq. 11; lutbake.ltc.polygon), one matrix for every f0. The shaded fit chooses each texel's packed M^-1 (4
coefficients, ltc_code's layout), magnitude and fresnel to minimise

    C = Σ_j ρ(z_j),  z_j = (value_j - T_j) / (T_j + c A),  ρ(z) = 2 s^2 (sqrt(1 + z^2 / s^2) - 1)   (soft L1)

over ``LIGHTS`` training lights per texel (lutbake.ltc.lights, from the texel's inputs; the area-light benchmark
draws another seed), for F = 1 (T_j = G_j = ∫_{P_j} f (n.l) dω, A the albedo) and, weighted by ``f0_weight``, for
f0 = ``F0_TRAIN`` (T_j = f0 G_j + (1 - f0) H_j, H_j = ∫_{P_j} f (1 - v.h)^5 (n.l) dω, A the same mix of the
albedos); c = ``ABS_WEIGHT``: relative errors of lights brighter than c A, absolute errors of dimmer ones; s =
``ROBUST_SCALE``: lights the clamped cosine cannot follow (below its transformed horizon) do not dominate. G_j and
H_j use one fixed set of the lobe's importance samples per texel (the L3 fit's own sampler, lutbake.ltc.fit
``lobe_samples``, ``SAMPLES`` x ``SAMPLES`` stratified): G_j = 1/K Σ_k f_k / p_k [l_k in P_j]. With ``f0_weight`` 0
(or a lobe without Fresnel) only F = 1 is fitted and fresnel is the exact channel (resp. the magnitude).

Search: Levenberg-Marquardt from the texel's L3 fit (lutbake.ltc.fit), ``ITERATIONS`` steps, forward-difference
Jacobian of the 4 coefficients (magnitude and fresnel are linear), float64 throughout; at normal incidence the lobe
is isotropic and only M^-1_22 of the matrix is free (M^-1_00 = M^-1_11, no skew), as ltc_code's table. The
I_j are one Warp launch per step over (texel, trial, light). Every texel is independent of every other and of how
texels are grouped: bit-identical for any tiling or worker count.
"""

from __future__ import annotations

import functools

import numpy as np
import warp as wp

from ..runtime.warp_runtime import MODULE_OPTIONS, load_module
from . import lights as ltc_lights
from .fit import unpack_inverse

wp.set_module_options(MODULE_OPTIONS)

LIGHTS = 128  # training lights per texel
SAMPLES = 48  # the lobe's importance samples per texel: SAMPLES x SAMPLES stratified
ABS_WEIGHT = 0.4  # c: errors relative to G_j + c A
ROBUST_SCALE = 0.05  # s of the soft-L1 loss on the weighted residuals
ITERATIONS = 8
LAMBDA0 = 1e-2  # initial Levenberg-Marquardt damping (relative to diag(J^T J))
FD_STEP = 1e-6  # forward-difference step, relative to max(|coefficient|, 1)
SEED = 40
EXACT_L3 = 1e-3  # relative L3 error below which a texel's L3 fit is kept as exact (the kind skips refining it)
TINY = 1e-30  # floor of a residual's scale (a lobe whose albedo vanishes, e.g. sheen at grazing, alpha -> 0)
F0_TRAIN = 0.04  # the dielectric reflectance fitted beside F = 1 (lobes with Fresnel)
F0_WEIGHT = 0.7  # default weight of the f0 = F0_TRAIN residuals beside F = 1 (0: F = 1 alone)


@wp.func
def edge_z(a: wp.vec3d, b: wp.vec3d):
    """acos(a.b) (a x b).z / |a x b| / (2 pi) for unit a, b (the exact edge integral; 0 for a = b)."""
    c = wp.cross(a, b)
    s = wp.length(c)
    if s <= wp.float64(0.0):
        return wp.float64(0.0)
    th = wp.atan2(s, wp.dot(a, b))
    return c[2] * th / (s * wp.float64(6.283185307179586))


@wp.func
def clipped_integral(p0: wp.vec3d, p1: wp.vec3d, p2: wp.vec3d, p3: wp.vec3d):
    """|I| of the quad (p0..p3) clipped to z >= 0 (Sutherland-Hodgman, <= 5 vertices), exact edges, two-sided."""
    c0 = wp.vec3d()
    c1 = wp.vec3d()
    c2 = wp.vec3d()
    c3 = wp.vec3d()
    c4 = wp.vec3d()
    n = int(0)  # noqa: UP018 - a dynamic Warp variable (mutated in the loop)
    for i in range(4):
        a = p0
        b = p1
        if i == 1:
            a = p1
            b = p2
        elif i == 2:
            a = p2
            b = p3
        elif i == 3:
            a = p3
            b = p0
        ina = a[2] >= wp.float64(0.0)
        inb = b[2] >= wp.float64(0.0)
        for k in range(2):
            emit = bool(False)  # noqa: UP018 - dynamic
            q = a
            if k == 0 and ina:
                emit = True
            if k == 1 and ina != inb:
                t = a[2] / (a[2] - b[2])
                q = a + t * (b - a)
                q = wp.vec3d(q[0], q[1], wp.float64(0.0))
                emit = True
            if emit:
                if n == 0:
                    c0 = q
                elif n == 1:
                    c1 = q
                elif n == 2:
                    c2 = q
                elif n == 3:
                    c3 = q
                else:
                    c4 = q
                n += 1
    if n < 3:
        return wp.float64(0.0)
    u0 = wp.normalize(c0)
    u1 = wp.normalize(c1)
    u2 = wp.normalize(c2)
    s = edge_z(u0, u1) + edge_z(u1, u2)
    if n == 3:
        s += edge_z(u2, u0)
    else:
        u3 = wp.normalize(c3)
        s += edge_z(u2, u3)
        if n == 4:
            s += edge_z(u3, u0)
        else:
            u4 = wp.normalize(c4)
            s += edge_z(u3, u4) + edge_z(u4, u0)
    return wp.abs(s)


@wp.kernel(enable_backward=False)
def polygon_integrals(
    texel: wp.array(dtype=int),
    minv: wp.array(dtype=wp.mat33d),
    polys: wp.array3d(dtype=wp.vec3d),
    out: wp.array2d(dtype=wp.float64),
):
    """out[i, j] = I of light j of texel[i] through M^-1 = minv[i] (the shader's integral, exact edges)."""
    i, j = wp.tid()
    t = texel[i]
    m = minv[i]
    out[i, j] = clipped_integral(m * polys[t, j, 0], m * polys[t, j, 1], m * polys[t, j, 2], m * polys[t, j, 3])


@functools.lru_cache(maxsize=None)
def _loaded(device: str) -> bool:
    load_module(polygon_integrals.module, device)
    return True


def integrals(minv: np.ndarray, texel: np.ndarray, polys: np.ndarray, device: str = "cpu") -> np.ndarray:
    """I (k, L) of the lights polys (T, L, 4, 3) of texels ``texel`` (k,) through M^-1 ``minv`` (k, 3, 3)."""
    _loaded(device)
    k, nl = len(texel), polys.shape[1]
    out = wp.zeros((k, nl), dtype=wp.float64, device=device)
    wp.launch(
        polygon_integrals,
        dim=(k, nl),
        inputs=[
            wp.array(np.asarray(texel, np.int32), dtype=int, device=device),
            wp.array(np.ascontiguousarray(minv, np.float64), dtype=wp.mat33d, device=device),
            wp.array(
                np.ascontiguousarray(polys.reshape(polys.shape[0], nl, 4, 3), np.float64), dtype=wp.vec3d, device=device
            ),
            out,
        ],
        device=device,
    )
    return out.numpy()


def robust(z: np.ndarray) -> np.ndarray:
    """The soft-L1 loss 2 s^2 (sqrt(1 + (z / s)^2) - 1), s = ROBUST_SCALE: quadratic below s, linear above (lights
    the one clamped cosine cannot follow, e.g. below its transformed horizon, do not dominate the fit)."""
    s2 = ROBUST_SCALE * ROBUST_SCALE
    return 2.0 * s2 * (np.sqrt(1.0 + z * z / s2) - 1.0)


def robust_weight(z: np.ndarray) -> np.ndarray:
    """The IRLS weight of ``robust``: 1 / sqrt(1 + (z / s)^2)."""
    return 1.0 / np.sqrt(1.0 + z * z / (ROBUST_SCALE * ROBUST_SCALE))


def texel_lights(nov: np.ndarray, alpha: np.ndarray, count: int = LIGHTS, seed: int = SEED) -> np.ndarray:
    """Training lights (k, count, 4, 3) per texel: one fixed set of uniform numbers (``seed``) mapped through each
    texel's own (n.v, alpha) (lutbake.ltc.lights.from_uniforms), so a texel's lights depend on its inputs alone."""
    u = np.random.default_rng(seed).random((2 * count + 16, ltc_lights.UNIFORMS))
    nv = np.asarray(nov, np.float64)
    v = np.stack([np.sqrt(np.maximum(1.0 - nv * nv, 0.0)), np.zeros_like(nv), nv], axis=1)
    p = ltc_lights.from_uniforms(u[None], v[:, None, :], np.asarray(alpha, np.float64)[:, None])
    return ltc_lights.first_lit(p, count)


@wp.kernel(enable_backward=False)
def light_integrals(
    dirs: wp.array2d(dtype=wp.vec3d),
    w: wp.array2d(dtype=wp.float64),
    wf: wp.array2d(dtype=wp.float64),
    polys: wp.array3d(dtype=wp.vec3d),
    g: wp.array2d(dtype=wp.float64),
    h: wp.array2d(dtype=wp.float64),
):
    """g[t, j] = Σ_s w[t, s] [dirs[t, s] in light j], h likewise with wf: the lobe's integral over each light from
    its importance samples (weights f / p / K), and its Schlick part."""
    t, j = wp.tid()
    p0 = polys[t, j, 0]
    p1 = polys[t, j, 1]
    p2 = polys[t, j, 2]
    p3 = polys[t, j, 3]
    e0 = wp.cross(p0, p1)
    e1 = wp.cross(p1, p2)
    e2 = wp.cross(p2, p3)
    e3 = wp.cross(p3, p0)
    zero = wp.float64(0.0)
    sg = wp.float64(0.0)
    sh = wp.float64(0.0)
    for s in range(dirs.shape[1]):
        l = dirs[t, s]
        if wp.dot(l, e0) >= zero and wp.dot(l, e1) >= zero and wp.dot(l, e2) >= zero and wp.dot(l, e3) >= zero:
            sg += w[t, s]
            sh += wf[t, s]
    g[t, j] = sg
    h[t, j] = sh


def targets(problem, texel: np.ndarray, polys: np.ndarray, device: str = "cpu") -> tuple[np.ndarray, np.ndarray]:
    """(G, H): the lobe's integral over each training light (k, L) and its Schlick part ∫_P f (1 - v.h)^5 (n.l) dω,
    from the problem's lobe samples (lutbake.ltc.fit.Problem: its sampler on its stratified grid)."""
    _loaded(device)
    dirs, f, p = problem.lobe_sample_arrays(texel)
    w = np.where(p > 0.0, f / np.where(p > 0.0, p, 1.0), 0.0) / dirs.shape[1]
    v = problem.v[texel].astype(np.float64)
    hv = dirs + v[:, None, :]
    hv /= np.maximum(np.linalg.norm(hv, axis=2, keepdims=True), 1e-300)
    f5 = (1.0 - np.clip(np.einsum("ksj,kj->ks", hv, v), 0.0, 1.0)) ** 5
    k, nl = len(texel), polys.shape[1]
    g = wp.zeros((k, nl), dtype=wp.float64, device=device)
    h = wp.zeros((k, nl), dtype=wp.float64, device=device)
    arr = functools.partial(wp.array, device=device)
    inputs = [arr(np.ascontiguousarray(dirs), dtype=wp.vec3d), arr(w, dtype=wp.float64), arr(w * f5, dtype=wp.float64)]
    inputs += [arr(np.ascontiguousarray(polys, np.float64), dtype=wp.vec3d), g, h]
    wp.launch(light_integrals, dim=(k, nl), inputs=inputs, device=device)
    return g.numpy(), h.numpy()


def refine(
    problem,
    texel: np.ndarray,
    packed: np.ndarray,
    fresnel: np.ndarray | None = None,
    fit_magnitude: bool = True,
    device: str = "cpu",
    lights: int = LIGHTS,
    samples: int = SAMPLES,
    f0_weight: float = F0_WEIGHT,
    schlick_lobe: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Levenberg-Marquardt from ``packed`` (k, 4) at ``texel``: (packed (k, 4), magnitude (k,), fresnel (k,)).

    ``fresnel``: the exact Schlick channel ∫ f (1 - v.h)^5 (n.l) dω of the texels, or None for a lobe without
    Fresnel (its fresnel channel is then the magnitude, and only F = 1 is fitted). With Fresnel the residuals are
    those of F = 1 and of f0 = ``F0_TRAIN`` (value (f0 magnitude + (1 - f0) fresnel) I against f0 G + (1 - f0) H,
    relative to the same mix of the albedos), so the one matrix serves metals and dielectrics.
    ``fit_magnitude`` False keeps magnitude = the albedo and fresnel = the exact channel and fits the matrix alone
    (for shaders that take the magnitude from another table, e.g. HDRP's PreIntegratedFGD).
    ``schlick_lobe``: fit the matrix and the fresnel channel to the Schlick part H alone (f0 = 0), the magnitude kept:
    the second LTC of a two-lobe shader, value = f0 magnitude I(M1) + (1 - f0) fresnel I(M2) (lutbake.validate.
    ltc_bench.fitted_texels "two_lobe")."""
    from .fit import Problem

    k = len(texel)
    polys = texel_lights(problem.nov[texel], problem.alpha[texel], lights)
    sp = Problem(problem.lobe, problem.nov[texel], problem.alpha[texel], problem.magnitude[texel], samples, device)
    G, H = targets(sp, np.arange(k), polys, device)
    A = problem.magnitude[texel]
    if schlick_lobe:
        f0s = (0.0,)
    else:
        f0s = (1.0,) if fresnel is None or f0_weight == 0.0 else (1.0, F0_TRAIN)
    AH = A if fresnel is None else np.asarray(fresnel, np.float64)
    # per reflectance: target (k, L), sqrt weight (k, L), d value / d (magnitude, fresnel) per unit I
    tg = [f0 * G + (1.0 - f0) * H for f0 in f0s]
    sw = [
        (1.0 if f0 == f0s[0] else f0_weight) / np.maximum(t + ABS_WEIGHT * (f0 * A + (1.0 - f0) * AH)[:, None], TINY)
        for f0, t in zip(f0s, tg)
    ]
    target = np.concatenate(tg, axis=1)
    sw = np.concatenate(sw, axis=1)
    coef_m = np.concatenate([np.full(G.shape, f0) for f0 in f0s], axis=1)
    coef_f = 1.0 - coef_m
    local = np.arange(k)
    iso = problem.isotropic[texel]
    free = np.ones((k, 4), bool)
    free[iso, :3] = False  # normal incidence: (1, 0, 0, w)
    lin = [name for name, used in (("m", max(f0s) > 0.0), ("f", min(f0s) < 1.0)) if fit_magnitude and used]
    npar = 4 + len(lin)

    def evaluate(theta):
        return np.tile(integrals(unpack_inverse(theta), local, polys, device), (1, len(f0s)))

    def residual(I, m, f):
        return ((coef_m * m[:, None] + coef_f * f[:, None]) * I - target) * sw

    def cost(z):
        return np.sum(robust(z), axis=1)

    theta = np.array(packed, np.float64)
    m, f = A.copy(), AH.copy()
    I = evaluate(theta)
    z = residual(I, m, f)
    c = cost(z)
    lam = np.full(k, LAMBDA0)
    for _ in range(ITERATIONS):
        so = np.sqrt(robust_weight(z))  # IRLS: the robust cost's local quadratic model
        # Jacobian of z in (theta, magnitude, fresnel), forward differences in theta
        h = FD_STEP * np.maximum(np.abs(theta), 1.0)
        trials = np.repeat(theta[:, None, :], 4, axis=1)
        trials[:, np.arange(4), np.arange(4)] += h
        It = integrals(unpack_inverse(trials.reshape(-1, 4)), np.repeat(local, 4), polys, device).reshape(k, 4, -1)
        dI = np.tile((It - I[:, None, : G.shape[1]]) / h[:, :, None], (1, 1, len(f0s)))  # (k, 4, R)
        scale = (coef_m * m[:, None] + coef_f * f[:, None]) * sw
        J = np.empty((k, target.shape[1], npar))
        J[:, :, :4] = (dI * scale[:, None, :]).transpose(0, 2, 1) * free[:, None, :]
        for i, name in enumerate(lin):
            J[:, :, 4 + i] = (coef_m if name == "m" else coef_f) * I * sw
        J *= so[:, :, None]
        JtJ = np.einsum("kja,kjb->kab", J, J)
        Jtr = np.einsum("kja,kj->ka", J, z * so)
        d = np.einsum("kaa->ka", JtJ).copy()
        d[d <= 0.0] = 1.0
        step = -np.linalg.solve(JtJ + lam[:, None, None] * d[:, :, None] * np.eye(npar)[None], Jtr[:, :, None])[..., 0]
        th_new = theta + step[:, :4] * free
        m_new, f_new = m.copy(), f.copy()
        for i, name in enumerate(lin):
            if name == "m":
                m_new = m + step[:, 4 + i]
            else:
                f_new = f + step[:, 4 + i]
        I_new = evaluate(th_new)
        z_new = residual(I_new, m_new, f_new)
        c_new = cost(z_new)
        ok = np.isfinite(c_new) & (c_new < c)
        theta[ok], I[ok], m[ok], f[ok], z[ok], c[ok] = th_new[ok], I_new[ok], m_new[ok], f_new[ok], z_new[ok], c_new[ok]
        lam = np.where(ok, lam / 3.0, lam * 4.0)
    if fresnel is None:
        f = m.copy()
    elif fit_magnitude and f0s == (1.0,):  # F = 1 alone: the Schlick channel is the exact integral
        f = AH.copy()
    return theta, m, f
