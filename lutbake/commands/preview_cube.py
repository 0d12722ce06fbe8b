"""``lutbake preview`` of an environment table's cube map (kinds environment_specular, environment_irradiance): one
PNG of every mip's six faces as a horizontal cross, tone mapped for display (lutbake.environment.render.tone_map:
exposure k = 1 / the mean luminance of mip 0, Reinhard, sRGB; the title states k); for an irradiance cube also its
L2 SH (the record's ``sh`` in its ``sh_form``) as E / pi on a sphere beside the cube's own E / pi on the same
sphere, and their difference.

**The cross** (``cross_image``): faces as stored (row 0 at the top, column s to the right), +Y above +Z, -X +Z +X -Z
across, -Y below: in OpenGL's face table (lutbake.environment.cube) every shared edge meets its neighbour's, the
usual picture of a GL cube map (the environment seen from inside, mirrored).

From Python: ``cube_figure(table)`` of a lutbake.table.CubeTable (what ``bake_table`` returns for an environment
kind), ``render_cube(table_or_path, out)``. From a file: ``read_cube_file`` (any cube lutbake.io.cube_read reads:
lutbake's KTX 2.0, DDS, EXR and an engine's KTX 2.0, KTX 1.1 or DDS, RGB9E5, B10G11R11 or 8-bit included).
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from ..environment import render
from ..table import CubeTable
from ..textsafe import shorten

# (face, row, column) in the 3 x 4 cross
CROSS = ((2, 0, 1), (1, 1, 0), (4, 1, 1), (0, 1, 2), (5, 1, 3), (3, 2, 1))
BACKGROUND = 0.12  # display value around the cross
COLUMNS = 3  # crosses per row of the figure
SPHERE_SIZE = 128
VIEW = (0.0, 0.0, 1.0)  # the irradiance spheres are seen from +Z, y up


def cross_image(faces: np.ndarray, background: float = 0.0) -> np.ndarray:
    """(3n, 4n, C): the six faces (6, n, n, C) of one mip as a horizontal cross (module docstring)."""
    n = faces.shape[1]
    out = np.full((3 * n, 4 * n) + faces.shape[3:], background, dtype=np.float64)
    for face, row, col in CROSS:
        out[row * n : (row + 1) * n, col * n : (col + 1) * n] = faces[face]
    return out


def orientation_of(record: dict) -> str:
    """The orientation a cube's record names (``face_convention`` starts with it), ``gl`` when absent."""
    from ..environment.cube import ORIENTATIONS

    name = str(record.get("face_convention", "gl")).split(":", 1)[0]
    return name if name in ORIENTATIONS else "gl"


def _mip_title(record: dict, m: int, n: int) -> str:
    rough = record.get("roughness")
    where = f", r = {rough[m]:.3g} (α = {rough[m] ** 2:.3g})" if isinstance(rough, list) and m < len(rough) else ""
    return f"mip {m}: {n}² texels{where}"


def _irradiance_spheres(fig, axes, table: CubeTable, exposure: float) -> None:
    """E / pi of the cube and of its SH on one sphere (seen from VIEW), and their difference, on three axes."""
    record = table.record
    view = render.sphere_view(SPHERE_SIZE, np.array(VIEW))
    cube = render.CubeSampler(table.mips, orientation_of(record)).sample(view.n, 0.0)
    shown = [(cube, "the cube's E/π, bilinear at n")]
    coefficients = record.get("sh")
    if coefficients is None:
        axes[1].set_title("no SH in the record", fontsize=8)
    else:
        form = str(record.get("sh_form", "radiance"))
        harmonic = render.sh_irradiance_over_pi(np.asarray(coefficients, np.float64), form, view.n)
        shown.append((harmonic, f"its L2 SH's E/π (form {form})"))
    for ax, (values, title) in zip(axes, shown):
        ax.imshow(render.tone_map(view.image(values, 0.0), exposure))
        ax.set_title(title, fontsize=8)
    if len(shown) == 2:
        diff = view.image((shown[1][0] - cube) @ render.LUMINANCE, np.nan)
        scale = float(np.mean(cube @ render.LUMINANCE))
        top = max(float(np.nanmax(np.abs(diff))), 1e-30)
        im = axes[2].imshow(diff, cmap="RdBu_r", vmin=-top, vmax=top)
        axes[2].set_title(f"SH - cube (luminance), max |Δ| = {top / scale:.2%}\nof the mean E/π", fontsize=8)
        fig.colorbar(im, ax=axes[2], fraction=0.046, pad=0.04).ax.tick_params(labelsize=7)
    for ax in axes:
        ax.axis("off")


def cube_figure(table: CubeTable, title: str | None = None):
    """The preview of a cube table as a matplotlib Figure (Agg; close it when done)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mips = [np.asarray(m, np.float64)[..., :3] for m in table.mips]
    exposure = render.exposure_for(mips[0])
    irradiance = table.kind == "environment_irradiance" or "sh" in table.record
    cols = min(COLUMNS, len(mips)) + (3 if irradiance else 0)
    rows = -(-len(mips) // COLUMNS)
    with matplotlib.rc_context({"text.parse_math": False}):
        fig = plt.figure(figsize=(3.2 * cols, 2.6 * rows + 1.2), dpi=100, layout="constrained")
        for m, faces in enumerate(mips):
            ax = fig.add_subplot(rows, cols, (m // COLUMNS) * cols + m % COLUMNS + 1)
            ax.imshow(cross_image(render.tone_map(faces, exposure), BACKGROUND), interpolation="nearest")
            ax.set_title(_mip_title(table.record, m, faces.shape[1]), fontsize=8)
            ax.axis("off")
        if irradiance:
            axes = [fig.add_subplot(rows, cols, cols - 2 + k) for k in range(3)]
            _irradiance_spheres(fig, axes, table, exposure)
        head = title or f"{table.kind or 'cube map'} '{table.name}'"
        if "stored" in table.record:  # a file lutbake did not write
            head += f" (no lutbake record; {table.record['stored']})"
        lines = [
            head,
            render.DISPLAY.format(k=exposure),
            "faces as stored (row 0 at the top): +Y above +Z; -X +Z +X -Z across; -Y below",
            f"face convention: {table.record.get('face_convention', 'the GL face table (the file records none)')}",
        ]
        if irradiance:
            lines.append(f"spheres seen from +Z (y up), orthographic, {SPHERE_SIZE}² pixels")
        width = int(3.2 * cols * 13)
        fig.suptitle("\n".join(textwrap.fill(line, width) for line in lines), fontsize=9)
    return fig


# ----------------------------------------------------------------------------------------------- files


def read_cube_file(path) -> CubeTable:
    """The CubeTable of a cube file (lutbake.io.cube_read.read_cube: KTX 2.0, KTX 1.1, DDS, lutbake's EXR cube;
    lutbake's or an engine's): its mips (float64 linear RGB) and lutbake's record ({} for an engine's file, whose
    container and pixel format go into the record's ``stored`` instead). ValueError says what is wrong."""
    from ..io.cube_read import read_cube

    cube = read_cube(path)
    record = dict(cube.record) if cube.record else {"stored": f"{cube.container}, {cube.pixel_format}, {cube.transfer}"}
    name = str(record.get("table", Path(path).stem))
    return CubeTable(name, str(record.get("kind", "")), cube.mips, record, str(record.get("reconstruction", "")))


def render_cube(source, out, dpi: int = 100, force: bool = False) -> Path:
    """Write the preview PNG of a cube: ``source`` a CubeTable (``out`` required) or a cube file's path (``out``
    None: <stem>.preview.png beside it). ``out`` is checked before anything is read
    (lutbake.preflight.check_image_output)."""
    from ..errors import LutbakeError
    from ..preflight import check_image_output, input_files
    from .figure_file import save_figure

    if isinstance(source, CubeTable):
        if out is None:
            raise ValueError("render_cube of a CubeTable needs out (the PNG's path)")
        out = Path(out)
        check_image_output(out, (), force, "--out")
        return save_figure(cube_figure(source), out, dpi)
    path = Path(source)
    out = Path(out) if out else path.with_name(path.stem + ".preview.png")
    check_image_output(out, input_files(path), force, "--out")
    try:
        table = read_cube_file(path)
    except ValueError as e:  # read_cube names the file
        raise LutbakeError(str(e)) from None
    return save_figure(cube_figure(table, f"{shorten(path.name)}: {table.kind or 'cube map'} '{table.name}'"), out, dpi)
