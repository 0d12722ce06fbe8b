"""``lutbake preview FILE``: one PNG to judge a table at a glance, for every kind and every format
lutbake reads (lutbake.io.readers).

- a 1D table (``albedo_avg``): each channel as a curve over its axis;
- a 2D table: each channel colour-mapped, ticks at the axis values the metadata lists (so non-linear
  mappings and flipped rows read correctly; image row 0 is drawn at the bottom);
- a 3D table (``specular_3d``, ``specular_aniso``, ``diffuse_3d``): a grid of slices, one row per channel,
  each slice titled with its z value (f0, anisotropy ...), one colour scale per channel;
- ``btf``: light x view images (theta_l across, theta_v up), one row per sigma, one column per phi;
- ``ltc``, from its EXR or any engine layout (lutbake.io.engine_files): the textures ltc_1 (matrix coefficients)
  and ltc_2 (magnitude, fresnel, sphere) as the two slices of a 3D table, per channel; HDRP's .cs holds one
  texture, drawn as a 2D table of HDRP's own texel;
- a table without lutbake metadata: its channels (or slices) by index.
A row of spheres follows where the table has a split-sum reconstruction (``dfg`` and ``specular_aniso``
layouts, ``specular_3d``, the sheen ``charlie`` layout): orthographic spheres lit by a sky/ground
environment with a sun, shaded with the file's own reconstruction, E looked up through the table's axes
(``Axis.uv``), so a wrong axis, flip or channel order shows up as an implausible sphere. Kinds with no
split-sum reconstruction (albedo, diffuse, btf, the sheen albedo-scaling layouts) get no sphere row.
"""

from __future__ import annotations

import re
import textwrap
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..axes import Axis
from ..io.bounded import reading_for
from ..io.readers import TableView, read_table
from ..textsafe import bounded, shorten

N_SPHERES = 5
MAX_CHANNELS = 4  # channels drawn (a table has 1 to 4; a renderer's EXR may add Z and others)
MAX_SLICES = 6  # columns of a 3D slice grid
MAX_BTF_SIGMAS, MAX_BTF_PHIS = 4, 5
SPHERE_F0 = np.array([1.0, 0.71, 0.29])  # a gold-like conductor's f0 (RGB)
SHEEN_COLOR = np.array([1.0, 1.0, 1.0])
SKY, GROUND = np.array([0.75, 0.82, 0.95]), np.array([0.06, 0.05, 0.04])  # a pale sky: gold reads as gold
SUN_DIR = np.array([-0.45, 0.65, 0.6]) / np.linalg.norm([-0.45, 0.65, 0.6])
SUN_POWER = 1.5  # integral of the sun's radiance over the sphere (its irradiance scale)
UNITS = {"phi": "rad", "theta_l": "rad", "theta_v": "rad"}
SYMBOLS = {
    "sigma": "σ",
    "phi": "φ",
    "cos_phi": "cos φ",
    "theta_l": "θ_l",
    "theta_v": "θ_v",
    "NoV": "n·v",
    "NoL": "n·l",
    "alpha": "α",
    "perceptual_roughness": "perceptual roughness r",
    "f0": "f0",
    "sphere_z": "z = cos elevation of F",
    "sphere_len": "len = |F|",
}
ROUGHNESS_AXES = ("perceptual_roughness", "alpha")
MEANING_WIDTH, MEANING_LINES = 44, 4  # characters per line and lines of a channel's meaning under its name
CLIP_PERCENTILE, CLIP_RATIO = 99.0, 3.0  # colour scale: see _color_range
CHARS_PER_INCH = 13  # of 9-point text: where the figure title wraps
# LTC matrix entries span decades (HDRP's M^-1 / M^-1_22 reaches the FP16 saturation 65504 at smooth grazing texels
# while most lie near 1): past LOG_SPAN between the largest |value| and the LOG_FLOOR_PERCENTILE of the non-zero
# ones, a symmetric log colour scale, linear within that floor
LOG_SPAN, LOG_FLOOR_PERCENTILE = 1.0e2, 5.0
LOG_TICKS_PER_SIGN = 4  # decades labelled on each side of 0
LTC_PANEL_INCHES, LTC_TITLE_CHARS, LTC_TITLE_LINES = 3.3, 34, 5
LTC_TEXTURES = ("ltc_1: the inverse matrix M⁻¹ (normalised)", "ltc_2: magnitude, Fresnel, fit error, sphere")
SPHERE_MEANING = "sphere"  # the ltc_2 channel on its own axes (lutbake.kinds.ltc: x = z * 0.5 + 0.5, y = len)


def _label(axis: Axis) -> str:
    unit = UNITS.get(axis.name)
    return SYMBOLS.get(axis.name, axis.name) + (f" [{unit}]" if unit else "")


def _short(axis: Axis, value: float) -> str:
    unit = UNITS.get(axis.name)
    return f"{SYMBOLS.get(axis.name, axis.name)} = {value:.3g}" + (f" {unit}" if unit else "")


# ------------------------------------------------------------------------------------- lookups


def lookup(data: np.ndarray, axes: list[Axis], coords: dict[str, np.ndarray | float]) -> np.ndarray:
    """n-linear, clamp-to-edge lookup of ``data`` (one axis per dimension, in order, channels last) at
    the axis values ``coords[axis.name]``, through each axis' ``uv`` (its texel convention, mapping and
    order): what a GPU's filtered fetch returns."""
    grids = np.broadcast_arrays(*[np.asarray(coords[a.name], np.float64) for a in axes])
    lo, frac = [], []
    for axis, n, g in zip(axes, data.shape[:-1], grids):
        x = np.clip(axis.uv(g) * n - 0.5, 0, n - 1)
        i0 = np.clip(np.floor(x).astype(int), 0, max(n - 2, 0))
        lo.append(i0)
        frac.append(np.clip(x - i0, 0.0, 1.0)[..., None])
    out = 0.0
    for corner in range(1 << len(axes)):
        w, idx = 1.0, []
        for d, (i0, f) in enumerate(zip(lo, frac)):
            up = corner >> d & 1
            idx.append(np.minimum(i0 + up, data.shape[d] - 1))
            w = w * (f if up else 1 - f)
        out = out + w * data[tuple(idx)]
    return out


def split_sum_form(layout: str) -> str | None:
    """How a file's R, G (B) rebuild E, from its layout's record (lutbake.layouts.base.Layout.split_sum): scale_bias,
    multiscatter, sheen or None (also for a layout this lutbake does not know)."""
    from ..layouts import REGISTRY

    lay = REGISTRY.get(("dfg", layout))
    return lay.split_sum if lay is not None else None


def split_sum(view: TableView):
    """(how the spheres are shaded, E(nov, roughness value) -> RGB, broad) from the file's own
    reconstruction, or None where the kind has none. ``roughness value`` is in the units of the table's
    roughness axis; ``broad``: the lobe is prefiltered as a near-uniform blur (sheen)."""
    axes = [a for a in view.axes if a.dim != "y_block"]
    names = [a.name for a in axes]
    rough = next((n for n in names if n in ROUGHNESS_AXES), None)
    if view.kind is None or "NoV" not in names or rough is None or view.data.ndim != 3 + (len(axes) == 3):
        return None
    form = split_sum_form(view.terms.get("layout", "scale_bias"))
    z = axes[0] if len(axes) == 3 else None
    nch = view.data.shape[-1]

    def at(nov, r, zval=None):
        coords = {"NoV": nov, rough: r}
        if z is not None:
            coords[z.name] = zval
        return lookup(view.data, axes, coords)

    if view.kind in ("dfg", "specular_aniso") and nch >= 2:
        zmid = float(z.values()[z.count // 2]) if z is not None else None
        where = f", {_short(z, zmid)}" if z is not None else ""
        if form == "scale_bias":  # Karis 2013: E = f0 * scale + bias

            def E_scale_bias(nov, r):
                t = at(nov, r, zmid)
                return SPHERE_F0 * t[..., 0:1] + t[..., 1:2]

            return f"E = f0 R + G, f0 = gold{where}", E_scale_bias, False
        if form == "multiscatter":  # Filament: E = mix(R, G, f0)

            def E_multiscatter(nov, r):
                t = at(nov, r, zmid)
                return (1 - SPHERE_F0) * t[..., 0:1] + SPHERE_F0 * t[..., 1:2]

            return f"E = (1 - f0) R + f0 G, f0 = gold{where}", E_multiscatter, False
        if form == "sheen" and nch >= 3:
            # the sheen lobe is broad: its prefiltered (Charlie) environment is close to the mean radiance
            return (
                "sheen = prefiltered_charlie sheenColor B, sheenColor = white",
                lambda nov, r: SHEEN_COLOR * at(nov, r)[..., 2:3],
                True,
            )
        return None
    if view.kind == "specular_3d":
        if z is not None and z.name == "f0":
            return (
                "E = T(n·v, r, f0) per RGB f0 of gold",
                lambda nov, r: np.concatenate([at(nov, r, f)[..., 0:1] for f in SPHERE_F0], axis=-1),
                False,
            )
        if z is None and nch == 3:
            return "E = T(n·v, r).rgb (the metal's own complex Fresnel)", lambda nov, r: at(nov, r), False
    return None


def sphere(E, roughness_value: float, perceptual: float, size: int = 128) -> np.ndarray:
    """An orthographic sphere, view along -z, lit by a prefiltered sky/ground/sun environment times
    E(n.v, roughness_value) (RGB); ``perceptual`` widens the prefilter."""
    s = (np.arange(size) + 0.5) / size * 2 - 1
    X, Y = np.meshgrid(s, -s)
    inside = X**2 + Y**2 < 1
    Z = np.sqrt(np.clip(1 - X**2 - Y**2, 0, 1))
    nov = np.clip(Z, 1e-4, 1.0)
    refl = np.stack([2 * nov * X, 2 * nov * Y, 2 * nov * Z - 1], -1)  # R = 2 (n.v) n - v, v = +z
    up = np.clip(0.5 + 0.5 * refl[..., 1], 0, 1)[..., None]
    radiance = GROUND + (SKY - GROUND) * (up**0.5)
    blur = perceptual**2  # the prefiltered sky tends to its average as roughness grows
    w = max(2.0 * perceptual**4, 2e-4)  # a sun prefiltered by a lobe of solid angle ~ 2 pi w
    sun = SUN_POWER * np.exp((refl @ SUN_DIR - 1) / w) / (2 * np.pi * w)
    prefiltered = (1 - blur) * radiance + blur * 0.5 * (SKY + GROUND) + np.minimum(sun, 50.0)[..., None]
    rgb = prefiltered * E(nov, np.full_like(nov, roughness_value))
    rgb = np.where(inside[..., None], rgb, 0.08)
    return np.clip(rgb / (1 + 0.25 * rgb), 0, 1) ** (1 / 2.2)  # soft tone map + display gamma (a picture)


# ---------------------------------------------------------------------------------------- drawing


def _ticks(ax, axis: Axis | None, n: int, which: str, label: bool = True) -> None:
    idx = np.unique(np.linspace(0, n - 1, min(n, 4)).round().astype(int))
    vals = axis.values() if axis is not None else np.arange(n)
    setter = ax.set_xticks if which == "x" else ax.set_yticks
    setter(idx, [f"{vals[i]:.3g}" for i in idx], fontsize=7)
    if label:
        text = f"{_label(axis)} ({axis.mapping}, {axis.texel})" if axis is not None else f"{which} index"
        (ax.set_xlabel if which == "x" else ax.set_ylabel)(text, fontsize=8)


def _image(fig, ax, img, y_axis, x_axis, vmin=None, vmax=None, labels=(True, True), bar=True, norm=None):
    limits = {"norm": norm} if norm is not None else {"vmin": vmin, "vmax": vmax}
    im = ax.imshow(img, origin="lower", cmap="viridis", interpolation="nearest", aspect="auto", **limits)
    _ticks(ax, x_axis, img.shape[1], "x", labels[0])
    _ticks(ax, y_axis, img.shape[0], "y", labels[1])
    if bar:
        fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04).ax.tick_params(labelsize=7)
    return im


def _color_range(values: np.ndarray) -> tuple[float, float, str]:
    """(vmin, vmax, note): the full range, or up to the CLIP_PERCENTILE when a few texels (a grazing corner)
    are far above the rest, so the rest stays readable; the note says so and gives the true maximum. Non-finite
    values (masked as NaN by _drawable) are left out."""
    values = values[np.isfinite(values)]
    if not values.size:
        return 0.0, 1.0, "\nno finite value"
    lo, hi = float(values.min()), float(values.max())
    top = float(np.percentile(values, CLIP_PERCENTILE))
    if hi - lo > CLIP_RATIO * (top - lo) > 0:
        return lo, top, f"\ncolours clipped at the {CLIP_PERCENTILE:g}th percentile {top:.3g} (max {hi:.3g})"
    return lo, hi, ""


def _channel_title(view: TableView, c: int) -> str:
    name, meaning = view.channel_names[c], view.meanings[c]
    meaning = meaning.split(": ", 1)[1] if meaning.startswith(name + ": ") else meaning
    lines = textwrap.wrap(meaning, MEANING_WIDTH)
    if len(lines) > MEANING_LINES:
        lines = lines[: MEANING_LINES - 1] + [textwrap.shorten(" ".join(lines[MEANING_LINES - 1 :]), MEANING_WIDTH)]
    col = view.data[..., c]
    const = f"  (constant {float(col.flat[0]):.3g})" if col.size and col.min() == col.max() else ""
    return "\n".join([f"{'RGBA'[c]} = {name}{const}" if c < len("RGBA") else f"{name}{const}"] + lines)


def _suptitle(view: TableView, path: Path, width_chars: int) -> str:
    name = shorten(path.name)
    head = f"{name}: {view.kind} table '{view.name}'" if view.kind else f"{name}: no lutbake metadata"
    terms = ", ".join(f"{k} {v}" for k, v in view.terms.items())
    attrs = view.attrs
    extra = ", ".join(f"{k} {bounded(attrs[k], 60)}" for k in ("estimator", "samples") if k in attrs)
    body = "; ".join(x for x in (terms, extra + (" per texel" if "samples" in attrs else "")) if x)
    return "\n".join([head] + textwrap.wrap(body, max(width_chars, 40)))


def _fig_1d(plt, view):
    axis = next(a for a in view.axes if a.dim == "x")
    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=100, layout="constrained")
    for c in range(view.data.shape[-1]):
        ax.plot(axis.values(), view.data[0, :, c], marker=".", label=view.channel_names[c])
    ax.set_xlabel(f"{_label(axis)} ({axis.mapping}, {axis.texel})", fontsize=9)
    ax.set_ylabel(", ".join(view.channel_names), fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("\n".join(textwrap.wrap(view.meanings[0], 70)), fontsize=8)
    return fig, 6.4


def _pick(n: int, k: int) -> list[int]:
    return sorted(set(np.linspace(0, n - 1, min(n, k)).round().astype(int).tolist()))


def _axis_by_dim(view, dim):
    return next((a for a in view.axes if a.dim == dim), None)


SPHERE_ROW_INCHES = 3.2


def _canvases(plt, width: float, grid_height: float, spheres):
    """The figure, the canvas the table is drawn on and (with spheres) the canvas of the sphere row."""
    fig = plt.figure(
        figsize=(width, grid_height + (SPHERE_ROW_INCHES if spheres else 0) + 0.8), dpi=100, layout="constrained"
    )
    if not spheres:
        return fig, fig, None
    top, bottom = fig.subfigures(2, 1, height_ratios=[grid_height, SPHERE_ROW_INCHES])
    return fig, top, bottom


def _fig_2d(plt, view, spheres):
    nch = view.data.shape[-1]
    width = max(3.4 * nch, 2.9 * N_SPHERES if spheres else 0)
    fig, canvas, row = _canvases(plt, width, 3.9, spheres)
    y_axis, x_axis = _axis_by_dim(view, "y"), _axis_by_dim(view, "x")
    for c in range(nch):
        ax = canvas.add_subplot(1, max(nch, 2), c + 1)
        vmin, vmax, clipped = _color_range(view.data[..., c])
        _image(canvas, ax, view.data[..., c], y_axis, x_axis, vmin, vmax)
        ax.set_title(_channel_title(view, c) + clipped, fontsize=8, loc="left")
    if spheres:
        _sphere_row(row, view, spheres)
    return fig, width


def _fig_3d(plt, view, spheres):
    data = view.data
    z_axis, y_axis, x_axis = (_axis_by_dim(view, d) for d in ("z", "y", "x"))
    nch = data.shape[-1]
    picks = _pick(data.shape[0], MAX_SLICES)
    width = max(2.6 * len(picks) + 1.2, 2.9 * N_SPHERES if spheres else 0)
    fig, canvas, row = _canvases(plt, width, 2.9 * nch + 0.4, spheres)
    zvals = z_axis.values() if z_axis is not None else None
    for c in range(nch):
        vmin, vmax, clipped = _color_range(data[..., c])
        axes = []
        for j, k in enumerate(picks):
            ax = canvas.add_subplot(nch, len(picks), c * len(picks) + j + 1)
            im = _image(
                canvas, ax, data[k, ..., c], y_axis, x_axis, vmin, vmax, labels=(c == nch - 1, j == 0), bar=False
            )
            where = _short(z_axis, zvals[k]) if z_axis is not None else f"slice {k}"
            ax.set_title(
                f"{where}  (slice {k})" if j else f"{_channel_title(view, c)}{clipped}\n{where}  (slice {k})",
                fontsize=8,
                loc="left",
            )
            axes.append(ax)
        canvas.colorbar(im, ax=axes, fraction=0.02, pad=0.02).ax.tick_params(labelsize=7)
    if spheres:
        _sphere_row(row, view, spheres)
    return fig, width


def _log_norm(values: np.ndarray):
    """A symmetric log norm when |values| span more than LOG_SPAN (see there), else None (a linear scale)."""
    from matplotlib.colors import SymLogNorm

    mag = np.abs(values[np.isfinite(values)])
    nonzero = mag[mag > 0]
    if nonzero.size == 0:
        return None
    floor = float(np.percentile(nonzero, LOG_FLOOR_PERCENTILE))
    if float(nonzero.max()) <= LOG_SPAN * floor:
        return None
    return SymLogNorm(linthresh=floor, vmin=float(np.nanmin(values)), vmax=float(np.nanmax(values)), base=10)


def _ltc_meanings(meaning: str) -> tuple[str, str]:
    """A 3D LTC channel's meaning, "slice 0 (ltc_1): ...; slice 1 (ltc_2): ...", as (ltc_1's, ltc_2's)."""
    m = re.search(r"slice 0(?: \(ltc_1\))?: (.*?); slice 1(?: \(ltc_2\))?: (.*)", meaning)
    return (m.group(1), m.group(2)) if m else (meaning, meaning)


def _ltc_title(letter: str, text: str, note: str) -> str:
    lines = textwrap.wrap(f"{letter}: {text}", LTC_TITLE_CHARS)
    if len(lines) > LTC_TITLE_LINES:
        lines = lines[: LTC_TITLE_LINES - 1] + [
            textwrap.shorten(" ".join(lines[LTC_TITLE_LINES - 1 :]), LTC_TITLE_CHARS)
        ]
    return "\n".join(lines + ([note] if note else []))


def _sphere_axes(n_y: int, n_x: int) -> tuple[Axis, Axis]:
    """The sphere channel's own (y, x) axes: len = j/(N - 1) up, z = 2 i/(N - 1) - 1 across (endpoint texels)."""
    return Axis("sphere_len", "y", n_y, 0.0, 1.0, texel="endpoint"), Axis(
        "sphere_z", "x", n_x, -1.0, 1.0, texel="endpoint"
    )


def _log_ticks(norm) -> list[float]:
    """Decades of a SymLogNorm's range, at most LOG_TICKS_PER_SIGN a side (every k-th), and 0 where it is inside."""

    def decades(top: float) -> list[float]:
        if top <= norm.linthresh:
            return []
        ks = list(range(int(np.ceil(np.log10(norm.linthresh))), int(np.floor(np.log10(top))) + 1))
        step = max(1, -(-len(ks) // LOG_TICKS_PER_SIGN))
        return [10.0**k for k in ks[::-1][::step]]

    ticks = [-v for v in decades(-norm.vmin)] + ([0.0] if norm.vmin < 0 < norm.vmax else []) + decades(norm.vmax)
    return sorted(ticks)


def _ltc_panel(canvas, ax, img, axes, title, matrix: bool) -> None:
    """One LTC channel: a log colour scale for a matrix entry spanning decades, else the usual range."""
    from matplotlib.ticker import FuncFormatter

    norm = _log_norm(img) if matrix else None
    if norm is not None:
        note = "log colour scale"
        im = _image(canvas, ax, img, *axes, norm=norm, bar=False)
        ticks = _log_ticks(norm)
    else:
        vmin, vmax, note = _color_range(img)
        im = _image(canvas, ax, img, *axes, vmin, vmax, bar=False)
        ticks = None
    if img.size and img.min() == img.max():
        note = f"constant {float(img.flat[0]):.3g}"
    bar = canvas.colorbar(im, ax=ax, fraction=0.046, pad=0.04, ticks=ticks)
    bar.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))  # plain text: mathtext is off
    bar.ax.tick_params(labelsize=7)
    ax.set_title(_ltc_title(*title, note.strip()), fontsize=7, loc="left")


def _fig_ltc(plt, view):
    """An LTC table: one row per texture, ltc_1 (the matrix, log-scaled where it spans decades) and ltc_2, each
    channel its own panel and colour scale, each row titled once (a subfigure each: no title overlaps another),
    the sphere channel on its own (z, len) axes. HDRP's .cs holds the matrix alone: one row."""
    data = view.data if view.data.ndim == 4 else view.data[None]
    n_tex, nch = data.shape[0], data.shape[-1]
    table_axes = (_axis_by_dim(view, "y"), _axis_by_dim(view, "x"))
    width = LTC_PANEL_INCHES * nch
    fig = plt.figure(figsize=(width, 4.3 * n_tex + 0.8), dpi=100, layout="constrained")
    rows = fig.subfigures(n_tex, 1) if n_tex > 1 else [fig]
    for k, row in enumerate(rows):
        if n_tex > 1:
            row.suptitle(LTC_TEXTURES[k] + f"  (slice {k})", fontsize=9, x=0.01, ha="left")
        for c in range(nch):
            meaning = _ltc_meanings(view.meanings[c])[k] if n_tex > 1 else view.meanings[c]
            sphere_channel = n_tex > 1 and k == 1 and meaning.startswith(SPHERE_MEANING)
            img = data[k, ..., c]
            axes = _sphere_axes(*img.shape) if sphere_channel else table_axes
            name = view.channel_names[c]
            letter = f"{'RGBA'[c]} = {name}" if name not in "xyzw" else f"{'RGBA'[c]} (.{name})"
            _ltc_panel(row, row.add_subplot(1, nch, c + 1), img, axes, (letter, meaning), matrix=k == 0)
    return fig, width


def _fig_btf(plt, view):
    """Light x view images, one row per sigma slice, one column per phi block (a y_block axis)."""
    z_axis, block, y_axis, x_axis = (_axis_by_dim(view, d) for d in ("z", "y_block", "y", "x"))
    data = view.data if view.data.ndim == 4 else view.data[None]
    sig = _pick(data.shape[0], MAX_BTF_SIGMAS)
    phis = _pick(block.count, MAX_BTF_PHIS)
    ny = y_axis.count
    vmin, vmax, _ = _color_range(data[..., 0])
    fig = plt.figure(figsize=(2.6 * len(phis) + 1.4, 2.6 * len(sig) + 1.4), dpi=100, layout="constrained")
    zvals, pvals = (z_axis.values() if z_axis is not None else None), block.values()
    for i, k in enumerate(sig):
        for j, p in enumerate(phis):
            ax = fig.add_subplot(len(sig), len(phis), i * len(phis) + j + 1)
            img = data[k, p * ny : (p + 1) * ny, :, 0]
            im = _image(fig, ax, img, y_axis, x_axis, vmin, vmax, labels=(i == len(sig) - 1, j == 0), bar=False)
            where = _short(z_axis, zvals[k]) + ", " if z_axis is not None else ""
            ax.set_title(f"{where}{_short(block, pvals[p])}", fontsize=8)
    fig.colorbar(im, ax=fig.axes, fraction=0.02, pad=0.02).ax.tick_params(labelsize=7)
    fig.supxlabel(_channel_title(view, 0).replace("\n", " "), fontsize=8)
    return fig, 2.6 * len(phis) + 1.4


def _sphere_row(canvas, view, spheres):
    how, E, broad = spheres
    canvas.suptitle(f"spheres lit by a sky, ground and sun environment: {how}", fontsize=8)
    rough = next(a for a in view.axes if a.name in ROUGHNESS_AXES)
    vals = rough.values()
    lo, hi = float(vals.min()), float(vals.max())
    for k, v in enumerate(lo + (hi - lo) * np.linspace(0.05, 0.95, N_SPHERES)):
        ax = canvas.add_subplot(1, N_SPHERES, k + 1)
        perceptual = 1.0 if broad else float(np.sqrt(v)) if rough.name == "alpha" else float(v)
        ax.imshow(sphere(E, float(v), perceptual))
        ax.set_title(_short(rough, v), fontsize=8)
        ax.axis("off")


def _drawable(view: TableView) -> tuple[TableView, list[str]]:
    """The view as drawn, and what was left out, each in one line: channels past MAX_CHANNELS (an EXR's RGBA + Z: the
    RGBA channels are drawn), and non-finite values, masked (NaN: not coloured; no sphere row is shaded from them)."""
    notes = []
    nch = view.data.shape[-1]
    if nch > MAX_CHANNELS:
        left = ", ".join(view.channel_names[MAX_CHANNELS:])
        notes.append(f"{nch} channels: the first {MAX_CHANNELS} are drawn, not {bounded(left, 200)}")
        view = replace(
            view,
            data=view.data[..., :MAX_CHANNELS],
            channel_names=view.channel_names[:MAX_CHANNELS],
            meanings=view.meanings[:MAX_CHANNELS],
        )
    bad = ~np.isfinite(view.data)
    count = int(bad.sum())
    if count:
        notes.append(f"{count} non-finite values (NaN/Inf) of {view.data.size} masked: drawn uncoloured")
        view = replace(view, data=np.where(bad, np.float32(np.nan), view.data))
    return view, notes


def figure(path):
    """The preview of the table file at ``path`` as a matplotlib Figure (Agg; close it when done)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    with reading_for("preview"):  # the read's memory budget counts what drawing takes
        view, notes = _drawable(read_table(path))
    spheres = split_sum(view) if not notes else None
    dims = {a.dim for a in view.axes}
    with matplotlib.rc_context({"text.parse_math": False}):  # names from the file are text: "$x$" is no formula
        if "y_block" in dims:
            fig, inches = _fig_btf(plt, view)
        elif view.kind == "ltc" and view.data.ndim in (3, 4) and view.data.shape[-1] == 4:
            fig, inches = _fig_ltc(plt, view)
        elif view.axes and dims == {"x"}:
            fig, inches = _fig_1d(plt, view)
        elif view.data.ndim == 4:
            fig, inches = _fig_3d(plt, view, spheres)
        else:
            fig, inches = _fig_2d(plt, view, spheres)
        note = (
            ""
            if spheres or not view.kind or notes
            else f"\n(no sphere row: {view.kind} has no split-sum reconstruction)"
        )
        note += "".join(f"\n({n})" for n in notes)
        fig.suptitle(_suptitle(view, path, int(inches * CHARS_PER_INCH)) + note, fontsize=9)
    return fig


def render(path, out=None, dpi: int = 100, force: bool = False) -> Path:
    """Write the preview PNG of the table at ``path`` (default: <path stem>.preview.png beside it); a cube map
    (an environment table's KTX 2.0, DDS or EXR) is drawn by lutbake.commands.preview_cube. ``out`` is checked
    before anything is read (lutbake.preflight.check_image_output): never the table, its sidecar or a config, a
    ``.png`` unless ``force``, in a directory that takes files."""
    from ..io.cubemap import cube_kind
    from ..preflight import check_image_output, input_files
    from .figure_file import save_figure

    path = Path(path)
    if cube_kind(path) is not None:
        from .preview_cube import render_cube

        return render_cube(path, out, dpi, force)
    out = Path(out) if out else path.with_name(path.stem + ".preview.png")
    check_image_output(out, input_files(path), force, "--out")
    return save_figure(figure(path), out, dpi)
