"""Evaluate the ``@wp.func`` terms at arrays of host inputs, for checks and tests.

Everything here lives in ONE Warp module (this Python module), compiled once: a kernel that evaluates
every term at each input record, and a kernel that evaluates the full specular BRDF of every
(NDF, masking) pair. The terms run exactly as the table kernels run them (float32 in, float32 out);
what is measured is the Warp code, not a host re-implementation.

Host API (inputs broadcast against each other; ``h``, ``l``, ``v`` carry a trailing axis of 3):

    evaluate_terms(h=..., alpha=..., nov=..., nol=..., voh=..., loh=..., f0=..., eta=..., cos_theta=..., names=...)
        -> {term name: array}, names in ``TERM_NAMES`` (all of them, or those in ``names``):
        D_<ndf>            D(h, alpha)                                  for every NDF in distributions.NDFS
        Lambda_<ndf>       Lambda(nov, alpha)
        G1_smith_<ndf>     G1_smith(Lambda(nov, alpha))
        G2[<ndf>,<masking>]  NDFS[ndf].G2(masking)(nov, nol, h.z, voh, alpha)  (the composed G2 tables use)
        G2_v_cavity        G2_v_cavity(h.z, nov, nol, voh, loh)          (with its own l.h)
        D_ggx_aniso        D_ggx_aniso(h, alpha, alpha_y)               (alpha = alpha_x along the tangent +x)
        Lambda_ggx_aniso   Lambda_ggx_aniso(v, alpha, alpha_y)
        D_ashikhmin_shirley  D_ashikhmin_shirley(h, as_exponent(alpha), as_exponent(alpha_y))
        F_schlick          F_schlick(f0, cos_theta);   Fc_schlick  Fc_schlick(cos_theta)
        F_dielectric       F_dielectric(eta, cos_theta)
        F_dielectric_f0    F_dielectric_f0(f0, cos_theta)
    evaluate_brdfs(l, v, alpha, f0) -> {(ndf, masking): f(l, v)} for every pair in ``BRDF_PAIRS``:
        f(l, v) = D(h) G2(n.v, n.l, n.h, v.h) F_schlick(f0, v.h) / (4 (n.l)(n.v)),  h = normalize(l + v),
        v.h = |l + v| / 2 (= l.h), so h and v.h are bitwise the same for f(v, l) and the only asymmetry
        left to a reciprocity check is the order of G2's and the denominator's arguments
        (Gotanda 2014 course notes, Eq. 1), 0 where n.l or n.v <= COS_EPS.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from ..edge import COS_EPS
from ..records import MASKING
from ..runtime.warp_runtime import MODULE_OPTIONS, kernel_factory
from ..terms import fresnel, masking, ndf
from ..terms.distributions import NDFS

wp.set_module_options(MODULE_OPTIONS)


@wp.struct
class TermInputs:
    """One input record: every term reads the fields it needs (see the module docstring)."""

    h: wp.vec3
    v: wp.vec3
    alpha: float
    alpha_y: float
    nov: float
    nol: float
    voh: float
    loh: float
    f0: float
    eta: float
    cos_theta: float


# --- one probe per term: a wp.func TermInputs -> float, paired with its output name ---------------


def _ndf_probes(ndf_name: str) -> list:
    nd = NDFS[ndf_name]
    D, Lam = nd.D, nd.Lambda

    @wp.func
    def probe_D(x: TermInputs):
        return D(x.h, x.alpha)

    if Lam is None:  # no Smith Lambda (blinn_phong)
        return [(f"D_{ndf_name}", probe_D)]

    @wp.func
    def probe_Lambda(x: TermInputs):
        return Lam(x.nov, x.alpha)

    @wp.func
    def probe_G1(x: TermInputs):
        return masking.G1_smith(Lam(x.nov, x.alpha))

    return [(f"D_{ndf_name}", probe_D), (f"Lambda_{ndf_name}", probe_Lambda), (f"G1_smith_{ndf_name}", probe_G1)]


def _g2_probe(ndf_name: str, masking_name: str) -> tuple:
    G2 = NDFS[ndf_name].G2(masking_name)

    @wp.func
    def probe_G2(x: TermInputs):
        return G2(x.nov, x.nol, x.h[2], x.voh, x.alpha)

    return (f"G2[{ndf_name},{masking_name}]", probe_G2)


@wp.func
def _probe_G2_v_cavity(x: TermInputs):
    return masking.G2_v_cavity(x.h[2], x.nov, x.nol, x.voh, x.loh)


@wp.func
def _probe_D_ggx_aniso(x: TermInputs):
    return ndf.D_ggx_aniso(x.h, x.alpha, x.alpha_y)


@wp.func
def _probe_Lambda_ggx_aniso(x: TermInputs):
    return masking.Lambda_ggx_aniso(x.v, x.alpha, x.alpha_y)


@wp.func
def _probe_D_ashikhmin_shirley(x: TermInputs):
    return ndf.D_ashikhmin_shirley(x.h, ndf.as_exponent(x.alpha), ndf.as_exponent(x.alpha_y))


@wp.func
def _probe_F_schlick(x: TermInputs):
    return fresnel.F_schlick(x.f0, x.cos_theta)


@wp.func
def _probe_Fc_schlick(x: TermInputs):
    return fresnel.Fc_schlick(x.cos_theta)


@wp.func
def _probe_F_dielectric(x: TermInputs):
    return fresnel.F_dielectric(x.eta, x.cos_theta)


@wp.func
def _probe_F_dielectric_f0(x: TermInputs):
    return fresnel.F_dielectric_f0(x.f0, x.cos_theta)


@wp.func
def _probe_D_charlie(x: TermInputs):
    return ndf.D_charlie(x.h, x.alpha)


@wp.func
def _probe_V_charlie(x: TermInputs):
    return masking.V_charlie(x.nov, x.nol, x.alpha)


BRDF_PAIRS: tuple[tuple[str, str], ...] = tuple(
    (n, m) for n in NDFS for m in MASKING.names() if NDFS[n].masking_allowed(m)
)

_PROBES = (
    [p for n in NDFS for p in _ndf_probes(n)]
    + [_g2_probe(n, m) for n, m in BRDF_PAIRS]
    + [
        ("D_ggx_aniso", _probe_D_ggx_aniso),
        ("Lambda_ggx_aniso", _probe_Lambda_ggx_aniso),
        ("D_ashikhmin_shirley", _probe_D_ashikhmin_shirley),
        ("D_charlie", _probe_D_charlie),
        ("V_charlie", _probe_V_charlie),
    ]
    + [
        ("G2_v_cavity", _probe_G2_v_cavity),
        ("F_schlick", _probe_F_schlick),
        ("Fc_schlick", _probe_Fc_schlick),
        ("F_dielectric", _probe_F_dielectric),
        ("F_dielectric_f0", _probe_F_dielectric_f0),
    ]
)
TERM_NAMES: tuple[str, ...] = tuple(name for name, _ in _PROBES)
_PROBE_FUNCS = [f for _, f in _PROBES]


SCALARS = ("alpha", "alpha_y", "nov", "nol", "voh", "loh", "f0", "eta", "cos_theta")  # _terms_kernel's s columns


@wp.kernel
def _terms_kernel(
    hv: wp.array2d(dtype=wp.vec3),
    s: wp.array2d(dtype=float),
    column: wp.array(dtype=int),
    out: wp.array2d(dtype=float),
):
    """hv[i] = (h, v); s[i] = SCALARS in order; term k goes to out[i, column[k]], skipped where column[k] < 0."""
    i = wp.tid()
    x = TermInputs()
    x.h = hv[i, 0]
    x.v = hv[i, 1]
    x.alpha = s[i, 0]
    x.alpha_y = s[i, 1]
    x.nov = s[i, 2]
    x.nol = s[i, 3]
    x.voh = s[i, 4]
    x.loh = s[i, 5]
    x.f0 = s[i, 6]
    x.eta = s[i, 7]
    x.cos_theta = s[i, 8]
    for k in range(wp.static(len(_PROBE_FUNCS))):
        if column[k] >= 0:
            out[i, column[k]] = wp.static(_PROBE_FUNCS[k])(x)


# --- full specular BRDFs ------------------------------------------------------------------------


@kernel_factory
def specular_brdf_for(ndf_name: str, masking_name: str):
    """``f(l, v, alpha, f0)``: the Cook-Torrance specular BRDF of one (NDF, masking) pair with Schlick F,
    assembled from the terms exactly as tables assemble it (module docstring)."""
    D = NDFS[ndf_name].D
    G2 = NDFS[ndf_name].G2(masking_name)

    @wp.func
    def brdf(l: wp.vec3, v: wp.vec3, alpha: float, f0: float):
        NoL = l[2]
        NoV = v[2]
        s = l + v
        if NoL <= COS_EPS or NoV <= COS_EPS or wp.length_sq(s) <= 0.0:
            return 0.0
        h = wp.normalize(s)
        # v.h = l.h = |l + v| / 2 for unit l, v: bitwise symmetric in (l, v), and free of the float32
        # cancellation of dot(v, h) when l ~ -v (relative error ~1e-7 / v.h there)
        VoH = 0.5 * wp.length(s)
        F = fresnel.F_schlick(f0, VoH)
        return D(h, alpha) * G2(NoV, NoL, h[2], VoH, alpha) * F / (4.0 * NoL * NoV)

    return brdf


_BRDF_FUNCS = [specular_brdf_for(n, m) for n, m in BRDF_PAIRS]


@wp.kernel
def _brdf_kernel(lv: wp.array2d(dtype=wp.vec3), alpha_f0: wp.array(dtype=wp.vec2), out: wp.array2d(dtype=float)):
    """lv[i] = (l, v); alpha_f0[i] = (alpha, f0)."""
    i = wp.tid()
    for k in range(wp.static(len(_BRDF_FUNCS))):
        out[i, k] = wp.static(_BRDF_FUNCS[k])(lv[i, 0], lv[i, 1], alpha_f0[i][0], alpha_f0[i][1])


# --- host side ------------------------------------------------------------------------------------


def _vec_and_scalars(vecs: dict, scalars: dict) -> tuple[tuple, np.ndarray, np.ndarray]:
    """Broadcast (..., 3) vectors and (...) scalars to one shape; return it, the vectors packed (n, len(vecs), 3)
    and the scalars (n, len(scalars)), float32, in the dicts' order."""
    vecs = {k: np.asarray(a, dtype=np.float32) for k, a in vecs.items()}
    scalars = [np.asarray(a, dtype=np.float32) for a in scalars.values()]
    for k, a in vecs.items():
        if a.shape[-1:] != (3,):
            raise ValueError(f"{k} must have a trailing axis of 3, got shape {a.shape}")
    shape = np.broadcast_shapes(*(a.shape[:-1] for a in vecs.values()), *(a.shape for a in scalars))
    vec = np.empty(shape + (len(vecs), 3), dtype=np.float32)
    for j, a in enumerate(vecs.values()):
        vec[..., j, :] = a
    sca = np.empty(shape + (len(scalars),), dtype=np.float32)
    for j, a in enumerate(scalars):
        sca[..., j] = a
    n = int(np.prod(shape, dtype=np.int64))
    return shape, vec.reshape(n, len(vecs), 3), sca.reshape(n, len(scalars))


def evaluate_terms(
    *,
    h=(0.0, 0.0, 1.0),
    v=(0.0, 0.0, 1.0),
    alpha=0.5,
    alpha_y=None,
    nov=1.0,
    nol=1.0,
    voh=1.0,
    loh=1.0,
    f0=0.04,
    eta=1.5,
    cos_theta=1.0,
    names=None,
    device: str = "cpu",
) -> dict[str, np.ndarray]:
    """Every term of ``TERM_NAMES`` (or only those in ``names``: the others are not evaluated) at the broadcast
    inputs (module docstring) -> {name: float32 array}.
    ``h`` is in the shading frame (n = +z) and is used as given (not normalised); n.h for G2 is h.z.
    The anisotropic terms read ``alpha`` as alpha_x (tangent, +x), ``alpha_y`` (default: alpha) and the
    direction ``v``; D_ashikhmin_shirley has exponents nu, nv = max(2/alpha^2 - 2, 0) of alpha, alpha_y."""
    alpha_y = alpha if alpha_y is None else alpha_y
    scalars = dict(
        alpha=alpha, alpha_y=alpha_y, nov=nov, nol=nol, voh=voh, loh=loh, f0=f0, eta=eta, cos_theta=cos_theta
    )
    shape, hv, sc = _vec_and_scalars({"h": h, "v": v}, {k: scalars[k] for k in SCALARS})
    names = TERM_NAMES if names is None else tuple(dict.fromkeys(names))
    unknown = set(names) - set(TERM_NAMES)
    if unknown:
        raise KeyError(f"unknown term(s) {sorted(unknown)}; valid: {', '.join(TERM_NAMES)}")
    column = np.full(len(TERM_NAMES), -1, dtype=np.int32)
    column[[TERM_NAMES.index(name) for name in names]] = np.arange(len(names))
    n = len(hv)
    out = wp.empty((n, len(names)), dtype=float, device=device)  # the kernel writes every element
    inputs = [wp.array(hv, dtype=wp.vec3, device=device), wp.array(sc, dtype=float, device=device)]
    if n:
        wp.launch(
            _terms_kernel, dim=n, inputs=inputs + [wp.array(column, dtype=int, device=device), out], device=device
        )
    res = out.numpy()
    return {name: res[:, k].reshape(shape) for k, name in enumerate(names)}


def evaluate_brdfs(l, v, alpha, f0=0.04, device: str = "cpu") -> dict[tuple[str, str], np.ndarray]:
    """f(l, v) of every (NDF, masking) pair in ``BRDF_PAIRS`` -> {(ndf, masking): float32 array}.
    ``l`` and ``v`` are unit vectors in the shading frame (n = +z)."""
    shape, lv, af = _vec_and_scalars({"l": l, "v": v}, {"alpha": alpha, "f0": f0})
    n = len(lv)
    out = wp.zeros((n, len(BRDF_PAIRS)), dtype=float, device=device)
    inputs = [wp.array(lv, dtype=wp.vec3, device=device), wp.array(af, dtype=wp.vec2, device=device)]
    if n:
        wp.launch(_brdf_kernel, dim=n, inputs=inputs + [out], device=device)
    res = out.numpy()
    return {pair: res[:, k].reshape(shape) for k, pair in enumerate(BRDF_PAIRS)}
