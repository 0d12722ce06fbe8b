"""Kind ``btf``: a diffuse BRDF of four scalars, f(θ_l, θ_v, φ; σ) (rho = 1, f0 baked), tabulated as one 3D block
per σ slice: the seed's "BTF-like techniques" for the microfacet diffuse model (Eq. 4, integrated over m by
lutbake.tables.diffuse.fd_microfacet_for) or any closed model (``model = "fitted"`` for Eq. 8, to diff the
fit against the integral).

Layout (one EXR, lutbake.io.exr): a multi-part file with one part per σ slice (z; σ of the slice in the
part's lutbake:slice_value and in lutbake:axes). Inside a part, columns are the light axis (x) and the rows
hold (φ, view) flattened: image row = iφ * N_v + i_v (the φ axis has dim ``y_block``). Parametrisation:
- ``cosines``: x = n.l in [0, 1], y = n.v in [0, 1], y_block = cos φ in [-1, 1];
- ``angles``: x = θ_l in [0, π/2], y = θ_v in [0, π/2], y_block = φ in [0, π] (radians).
φ is the azimuth between l and v; f is even in φ, so [0, π] (cos φ in [-1, 1]) covers every pair.
Reciprocity f(l, v) = f(v, l) makes every (φ, σ) block symmetric when the x and y grids agree (tested).
"""

from __future__ import annotations

import json

import numpy as np
import warp as wp

from ..axes import TEXELS, Axis
from . import diffuse, diffuse_albedo
from .base import Key, Kind, Plan

PARAMETRISATIONS = {
    "cosines": "x = NoL in [0, 1], y = NoV in [0, 1], row blocks = cos(phi) in [-1, 1]",
    "angles": "x = theta_l in [0, pi/2], y = theta_v in [0, pi/2], row blocks = phi in [0, pi] (radians)",
}
DEFAULT_ORDER = 12  # GL order of the m-integral (docs/diffuse.md: measured relative errors on the 16 x 32^3 grid)
GRAZING_COS = 0.15  # texels with n.l and n.v both below it get order + GRAZING_EXTRA
GRAZING_EXTRA = 8
ESTIMATE_EXTRA = 8  # the error estimate re-evaluates probe texels at their order + 8

KEYS = {
    "name": diffuse.KEYS["name"],
    "kind": diffuse.KEYS["kind"],
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
    "model": Key("model", "str", "microfacet", "the diffuse BRDF tabulated", diffuse.MODELS),
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
    "samples": Key(
        "samples",
        "int",
        None,
        "Gauss-Legendre order n of the m-integral (microfacet: up to "
        "(K + 3) x 4 n^2 facet normals per texel, K the tan(theta_m) panels); omitted: 12; closed models "
        "ignore it",
        minimum=2,
        maximum=64,
    ),
    "dtype": diffuse.KEYS["dtype"],
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
    if o["sigma_values"] is not None:
        vals = tuple(float(x) for x in o["sigma_values"])
        sig = Axis("sigma", "z", len(vals), vals[0], vals[-1], texel=tx, mapping="listed", listed=vals)
    else:
        sig = Axis("sigma", "z", o["sigma_size"], *o["sigma_range"], texel=tx)
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


def plan(spec) -> Plan:
    o = spec.options
    axes = axes_for(o)
    l, v, sigma = directions(axes, o["parametrisation"])
    model, ff = o["model"], o["facet_fresnel"]
    order = o["samples"] or DEFAULT_ORDER
    integrated = model == "microfacet"

    # texels with light and view both grazing hold the smallest values (f ~ 1e-5 in back-scattering): their
    # relative error converges last, so they get order + GRAZING_EXTRA (about 1 % of the texels)
    orders = np.where((l[:, 2] < GRAZING_COS) & (v[:, 2] < GRAZING_COS), order + GRAZING_EXTRA, order)

    def run(idx, extra, device):
        idx = np.arange(len(sigma))[idx]
        out = np.empty((len(idx), 1))
        for n in np.unique(orders[idx]):
            sel = orders[idx] == n
            out[sel, 0] = diffuse.eval_brdf(
                model,
                l[idx[sel]],
                v[idx[sel]],
                sigma[idx[sel]],
                o["f0"],
                ff,
                o["sigma_to_alpha"],
                int(n) + extra,
                device=device,
            )
        return out

    def error_estimate(data: np.ndarray, device: str) -> tuple[float, str]:
        n = len(sigma)
        grazing = np.flatnonzero((l[:, 2] <= l[:, 2].min()) | (v[:, 2] <= v[:, 2].min()))
        both = np.flatnonzero((l[:, 2] <= l[:, 2].min()) & (v[:, 2] <= v[:, 2].min()))
        idx = np.unique(
            np.concatenate([np.arange(0, n, max(1, n // 512)), grazing[:: max(1, len(grazing) // 128)], both])
        )
        ref = run(idx, ESTIMATE_EXTRA, device)[:, 0]
        got = data.reshape(n, -1)[idx, 0]
        ok = np.abs(ref) > 1e-6
        rel = float(np.max(np.abs(got - ref)[ok] / np.abs(ref[ok]))) if ok.any() else 0.0
        ab = float(np.max(np.abs(got - ref)))
        return rel, (
            f"max relative |orders - orders + {ESTIMATE_EXTRA}| / |orders + {ESTIMATE_EXTRA}| over "
            f"{int(ok.sum())} probe texels (strided + most grazing light or view + both most grazing; "
            f"|f| > 1e-6); max abs {ab:.3e}"
        )

    sig_axis = axes[0]
    terms = {
        "model": model,
        "f0": str(o["f0"]),
        "f0_factor": diffuse.f0_factor(model, ff),
        "parametrisation": o["parametrisation"],
    }
    if integrated:
        terms.update(ndf="ggx", masking="smith_height_correlated", facet_fresnel=ff, sigma_to_alpha=o["sigma_to_alpha"])
    extra = {
        "f0_factor": diffuse.f0_factor(model, ff),
        "f0": repr(o["f0"]),
        "rho": "1",
        "parametrisation": o["parametrisation"],
        "layout": "part = sigma slice; row = phi_index * N_view + view_index; column = light_index",
        "sigma_values": json.dumps([float(s) for s in sig_axis.values()]),
        "sigma_alpha": json.dumps([float(a) for a in diffuse.alpha_from_sigma(sig_axis.values(), o["sigma_to_alpha"])]),
    }
    per = 1
    if integrated:  # at most (K + 3) u panels (K + 1 geometric ones, cut at u_l and u_v) x 4 arcs x n^2
        a = diffuse.alpha_from_sigma(sig_axis.values(), o["sigma_to_alpha"]).astype(np.float64)
        k = np.clip(
            np.ceil(np.log(diffuse_albedo.TAIL_TAN / a) / np.log(diffuse_albedo.TAIL_RATIO)),
            1,
            diffuse_albedo.MAX_TAIL_CUTS,
        )
        per = int(round(float(np.mean(k + 3)) * 4 * order * order))
    key = (model, ff)
    return Plan(
        axes=axes,
        channels={"f": "the BRDF f_r(l, v) for rho = 1 at the baked f0 (1/sr; radiance = f E0 (n.l))"},
        reconstruction=RECONSTRUCTION,
        n_texels=len(sigma),
        n_channels=1,
        run_tile=lambda s, e, d: run(slice(s, e), 0, d),
        prepare=lambda d: wp.load_module(diffuse.brdf_kernel_for(*key).module, device=d),
        samples=per,
        estimator="gauss_legendre" if integrated else "closed_form",
        terms=terms,
        cost=float(len(sigma)) * per,
        extra=extra,
        error_estimate=error_estimate if integrated else None,
    )


def check_spec(spec) -> str | None:
    o = spec.options
    ns = o["sigma_size"] if o["sigma_values"] is None else len(o["sigma_values"])
    n = o["size"][0] * o["size"][1] * o["phi_size"] * ns
    if n > 1 << 26:
        return f"size x phi_size x sigma_size = {n} texels: at most {1 << 26}"
    return None


BTF = Kind(
    "btf",
    "the diffuse BRDF of four scalars as sigma slices of (light, view, azimuth) blocks (cosines or "
    "angles), microfacet (Eq. 4 integrated) or fitted (Eq. 8) or any diffuse model",
    KEYS,
    plan,
    aliases=("diffuse_btf",),
    check=check_spec,
)
