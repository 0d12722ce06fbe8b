"""``lutbake preview FILE``: one PNG to judge a table at a glance.

Top row: every channel as a colour-mapped image with labelled axes (ticks show the axis values the
file's metadata lists, so non-linear mappings and flipped rows read correctly; image row 0 is drawn at
the bottom). Bottom row (``dfg`` tables): spheres of increasing roughness lit by a simple sky/ground
environment with the split-sum, E = table(NoV, r) reconstructed per the file's layout, so a wrong axis,
flip or channel order shows up as an implausible sphere.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .axes import Axis

SPHERE_ROUGHNESS = (0.05, 0.25, 0.45, 0.65, 0.85)
SPHERE_F0 = np.array([1.0, 0.71, 0.29])  # gold-like conductor
SKY, GROUND = np.array([0.45, 0.65, 1.1]), np.array([0.06, 0.05, 0.04])
SUN_DIR = np.array([-0.45, 0.65, 0.6]) / np.linalg.norm([-0.45, 0.65, 0.6])
SUN_POWER = 1.5  # integral of the sun's radiance over the sphere (its irradiance scale)


def axis_from_meta(d: dict) -> Axis:
    lo, hi = d.get("range", [0.0, 1.0])
    clamp = d.get("clamp")
    listed = tuple(d["values"]) if d.get("mapping") == "listed" else ()
    return Axis(
        d["name"],
        d["dim"],
        int(d["count"]),
        float(lo),
        float(hi),
        texel=d.get("texel", "center"),
        mapping=d.get("mapping", "linear"),
        order=d.get("order", "lo_first"),
        clamp=tuple(clamp) if clamp else None,
        listed=listed,
    )


def read_table(path: Path) -> tuple[np.ndarray, dict]:
    """(data, attrs) from an EXR, or from a .npy with its sidecar <name>.npy.json."""
    if path.suffix == ".npy":
        from .io.integrity import sidecar_path

        side = sidecar_path(path)
        if not side.is_file():
            raise ValueError(f"{path}: no sidecar {side.name} with the table's conventions")
        return np.load(path).astype(np.float32), json.loads(side.read_text())["lutbake"]
    from .io.exr import read_exr

    return read_exr(path)


def sample(data: np.ndarray, axes: list[Axis], nov: np.ndarray, rough: np.ndarray) -> np.ndarray:
    """Bilinear (clamp-to-edge) lookup of a 2D dfg table at (NoV, roughness), via each axis' uv()."""
    y_axis, x_axis = axes
    by = {a.name: a for a in axes}
    rname = next(n for n in by if n != "NoV")
    u = {"NoV": by["NoV"].uv(nov), rname: by[rname].uv(rough if rname != "alpha" else rough**2)}
    h, w = data.shape[:2]
    x = np.clip(u[x_axis.name] * w - 0.5, 0, w - 1)
    y = np.clip(u[y_axis.name] * h - 0.5, 0, h - 1)
    x0 = np.clip(np.floor(x).astype(int), 0, max(w - 2, 0))
    y0 = np.clip(np.floor(y).astype(int), 0, max(h - 2, 0))
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    return (1 - fy) * ((1 - fx) * data[y0, x0] + fx * data[y0, x1]) + fy * ((1 - fx) * data[y1, x0] + fx * data[y1, x1])


def specular_E(t: np.ndarray, layout: str, f0: np.ndarray) -> np.ndarray:
    r, g = t[..., 0:1], t[..., 1:2]
    if layout.startswith("multiscatter"):
        return (1 - f0) * r + f0 * g
    return f0 * r + g


def sphere(data, axes, layout, roughness, size=128):
    """An orthographic sphere, view along -z, lit by prefiltered sky/ground radiance times E."""
    s = (np.arange(size) + 0.5) / size * 2 - 1
    X, Y = np.meshgrid(s, -s)
    inside = X**2 + Y**2 < 1
    Z = np.sqrt(np.clip(1 - X**2 - Y**2, 0, 1))
    nov = np.clip(Z, 1e-4, 1.0)
    refl = np.stack([2 * nov * X, 2 * nov * Y, 2 * nov * Z - 1], -1)  # R = 2 (n.v) n - v, v = +z
    up = np.clip(0.5 + 0.5 * refl[..., 1], 0, 1)[..., None]
    radiance = GROUND + (SKY - GROUND) * (up**0.5)
    avg = 0.5 * (SKY + GROUND)
    blur = roughness**2  # the prefiltered sky tends to its average as roughness grows
    # a sun prefiltered by a lobe of solid angle ~ 2 pi w: exp((cos - 1) / w) / (2 pi w)
    w = max(2.0 * roughness**4, 2e-4)
    sun = SUN_POWER * np.exp((refl @ SUN_DIR - 1) / w) / (2 * np.pi * w)
    prefiltered = (1 - blur) * radiance + blur * avg + np.minimum(sun, 50.0)[..., None]
    E = specular_E(sample(data, axes, nov, np.full_like(nov, roughness)), layout, SPHERE_F0)
    rgb = prefiltered * E
    rgb = np.where(inside[..., None], rgb, 0.08)
    return np.clip(rgb / (1 + 0.25 * rgb), 0, 1) ** (1 / 2.2)  # soft tone map + display gamma (a picture)


def render(path, out=None) -> Path:
    """Write the preview PNG of the table at ``path`` (default: <path stem>.preview.png)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    data, attrs = read_table(path)
    axes = [axis_from_meta(d) for d in json.loads(attrs["axes"])]
    names = json.loads(attrs.get("channel_names", "{}"))
    meanings = json.loads(attrs.get("channels", "{}"))
    terms = json.loads(attrs.get("terms", "{}"))
    if data.ndim == 4:
        data = data[data.shape[0] // 2]  # the middle slice of a 3D table
        axes = axes[1:]
    nch = data.shape[-1]
    spheres = attrs.get("kind") == "dfg" and nch >= 2
    ncols = max(nch, len(SPHERE_ROUGHNESS) if spheres else 0)
    fig = plt.figure(figsize=(3.2 * ncols, 6.4 if spheres else 3.4), dpi=100)
    y_axis, x_axis = axes
    for c in range(nch):
        ax = fig.add_subplot(2 if spheres else 1, ncols, c + 1)
        im = ax.imshow(data[..., c], origin="lower", cmap="viridis", interpolation="nearest", aspect="auto")
        letter = "RGBA"[c]
        ax.set_title(f"{letter} = {names.get(letter, '?')}", fontsize=9)
        for axis, setter, ticker in ((x_axis, ax.set_xlabel, ax.set_xticks), (y_axis, ax.set_ylabel, ax.set_yticks)):
            idx = np.unique(np.linspace(0, axis.count - 1, 5).round().astype(int))
            vals = axis.values()
            ticker(idx, [f"{vals[i]:.3g}" for i in idx], fontsize=7)
            setter(f"{axis.name} ({axis.mapping}, {axis.texel}, {axis.order})", fontsize=8)
        fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04).ax.tick_params(labelsize=7)
        ax.tick_params(labelsize=7)
        ax.text(0.0, -0.32, meanings.get(letter, "")[:60], transform=ax.transAxes, fontsize=6)
    if spheres:
        layout = terms.get("layout", "scale_bias")
        for k, r in enumerate(SPHERE_ROUGHNESS):
            ax = fig.add_subplot(2, ncols, ncols + k + 1)
            ax.imshow(sphere(data, axes, layout, r))
            ax.set_title(f"r = {r:g}, f0 = gold", fontsize=8)
            ax.axis("off")
    fig.suptitle(f"{path.name}: {attrs.get('kind', '?')} {attrs.get('table', '')}  {json.dumps(terms)}", fontsize=9)
    fig.tight_layout()
    out = Path(out) if out else path.with_name(path.stem + ".preview.png")
    from .io.atomic import atomic_write

    atomic_write(out, lambda tmp: fig.savefig(tmp, format="png"))
    plt.close(fig)
    return out
