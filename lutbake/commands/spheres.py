"""``lutbake spheres ENVIRONMENT``: what the split sum costs, in pictures. Spheres of perceptual roughness r (alpha =
r^2) of two materials, seen by an orthographic camera (lutbake.environment.render), shaded three ways under one
texel-constant lat-long environment:

- **ground truth** (lutbake.environment.ground_truth): f = GGX D, height-correlated Smith G2, Schlick F (+ rho / pi,
  the dielectric's Lambert base) integrated against every texel of the environment; its error is measured on probe
  pixels against the rule refined (K x 2, one node more per axis and texel) and stated per sphere;
- **split sum** (Karis 2013): the prefiltered cube (lutbake.environment.prefilter.bake_cube, lobe ``ggx_nl``, one
  mip per r of the ``linear`` curve) looked up at R = reflect(-v, n) at the curve's lod, trilinear and seamless,
  times lutbake's DFG table of preset ``bevy``'s conventions (scale_bias: E = f0 scale + bias; 64^2, perceptual
  roughness, GGX, height-correlated Smith), plus the irradiance cube (E / pi) times the albedo;
- their difference, split sum - ground truth (luminance, signed).
Per sphere: max and RMS over its pixels and channels of |split - truth|, and the mean of split - truth (its bias),
each divided by the sphere's mean ground-truth luminance (``SphereRenders.errors``).

**Diffuse** (``render_diffuse``): a diffuse model's ground truth (its BRDF, rho = 1, f0 = 0, against every texel) vs
the split-sum style irradiance_over_pi(n) E_d(n.v, sigma), E_d from lutbake's ``diffuse`` table of the model (the
kind's reconstruction: diffuse = albedo (irradiance / pi) E). Lambert's E_d = 1: the approximation is exact there
but for the irradiance cube's interpolation.

Both methods see the same environment: the source reduced by its box pyramid (lutbake.environment.latlong, exact
solid-angle-weighted means) to at most ``height`` rows.
"""

from __future__ import annotations

import functools
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..environment import render
from ..environment.curves import CURVES, MipCurve
from ..environment.ground_truth import Quality
from .preview import SPHERE_F0, lookup


@dataclass(frozen=True)
class Material:
    """Specular f0 (RGB, Schlick) and the Lambert base's albedo rho (RGB; 0: none): f = f_GGX + rho / pi."""

    name: str
    f0: tuple[float, float, float]
    albedo: tuple[float, float, float]


MATERIALS = (
    Material("gold", tuple(float(x) for x in SPHERE_F0), (0.0, 0.0, 0.0)),
    Material("dielectric", (0.04, 0.04, 0.04), (0.5, 0.5, 0.5)),
)
ROUGHNESS = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)
DIFFUSE_MODELS = (("lambert", 0.0), ("oren_nayar", 1.0), ("fitted", 1.0))  # (model, sigma)
CUBE_SIZE, IRRADIANCE_SIZE = 64, 16
DFG_PRESET, CURVE, LOBE = "bevy", "linear", "ggx_nl"
DIFFUSE_TABLE_SIZE = [64, 16]  # [NoV, sigma]
MAX_HEIGHT = 128  # rows of the environment both methods see (the source's pyramid level at or below it)
VIEW_TURN, VIEW_ELEVATION = 0.6, 0.3  # radians: the camera's azimuth past the brightest texel's, its elevation
PROBE_STRIDE = 4  # every 4th pixel of a sphere is evaluated again with the refined rule
CLIP_PERCENTILE = 99.0  # the difference rows' colour scale


@dataclass
class Lighting:
    """What the spheres are lit by: the lat-long ``image`` (h, 2h, 3) the ground truth integrates, and what the split
    sum reads (the prefiltered and irradiance cubes as the GPU samples them, the curve, the DFG table)."""

    image: np.ndarray
    specular: render.CubeSampler
    curve: MipCurve
    irradiance: render.CubeSampler
    dfg: object  # lutbake.table.Table, layout scale_bias


def reduce(image: np.ndarray, height: int = MAX_HEIGHT) -> np.ndarray:
    """The source's box-pyramid level with at most ``height`` rows (the source itself when it has no more)."""
    from ..environment import latlong

    pyr = latlong.pyramid(image)
    level = next((k for k in range(pyr.levels) if pyr.heights[k] <= height), pyr.levels - 1)
    return pyr.level(level)


@functools.lru_cache(maxsize=4)
def bake_dfg(preset: str = DFG_PRESET, workers: int | None = None):
    """The DFG table of ``preset`` (its first dfg table), baked with lutbake's pipeline, once per process (its data
    read-only); ValueError unless its layout is scale_bias (E = f0 scale + bias)."""
    from ..config import load_configs, preset_path
    from ..pipeline import bake_table

    spec = next(s for s in load_configs([preset_path(preset)]) if s.kind == "dfg")
    table = bake_table(spec, workers)[0]
    if list(table.channels)[:2] != ["scale", "bias"]:
        raise ValueError(f"preset {preset!r}: its dfg table holds {list(table.channels)}, not (scale, bias)")
    table.data.flags.writeable = False
    return table


def lighting(
    image: np.ndarray,
    cube_size: int = CUBE_SIZE,
    irradiance_size: int = IRRADIANCE_SIZE,
    curve: str = CURVE,
    lobe: str = LOBE,
    dfg_preset: str = DFG_PRESET,
    workers: int | None = None,
    method: str = "auto",
) -> Lighting:
    """Bake the split sum's inputs from ``image``: the specular cube (``cube_size``^2, the full mip chain, r per mip
    by ``curve``, ``lobe``) and the irradiance cube (prefilter.bake_cube's ``method``), and the DFG table of
    ``dfg_preset``."""
    from ..environment import latlong, prefilter

    image = np.asarray(image, np.float64)
    pyr = latlong.pyramid(image)
    mips = cube_size.bit_length()
    mip_curve = CURVES[curve]
    rough = [mip_curve.roughness(m, mips) for m in range(mips)]
    specular = prefilter.bake_cube(pyr, cube_size, rough, lobe, workers=workers, estimate=False, method=method)
    diffuse = prefilter.bake_cube(pyr, irradiance_size, [1.0], "cosine", workers=workers, estimate=False, method=method)
    return Lighting(
        image,
        render.CubeSampler(specular.mips),
        mip_curve,
        render.CubeSampler(diffuse.mips),
        bake_dfg(dfg_preset, workers),
    )


def lighting_of(image: np.ndarray, specular, irradiance, dfg_preset: str = DFG_PRESET, workers=None) -> Lighting:
    """The Lighting of cubes baked already (lutbake.table.CubeTable, e.g. lutbake.commands.preview_cube.read_cube_file
    of a bevy-ibl output): each looked up in its record's orientation, the specular cube at its record's curve. They
    must have been baked from ``image`` (the ground truth's environment) for the difference to be the split sum's."""
    from .preview_cube import orientation_of

    name = str(specular.record.get("mip_curve", CURVE)).split(":", 1)[0]
    if name not in CURVES:
        raise ValueError(f"the specular cube's record names the curve {name!r}; lutbake knows {sorted(CURVES)}")
    return Lighting(
        np.asarray(image, np.float64),
        render.CubeSampler(specular.mips, orientation_of(specular.record)),
        CURVES[name],
        render.CubeSampler(irradiance.mips, orientation_of(irradiance.record)),
        bake_dfg(dfg_preset, workers),
    )


def dfg_of(table):
    """(nov, r) -> (scale, bias) of a scale_bias DFG table, bilinear through its axes (lutbake.commands.preview's
    lookup: what a GPU's filtered fetch returns)."""
    names = [a.name for a in table.axes]
    rough = "perceptual_roughness" if "perceptual_roughness" in names else "alpha"

    def dfg(nov, r):
        t = lookup(table.data, table.axes, {"NoV": nov, rough: r if rough == "perceptual_roughness" else r * r})
        return t[..., 0], t[..., 1]

    return dfg


def default_view(image: np.ndarray) -> np.ndarray:
    """The direction toward the camera: VIEW_TURN past the azimuth of the brightest texel (luminance), VIEW_ELEVATION
    above the horizon, so the brightest light is reflected off the sphere's centre."""
    from ..environment import latlong

    h, w = image.shape[:2]
    i, j = np.unravel_index(np.argmax(np.asarray(image) @ render.LUMINANCE), (h, w))
    phi = (latlong.column_edges(w)[j] + latlong.column_edges(w)[j + 1]) / 2
    return render.camera_direction(phi + VIEW_TURN, VIEW_ELEVATION)


def share(x: float) -> str:
    """A relative error as text: a percentage below 10, a factor from there (the sun's pixels reach thousands)."""
    return f"{x:+.1%}" if abs(x) < 10 else f"{x:+.0f}x"


def _relative(values: np.ndarray, reference: np.ndarray) -> tuple[float, float, float]:
    """(max |values|, RMS, mean) over pixels and channels, / the mean luminance of ``reference`` (N, 3)."""
    scale = float(np.mean(reference @ render.LUMINANCE))
    scale = scale if scale > 0 else 1.0
    return tuple(float(x) / scale for x in (np.max(np.abs(values)), np.sqrt(np.mean(values**2)), np.mean(values)))


@dataclass
class SphereRenders:
    """The spheres of every material (first axis) and roughness (second): ``truth`` and ``split`` (M, R, N, 3) at
    the view's inside pixels, ``truth_error`` (M, R): the ground truth's max |truth - refined| over the probe
    pixels, / the sphere's mean truth luminance."""

    view: render.SphereView
    roughness: tuple[float, ...]
    materials: tuple[Material, ...]
    truth: np.ndarray
    split: np.ndarray
    truth_error: np.ndarray

    def errors(self) -> np.ndarray:
        """(M, R, 3): max |split - truth|, its RMS and the mean of split - truth per sphere, / its mean truth
        luminance."""
        return np.array(
            [
                [_relative(self.split[m, k] - self.truth[m, k], self.truth[m, k]) for k in range(len(self.roughness))]
                for m in range(len(self.materials))
            ]
        )


def _probes(view: render.SphereView, stride: int) -> np.ndarray:
    return np.arange(0, len(view.n), max(1, stride))


def render_spheres(
    light: Lighting,
    size: int = 64,
    roughness=ROUGHNESS,
    materials=MATERIALS,
    toward_camera=None,
    quality: Quality = Quality(),
    probe_stride: int = PROBE_STRIDE,
    device: str = "cpu",
) -> SphereRenders:
    """The spheres under ``light`` (module docstring), ``size``^2 pixels each, seen from ``toward_camera``
    (default_view when None)."""
    from ..environment import ground_truth

    view = render.sphere_view(size, default_view(light.image) if toward_camera is None else toward_camera)
    env = ground_truth.Environment(light.image)
    probes = _probes(view, probe_stride)
    n, v = view.n, view.v
    lambert = ground_truth.diffuse(env, n, v, "lambert", quality=quality, device=device)
    lambert_fine = ground_truth.diffuse(env, n[probes], v[probes], "lambert", quality=quality.refined(), device=device)
    irradiance = light.irradiance.sample(n, 0.0)
    dfg = dfg_of(light.dfg)
    shape = (len(materials), len(roughness), len(n), 3)
    truth, split, error = np.zeros(shape), np.zeros(shape), np.zeros(shape[:2])
    for k, r in enumerate(roughness):
        a, b = ground_truth.specular(env, n, v, r * r, quality, device)
        fine_a, fine_b = ground_truth.specular(env, n[probes], v[probes], r * r, quality.refined(), device)
        for m, mat in enumerate(materials):
            f0, rho = np.asarray(mat.f0), np.asarray(mat.albedo)
            truth[m, k] = f0 * a + b + rho * lambert
            fine = f0 * fine_a + fine_b + rho * lambert_fine
            error[m, k] = _relative(truth[m, k][probes] - fine, truth[m, k])[0]
            split[m, k] = render.split_sum_specular(light.specular, light.curve, dfg, n, v, r, f0) + rho * irradiance
    return SphereRenders(view, tuple(roughness), tuple(materials), truth, split, error)


@dataclass
class DiffuseRenders:
    """Per diffuse model (``models``: (name, sigma)): ``truth`` and ``approx`` (K, N, 3) at the view's inside
    pixels, ``truth_error`` (K,) as SphereRenders'."""

    view: render.SphereView
    models: tuple[tuple[str, float], ...]
    truth: np.ndarray
    approx: np.ndarray
    truth_error: np.ndarray

    def errors(self) -> np.ndarray:
        """(K, 3): max |approx - truth|, its RMS and mean per sphere, / its mean truth luminance."""
        return np.array([_relative(a - t, t) for a, t in zip(self.approx, self.truth)])


def diffuse_albedo(model: str, workers: int | None = None):
    """(nov, sigma) -> E_d of lutbake's ``diffuse`` table of ``model`` (DIFFUSE_TABLE_SIZE, f0 = 0), bilinear."""
    from ..config import validate_table
    from ..pipeline import bake_table

    raw = {"name": f"spheres_{model}", "kind": "diffuse", "model": model, "size": DIFFUSE_TABLE_SIZE}
    table = bake_table(validate_table(raw, "<lutbake spheres>", 0), workers)[0]
    return lambda nov, sigma: lookup(table.data, table.axes, {"NoV": nov, "sigma": sigma})[..., 0]


def render_diffuse(
    light: Lighting,
    size: int = 48,
    models=DIFFUSE_MODELS,
    toward_camera=None,
    quality: Quality = Quality(),
    probe_stride: int = PROBE_STRIDE,
    workers: int | None = None,
    device: str = "cpu",
) -> DiffuseRenders:
    """Each diffuse model's sphere, ground truth and irradiance x its table's E_d (module docstring)."""
    from ..environment import ground_truth

    view = render.sphere_view(size, default_view(light.image) if toward_camera is None else toward_camera)
    env = ground_truth.Environment(light.image)
    probes = _probes(view, probe_stride)
    n, v = view.n, view.v
    nov = np.clip(np.sum(n * v, axis=-1), 0.0, 1.0)
    irradiance = light.irradiance.sample(n, 0.0)
    truth, approx, error = [], [], []
    for model, sigma in models:
        t = ground_truth.diffuse(env, n, v, model, sigma, quality=quality, device=device)
        fine = ground_truth.diffuse(env, n[probes], v[probes], model, sigma, quality=quality.refined(), device=device)
        truth.append(t)
        error.append(_relative(t[probes] - fine, t)[0])
        approx.append(irradiance * diffuse_albedo(model, workers)(nov, np.full_like(nov, sigma))[:, None])
    return DiffuseRenders(view, tuple(models), np.array(truth), np.array(approx), np.array(error))


# ------------------------------------------------------------------------------------------------ pictures


def _row(fig, axes, view, spheres, exposure: float, label: str) -> None:
    for ax, values in zip(axes, spheres):
        ax.imshow(render.tone_map(view.image(values), exposure), interpolation="nearest")
        ax.set_xticks([])
        ax.set_yticks([])
    axes[0].set_ylabel(label, fontsize=8)


def _difference_row(fig, axes, view, diffs, titles, label: str) -> None:
    """Signed luminance differences on one colour scale, ±CLIP_PERCENTILE of |Δ| over the row (a sun's few pixels
    would leave the rest white); the colour bar says so."""
    lum = [view.image(d @ render.LUMINANCE, np.nan) for d in diffs]
    every = np.abs(np.concatenate([x[view.inside] for x in lum]))
    top = max(float(np.percentile(every, CLIP_PERCENTILE)), 1e-30)
    for ax, image, title in zip(axes, lum, titles):
        im = ax.imshow(image, cmap="RdBu_r", vmin=-top, vmax=top, interpolation="nearest")
        ax.set_title(title, fontsize=7)
        ax.set_xticks([])
        ax.set_yticks([])
    axes[0].set_ylabel(label, fontsize=8)
    bar = fig.colorbar(im, ax=list(axes), fraction=0.02, pad=0.01)
    bar.ax.tick_params(labelsize=7)
    clipped = float(every.max()) > top
    bar.set_label(f"Δ luminance{f', {CLIP_PERCENTILE:g}th pct. clip' if clipped else ''}", fontsize=6)


def spheres_figure(renders: SphereRenders, title: str = ""):
    """Per material three rows (ground truth, split sum, their difference) by roughness, as a Figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    M, R = len(renders.materials), len(renders.roughness)
    exposure = render.exposure_for(renders.truth)
    errors = renders.errors()
    with matplotlib.rc_context({"text.parse_math": False}):
        fig = plt.figure(figsize=(1.3 * R + 1.3, 1.35 * 3 * M + 1.3), dpi=100, layout="constrained")
        axes = fig.subplots(3 * M, R, squeeze=False)
        for k, r in enumerate(renders.roughness):
            axes[0, k].set_title(f"r = {r:.2g} (α = {r * r:.2g})", fontsize=8)
        for m, mat in enumerate(renders.materials):
            view = renders.view
            _row(fig, axes[3 * m], view, renders.truth[m], exposure, f"{mat.name}\nground truth")
            _row(fig, axes[3 * m + 1], view, renders.split[m], exposure, f"{mat.name}\nsplit sum")
            titles = [
                f"max {share(e[0])[1:]} RMS {share(e[1])[1:]}\nmean {share(e[2])} truth ±{t:.0e}"
                for e, t in zip(errors[m], renders.truth_error[m])
            ]
            _difference_row(fig, axes[3 * m + 2], view, renders.split[m] - renders.truth[m], titles, "split - truth")
        fig.suptitle(
            (title + "\n" if title else "")
            + "gold: f0 = (1, 0.71, 0.29); dielectric: f0 = 0.04 + Lambert rho = 0.5; GGX, height-correlated Smith, "
            + "Schlick\n"
            + render.DISPLAY.format(k=exposure)
            + "; differences in luminance; % of the sphere's mean",
            fontsize=8,
        )
    return fig


def diffuse_figure(renders: DiffuseRenders, title: str = ""):
    """Per diffuse model a column: ground truth, irradiance x E_d, their difference."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    K = len(renders.models)
    exposure = render.exposure_for(renders.truth)
    errors = renders.errors()
    with matplotlib.rc_context({"text.parse_math": False}):
        fig = plt.figure(figsize=(1.6 * K + 1.2, 5.8), dpi=100, layout="constrained")
        axes = fig.subplots(3, K, squeeze=False)
        view = renders.view
        _row(fig, axes[0], view, renders.truth, exposure, "ground truth")
        _row(fig, axes[1], view, renders.approx, exposure, "irradiance × E_d")
        for k, (model, sigma) in enumerate(renders.models):
            axes[0, k].set_title(f"{model}" + (f"\nσ = {sigma:g}" if model != "lambert" else ""), fontsize=8)
        titles = [
            f"max {e[0]:.1%} RMS {e[1]:.1%}\nmean {e[2]:+.1%} truth ±{t:.0e}"
            for e, t in zip(errors, renders.truth_error)
        ]
        _difference_row(fig, axes[2], view, renders.approx - renders.truth, titles, "approx - truth")
        fig.suptitle(
            (title + "\n" if title else "")
            + "diffuse, rho = 1, f0 = 0: E_d from lutbake's diffuse table of each model\n"
            + render.DISPLAY.format(k=exposure),
            fontsize=8,
        )
    return fig


def arrays(renders: SphereRenders, diffuse: DiffuseRenders | None = None) -> dict[str, np.ndarray]:
    """The float arrays behind the pictures: images (…, size, size, 3) float64 (0 outside the sphere), the inside
    mask, the roughness, materials' f0 and albedo, the errors (module docstring)."""
    view = renders.view
    out = {
        "inside": view.inside,
        "roughness": np.array(renders.roughness),
        "f0": np.array([m.f0 for m in renders.materials]),
        "albedo": np.array([m.albedo for m in renders.materials]),
        "truth": np.array([[view.image(s) for s in per] for per in renders.truth]),
        "split_sum": np.array([[view.image(s) for s in per] for per in renders.split]),
        "split_sum_error_max_rms_mean": renders.errors(),
        "truth_error": renders.truth_error,
    }
    if diffuse is not None:
        out["diffuse_models"] = np.array([f"{m}:{s:g}" for m, s in diffuse.models])
        out["diffuse_truth"] = np.array([diffuse.view.image(s) for s in diffuse.truth])
        out["diffuse_approx"] = np.array([diffuse.view.image(s) for s in diffuse.approx])
        out["diffuse_error_max_rms_mean"] = diffuse.errors()
        out["diffuse_truth_error"] = diffuse.truth_error
    return out


def write(renders: SphereRenders, out, diffuse: DiffuseRenders | None = None, title: str = "", dpi: int = 100):
    """Write ``out`` (the spheres' PNG), ``<stem>_diffuse.png`` (with ``diffuse``) and ``<stem>.npz`` (``arrays``);
    returns their paths."""
    from ..io.atomic import atomic_write
    from .figure_file import save_figure

    out = Path(out)
    paths = [save_figure(spheres_figure(renders, title), out, dpi)]
    if diffuse is not None:
        paths.append(save_figure(diffuse_figure(diffuse, title), out.with_name(out.stem + "_diffuse.png"), dpi))
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays(renders, diffuse))
    paths.append(atomic_write(out.with_suffix(".npz"), lambda tmp: tmp.write_bytes(buffer.getvalue())))
    return paths


def table_lines(renders: SphereRenders) -> list[str]:
    """The split sum's error per material and roughness, one line each (what the CLI prints)."""
    errors = renders.errors()
    lines = [f"{'material':<12}{'r':>6}{'max':>10}{'RMS':>9}{'mean':>9}{'truth ±':>10}"]
    for m, mat in enumerate(renders.materials):
        for k, r in enumerate(renders.roughness):
            e, t = errors[m, k], renders.truth_error[m, k]
            lines.append(f"{mat.name:<12}{r:>6.2f}{share(e[0])[1:]:>10}{share(e[1])[1:]:>9}{share(e[2]):>9}{t:>10.1e}")
    return lines
