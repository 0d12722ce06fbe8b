"""Kind ``btf``: a diffuse BRDF of four scalars, f(θ_l, θ_v, φ; σ) (rho = 1, f0 baked), tabulated as one 3D block
per σ slice: the seed's "BTF-like techniques" for the microfacet diffuse model (Eq. 4, integrated over m by
lutbake.sampling.facets) or any closed model (``model = "fitted"`` for Eq. 8, to diff the
fit against the integral).

Layout (one EXR, lutbake.io.exr): a multi-part file with one part per σ slice (z; σ of the slice in the
part's lutbake:slice_value and in lutbake:axes). Inside a part, columns are the light axis (x) and the rows
hold (φ, view) flattened: image row = iφ * N_v + i_v (the φ axis has dim ``y_block``). Parametrisation:
- ``cosines``: x = n.l in [0, 1], y = n.v in [0, 1], y_block = cos φ in [-1, 1];
- ``angles``: x = θ_l in [0, π/2], y = θ_v in [0, π/2], y_block = φ in [0, π] (radians).
φ is the azimuth between l and v; f is even in φ, so [0, π] (cos φ in [-1, 1]) covers every pair.
Reciprocity f(l, v) = f(v, l) makes every (φ, σ) block symmetric when the x and y grids agree (tested).
Edge policy (lutbake.edge, the same on the light and the view axis): cosines >= NOV_MIN, angles <= acos(NOV_MIN),
so the endpoint texel convention lists and integrates the same clamped value on both axes.
"""

from __future__ import annotations

import json

import numpy as np

from ..axes import TEXELS, Axis, sigma_alpha
from ..edge import effective_alpha
from ..limits import MAX_GL_ORDER
from ..records import DIFFUSE
from ..registry import choices
from ..runtime.plan import TexelPlan
from ..sampling.plan import Grid, per_texel_plan
from ..tolerance import Tolerance, tolerance_of
from . import diffuse
from .base import Estimation, Key, declare

PARAMETRISATIONS = {
    "cosines": "x = NoL in [0, 1], y = NoV in [0, 1], row blocks = cos(phi) in [-1, 1]",
    "angles": "x = theta_l in [0, pi/2], y = theta_v in [0, pi/2], row blocks = phi in [0, pi] (radians)",
}
DEFAULT_ORDER = 12  # GL order of the m-integral with ``samples`` unset and estimator sobol_ndf's nominal record
GRAZING_COS = 0.15  # fixed order (``samples`` set): texels with n.l and n.v both below it get order + GRAZING_EXTRA
GRAZING_EXTRA = 8
# the float32 default tolerance of the microfacet btf: relative, as its values span five decades (f ~ 1e-5 in grazing
# back-scatter to 0.8); half and png16 keep the storage-derived defaults of lutbake.tolerance
FLOAT32_TOLERANCE = Tolerance(0.0, 1.0e-5)

KEYS = {
    "size": Key("size", "int_pair", [32, 32], "[light, view] texel counts (columns, rows per phi block)", minimum=1),
    "phi_size": Key("phi_size", "int", 32, "azimuth texel count (row blocks)", minimum=1, maximum=4096),
    "sigma_size": Key("sigma_size", "int", 16, "sigma slice count (z, one EXR part each)", minimum=1, maximum=1024),
    "sigma_range": diffuse.KEYS["sigma_range"],
    "sigma_values": Key(
        "sigma_values",
        "float_list",
        None,
        "explicit sigma of every slice, strictly increasing "
        "(replaces sigma_size and sigma_range; the axis mapping is then 'listed')",
        minimum=0.0,
        maximum=1.0,
    ),
    "parametrisation": Key(
        "parametrisation", "str", "cosines", "what the light, view and azimuth axes hold", PARAMETRISATIONS
    ),
    "model": Key("model", "str", "microfacet", "the diffuse BRDF tabulated", choices(DIFFUSE)),
    "f0": Key(
        "f0",
        "float",
        0.0,
        "Fresnel reflectance at normal incidence baked in (lutbake:f0_factor: how it scales)",
        minimum=0.0,
        maximum=0.999,
    ),
    "sigma_to_alpha": diffuse.KEYS["sigma_to_alpha"],
    "facet_fresnel": diffuse.KEYS["facet_fresnel"],
    "texel": Key("texel", "str", "center", "texel convention of every axis", TEXELS),
}
RECONSTRUCTION = (
    "part k = sigma slice k (lutbake:slice_value); within a part, column = light index, row = phi_index * N_view + "
    "view_index. Texel centres (t = (i + 0.5) / N) on every axis: x = (light param) * N_l - 0.5, y = (view param) * "
    "N_v - 0.5, p = (phi param) * N_phi - 0.5; fetch bilinearly at row p0 * N_v + clamp(y, 0, N_v - 1) for the two "
    "phi blocks p0 = floor(p), p0 + 1 (clamped), lerp by fract(p), and lerp the two sigma parts: "
    "f = rho * value * g(f0) / g(f0_baked) (lutbake:f0_factor); radiance = f * E0 * NoL"
)


def axes_for(o: dict) -> list[Axis]:
    nl, nv = o["size"]
    tx = o["texel"]
    am = o["sigma_to_alpha"]
    if o["sigma_values"] is not None:
        vals = tuple(float(x) for x in o["sigma_values"])
        sig = Axis("sigma", "z", len(vals), vals[0], vals[-1], texel=tx, mapping="listed", listed=vals, alpha_map=am)
    else:
        sig = Axis("sigma", "z", o["sigma_size"], *o["sigma_range"], texel=tx, alpha_map=am)
    if o["parametrisation"] == "cosines":
        return [
            sig,
            Axis("cos_phi", "y_block", o["phi_size"], -1.0, 1.0, texel=tx),
            Axis("NoV", "y", nv, 0.0, 1.0, texel=tx),
            Axis("NoL", "x", nl, 0.0, 1.0, texel=tx),
        ]
    half_pi = float(np.pi / 2)
    return [
        sig,
        Axis("phi", "y_block", o["phi_size"], 0.0, float(np.pi), texel=tx),
        Axis("theta_v", "y", nv, 0.0, half_pi, texel=tx),
        Axis("theta_l", "x", nl, 0.0, half_pi, texel=tx),
    ]


def directions(axes: list[Axis], parametrisation: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(l, v, sigma) per texel in row-major order (sigma, phi, view, light), float64."""
    sig, ph, va, la = (a.values().astype(np.float64) for a in axes)
    S, P, V, L = np.meshgrid(sig, ph, va, la, indexing="ij")
    if parametrisation == "cosines":
        cl, cv = np.clip(L, 0.0, 1.0), np.clip(V, 0.0, 1.0)
        cp = np.clip(P, -1.0, 1.0)
        sp = np.sqrt(1.0 - cp * cp)
    else:
        cl, cv, cp, sp = np.cos(L), np.cos(V), np.cos(P), np.sin(P)
    sl, sv = np.sqrt(np.maximum(1.0 - cl * cl, 0.0)), np.sqrt(np.maximum(1.0 - cv * cv, 0.0))
    l = np.stack([sl * cp, sl * sp, cl], -1).reshape(-1, 3)
    v = np.stack([sv, np.zeros_like(sv), cv], -1).reshape(-1, 3)
    return l, v, S.reshape(-1)


def texel_count(o: dict) -> int:
    """size x phi_size x sigma_size (or the sigma_values count)"""
    ns = o["sigma_size"] if o["sigma_values"] is None else len(o["sigma_values"])
    return o["size"][0] * o["size"][1] * o["phi_size"] * ns


DEFAULT_SOBOL = 4096
TILE_PHI_BLOCKS = 8  # phi blocks per tile of the adaptive microfacet btf


def check_spec(spec) -> tuple[str, str] | None:
    o = spec.options
    if o["estimator"] == "sobol_ndf" and o["model"] != "microfacet":
        return (
            "estimator",
            f"'sobol_ndf' samples the microfacet model's m-integral; model {o['model']!r} is closed "
            "form (use 'gauss_legendre')",
        )
    if o["estimator"] == "gauss_legendre" and o["samples"] is not None and o["samples"] > MAX_GL_ORDER:
        return ("samples", f"with estimator 'gauss_legendre' samples is the GL order: at most {MAX_GL_ORDER}")
    return None


SAMPLES_DOC = (
    "gauss_legendre: the Gauss-Legendre order n of the m-integral (2 to 64; microfacet: up to (K + 3) x 4 n^2 "
    "facet normals per texel, K the tan(theta_m) panels); omitted: 12; closed models ignore it. sobol_ndf: "
    "the number of facet normals (default 4096)"
)
BTF_ESTIMATORS = {
    "gauss_legendre": "the microfacet model's m-integral by Gauss-Legendre panels (lutbake.sampling.facets); closed "
    "models are evaluated in closed form",
    "sobol_ndf": "the microfacet model's m-integral by scrambled Sobol' facet normals from GGX's D(m)(n.m) "
    "(samples = points, default 4096): a cross-check",
}


def reciprocal_inputs(l: np.ndarray, v: np.ndarray, o: dict) -> tuple[np.ndarray, np.ndarray]:
    """l, v with every texel whose light index exceeds its view index given the directions of its reciprocal
    (light and view indices swapped, same phi and sigma): f(l, v) = f(v, l), and rotating by -phi about n and
    mirroring y maps (v, l) onto that texel's (l, v). Then a texel and its reciprocal are one integral
    (PointAdaptive integrates equal rows once) and every (phi, sigma) block is exactly symmetric. Only where the
    light and view axes are the same grid (equal counts): otherwise l, v unchanged."""
    nl, nv = o["size"]
    if nl != nv:
        return l, v
    t = np.arange(len(l)).reshape(-1, nv, nl)  # (sigma x phi blocks, view, light)
    src = t.transpose(0, 2, 1).reshape(-1)  # texel (b, i, j) -> (b, j, i)
    iv, il = np.meshgrid(np.arange(nv), np.arange(nl), indexing="ij")
    swap = np.broadcast_to(il > iv, t.shape).reshape(-1)
    l, v = l.copy(), v.copy()
    l[swap], v[swap] = l[src[swap]], v[src[swap]]
    return l, v


def plan(spec) -> TexelPlan:
    from ..integrands.diffuse import diffuse_integrand
    from ..sampling.diffuse import PointAdaptive, PointEvaluation, PointSobol
    from ..sampling.facets import FACET_ORDERS
    from ..sampling.panels import n_tail_cuts_np

    o = spec.options
    axes = axes_for(o)
    l, v, sigma = directions(axes, o["parametrisation"])
    model, ff = o["model"], o["facet_fresnel"]
    order = (o["samples"] if o["estimator"] == "gauss_legendre" else None) or DEFAULT_ORDER
    integrated = model == "microfacet"
    adaptive = integrated and o["estimator"] == "gauss_legendre" and o["samples"] is None
    if adaptive:
        l, v = reciprocal_inputs(l, v, o)
    # texels with light and view both grazing hold the smallest values (f ~ 1e-5 in back-scattering): their
    # relative error converges last, so they get order + GRAZING_EXTRA (about 1 % of the texels)
    orders = np.where((l[:, 2] < GRAZING_COS) & (v[:, 2] < GRAZING_COS), order + GRAZING_EXTRA, order)
    sig_axis = axes[0]
    alpha = sigma_alpha(sigma.astype(np.float32), o["sigma_to_alpha"])
    grid = Grid(
        axes,
        {"l": l, "v": v, "sigma": sigma, "alpha": effective_alpha(alpha, False), "order": orders},
        grazing=np.minimum(l[:, 2], v[:, 2]),
        alpha=alpha,
    )
    terms = {
        "model": model,
        "f0": str(o["f0"]),
        "f0_factor": diffuse.f0_factor(spec),
        "parametrisation": o["parametrisation"],
    }
    if integrated:
        terms.update(ndf="ggx", masking="smith_height_correlated", facet_fresnel=ff, sigma_to_alpha=o["sigma_to_alpha"])
    extra = {
        "f0_factor": diffuse.f0_factor(spec),
        "f0": repr(o["f0"]),
        "rho": "1",
        "parametrisation": o["parametrisation"],
        "layout": "part = sigma slice; row = phi_index * N_view + view_index; column = light_index",
        "sigma_values": json.dumps([float(s) for s in sig_axis.values()]),
        **diffuse.sigma_record(sig_axis),
    }
    per = 1
    if integrated:  # at most (K + 3) u panels (K + 1 geometric ones, cut at u_l and u_v) x 4 arcs x n^2
        a = effective_alpha(sigma_alpha(sig_axis.values(), o["sigma_to_alpha"]), False)
        per = int(round(float(np.mean(n_tail_cuts_np(a) + 3)) * 4 * order * order))
        if adaptive:  # nominal: every panel at the first two orders, on at most two phi pieces (the work adapts)
            per = int(round(float(np.mean(n_tail_cuts_np(a) + 3)) * 2 * sum(n * n for n in FACET_ORDERS[:2])))
    estimator = PointEvaluation(o["f0"], name="gauss_legendre" if integrated else "closed_form", evaluations=per)
    if adaptive:
        tol = tolerance_of(o, FLOAT32_TOLERANCE)
        estimator = PointAdaptive(tol.absolute, tol.relative, o["f0"], evaluations=per)
    if o["estimator"] == "sobol_ndf":
        estimator = PointSobol(o["samples"] or DEFAULT_SOBOL, o["seed"], f0=o["f0"])
    block = o["size"][0] * o["size"][1]
    return per_texel_plan(
        diffuse_integrand(spec.records["model"], spec.records["facet_fresnel"]),
        estimator,
        grid,
        channels={"f": "the BRDF f_r(l, v) for rho = 1 at the baked f0 (1/sr; radiance = f E0 (n.l))"},
        reconstruction=RECONSTRUCTION,
        terms=terms,
        extra=extra,
        relative_error=True,
        error_estimate=integrated,
        # whole blocks (reciprocal_inputs), at least 512 texels and TILE_PHI_BLOCKS azimuths (texels that differ
        # only in phi share the u nodes of their m-integral: lutbake.sampling.diffuse.adaptive_azimuths_kernel)
        tile_texels=block * max(-(-512 // block), min(o["phi_size"], TILE_PHI_BLOCKS)) if adaptive else None,
    )


DESCRIPTION = (
    "the diffuse BRDF of four scalars as sigma slices of (light, view, azimuth) blocks (cosines or angles), "
    "microfacet (Eq. 4 integrated) or fitted (Eq. 8) or any diffuse model"
)
ESTIMATION = Estimation(BTF_ESTIMATORS, "gauss_legendre", SAMPLES_DOC, samples_min=2)
BTF = declare(
    "btf", DESCRIPTION, KEYS, plan, ESTIMATION, aliases=("diffuse_btf",), check=check_spec, texels=texel_count
)
