"""Kinds ``environment_specular`` and ``environment_irradiance``: the split sum's other half as config tables. Each
bakes a lat-long environment (key ``environment``, a path relative to the config) into a cube map with lutbake's
record (lutbake.io.cubemap): the prefiltered specular cube, one perceptual roughness r per mip by the engine's curve
(lutbake.environment.curves), alpha = r^2; or the irradiance cube E / pi and its L2 SH (``<name>_sh.json``). The
computation is lutbake.environment.prefilter.bake_cube and lutbake.environment.sh (docs/environment.md).

They are baked whole (``Kind.bake``: the output is a lutbake.table.CubeTable, no (z,) y, x, C table). The environment
file is read and checked where the config is (missing, unreadable, not a 2:1 EXR/HDR, a NaN or an infinity:
ConfigError before any work), and its sha256, with the sources of the prefilter (lutbake.sources.ENVIRONMENT_SOURCES),
enters the table's content hash (``inputs``): editing the file rebakes the table, leaving it skips it.
"""

from __future__ import annotations

import threading
from dataclasses import replace
from pathlib import Path

from ..environment import cube, curves
from ..io.environment import CubeEnvironment, read_environment
from ..io.integrity import sha256_file
from ..registry import Lazy, Record, choices, family
from ..sources import ENVIRONMENT_SOURCES, sources_digest
from ..table import CubeTable
from .base import Estimation, Key, Kind, common_keys

MIP_CURVE = family("mip_curve", "the engines' roughness <-> mip curves of a prefiltered specular cube")
ENVIRONMENT_LOBE = family("environment_lobe", "the weight a prefiltered specular cube integrates the source against")
for _curve in curves.CURVES.values():
    MIP_CURVE.add(
        Record(
            "mip_curve",
            _curve.name,
            f"{_curve.lod}, r = perceptual roughness, M = mip count",
            _curve.source,
            fields={"obj": Lazy("lutbake.environment.curves:CURVES", _curve.name)},
        )
    )
for _name, _desc, _cite in (
    (
        "ggx_nl",
        "w = D_ggx(h) (n.l) / 4, n = v = r: the n.l-weighted prefilter",
        "Karis 2013, the split sum's first sum",
    ),
    (
        "ggx",
        "w = D_ggx(h) / 4 over r.l > 0: the unweighted prefilter",
        "glTF-IBL-Sampler with its n.l weighting off",
    ),
    (
        "charlie",
        "w = D_charlie(h) (n.l) / 4, n = v = r, alpha = r: the sheen prefilter",
        "Estevez & Kulla 2017, Eq. 2; glTF-IBL-Sampler's Charlie distribution (KHR_materials_sheen)",
    ),
):
    ENVIRONMENT_LOBE.add(
        Record("environment_lobe", _name, _desc, _cite, fields={"obj": Lazy("lutbake.environment.lobes:LOBES", _name)})
    )

FORMATS = {
    "ktx2": "KTX 2.0 cube, every mip (RGBA16F / RGBA32F, A = 1), the record in key lutbake:metadata + .json sidecar",
    "dds": "DDS cube (DX10 header, TEXTURECUBE), every mip (RGBA16F / RGBA32F) + .json sidecar with the record",
    "exr": "OpenEXR, one part per mip (mip_<m>: the six faces stacked top to bottom), the record in every part",
}
DTYPES = {
    "half": "16-bit float (RGBA16F, A = 1)",
    "float32": "32-bit float (RGBA32F, A = 1)",
    "rgb9e5": "RGB9E5: three 9-bit mantissas and a shared 5-bit exponent, 32 bits a texel (VK_FORMAT_E5B9G9R9_UFLOAT_"
    "PACK32, DXGI R9G9B9E5_SHAREDEXP; EXT_texture_shared_exponent's exact rounding; max 65408); ktx2 and dds only",
    "b10g11r11": "unsigned 11-, 11- and 10-bit floats, 32 bits a texel (VK_FORMAT_B10G11R11_UFLOAT_PACK32, DXGI "
    "R11G11B10_FLOAT; rounded to nearest, ties to even; max 65024 / 64512); ktx2 and dds only",
}
PACKED_FORMATS = ("ktx2", "dds")  # the formats that hold rgb9e5 and b10g11r11
# environment_specular's own format and dtype: Filament's KTX 1 (its irradiance is the SH in the file)
KTX1_FORMAT = (
    "KTX 1.1 cube as Filament's cmgen writes it (<name>.ktx: R11F_G11F_B10F / RGB16F / RGB32F, level 0 first), the "
    "environment's L2 SH (form filament) in its key sh: the one file Filament's Engine.createIblFromKtx1 loads "
    "(lutbake.io.ktx1)"
)
R11G11B10F = (
    "GL R11F_G11F_B10F (the bits of b10g11r11), rounded as cmgen rounds (a tie up: Filament math "
    "fp<0, 5, M>::fromf; max 64512); ktx1 only"
)
KTX1_DTYPES = ("r11g11b10f", "half", "float32")  # lutbake.io.ktx1.FORMATS
SH_FORMS = {
    "radiance": "L_k = ∫ L Y_k dω (three.js LightProbe / SphericalHarmonics3.getIrradianceAt)",
    "irradiance": "Â_l L_k: E(n) = Σ c_k Y_k(n) (Ramamoorthi & Hanrahan 2001, Eq. 8)",
    "irradiance_over_pi": "Â_l L_k / pi: E(n) / pi = Σ c_k Y_k(n) (a white Lambertian surface's radiance)",
}
NO_ENVIRONMENT = (
    'no environment file: set environment = "FILE" (a lat-long .exr or .hdr, width = 2 x height, relative to the '
    "config) or give one on the command line: lutbake bake {config} --environment FILE "
    "(Python: lutbake.bake(..., environment=FILE))"
)
PRESETS = Path(__file__).resolve().parent.parent / "presets"  # lutbake.config.PRESET_DIR, named here for the message
ESTIMATION = Estimation(
    {
        "auto": "each mip by spherical harmonics where its lobe allows (every GGX mip with alpha above ~0.007, the "
        "irradiance cube), the others (the footprint mip 0, narrower lobes) by the quadrature",
        "harmonic": "exact convolution by spherical harmonics (lutbake.environment.harmonic, ducc0): seconds; a mip "
        "it cannot bake is refused",
        "quadrature": "exact quadrature over the source's pyramid (lutbake.environment.quadrature): no random sample, "
        "float64 sums, bit-identical for any worker count; minutes for a 256^2 cube of a 2048 x 1024 source",
    },
    "auto",
    "",
)
MAX_MIPS = 32  # KTX 2.0's levelCount of a 2^31-texel face; the texel cap (config.MAX_TEXELS) binds long before
ROUGHNESS = {
    "ggx": "perceptual: the curve gives r per mip, alpha = r^2 (Burley 2012; glTF, Bevy, Filament)",
    "charlie": "sheen roughness: the curve gives r per mip, alpha = r (glTF-IBL-Sampler's D_Charlie(sheenRoughness))",
}
SOURCE_CONVENTION = (
    "lat-long, row 0 = +Y, u = 0.5 + atan2(z, x) / 2pi (lutbake.environment.latlong); texel-constant radiance"
)
ERROR_METHOD = (
    "max relative |P - P_finer| over <= 96 strided probe texels per mip, P_finer at tau / 8, K x 2, order + 1, one "
    "sub-texel level more (lutbake.environment.prefilter)"
)


ENVIRONMENT_KEY = Key(
    "environment",
    "str",
    None,
    "the environment: a lat-long .exr or .hdr file (width = 2 x height, row 0 = +Y) or a cube map (KTX 2.0, "
    "KTX 1.1, DDS or lutbake's EXR cube: its mip 0, texel-constant on the faces; baked by spherical harmonics, "
    "mip 0 the exact box average where one size divides the other), a path relative to this config (absolute "
    "paths too); read and checked when the config is (missing, unreadable, not an image, a NaN or an infinity: "
    "refused before any work); its sha256 enters the content hash. A preset has none: lutbake bake --preset NAME "
    "--environment FILE",
)


def _common() -> dict[str, Key]:
    """The keys both environment kinds share: name and kind (lutbake.kinds.base.common_keys; the environment kinds
    have no samples, seed or tolerance), format, dtype, estimator, environment, orientation and the quadrature's
    controls (lutbake.environment.prefilter.Quality)."""
    named = {k: v for k, v in common_keys(ESTIMATION).items() if k in ("name", "kind")}
    return {
        **named,
        "environment": ENVIRONMENT_KEY,
        "format": Key("format", "str", "ktx2", "output file format: <out-dir>/<name>.<ext>", FORMATS),
        "dtype": Key("dtype", "str", "half", "pixel type written", DTYPES),
        "estimator": Key(
            "estimator", "str", ESTIMATION.default, "how each texel's integral is computed", ESTIMATION.estimators
        ),
        "orientation": Key(
            "orientation",
            "str",
            "gl",
            "the world direction each texel's lookup vector stands for (recorded as face_convention): "
            "d3d_left_handed for a shader that looks the cube up at (x, y, -z), as Bevy's environment_map.wgsl "
            "(vec3(R.xy, -R.z)) and left-handed engines do",
            {name: o.doc for name, o in cube.ORIENTATIONS.items()},
        ),
        "tau": Key(
            "tau",
            "float",
            0.3,
            "the quadrature's radiance-fixing tolerance (relative): smaller spends more pyramid leaves per texel",
            minimum=1e-4,
            maximum=3.0,
        ),
        "k_geo": Key(
            "k_geo",
            "float",
            4.0,
            "the quadrature's cell size per distance K: a leaf's angular radius times K is at most its distance to "
            "the lobe's peak plus the lobe width",
            minimum=1.0,
            maximum=64.0,
        ),
        "order": Key(
            "order", "int", 3, "Gauss-Legendre order per pyramid leaf and axis of the weight's integral", None, 1, 8
        ),
    }


def environment_path(spec) -> Path:
    """The environment file a spec names: its ``environment`` key, relative to its config's folder."""
    return Path(spec.source).parent / spec.options["environment"]


def check_environment(spec) -> tuple[str, str] | None:
    """The storage (a packed dtype needs a format that holds it), then the environment file, read as the bake will
    (read_environment): (key, why not) or None."""
    o = spec.options
    if o.get("dtype") in ("rgb9e5", "b10g11r11") and o.get("format") not in PACKED_FORMATS:
        return "dtype", f"{o['dtype']} is written in {' and '.join(PACKED_FORMATS)} cubes only, not {o.get('format')}"
    if spec.options.get("environment") is None:
        source = Path(spec.source)
        preset = source.suffix == ".toml" and source.resolve().parent == PRESETS
        return "environment", NO_ENVIRONMENT.format(config=f"--preset {source.stem}" if preset else source)
    try:
        env = read_environment(environment_path(spec))
    except (ValueError, OSError) as e:
        return "environment", f"cannot be baked: {e}"
    if isinstance(env, CubeEnvironment):
        if o.get("estimator") == "quadrature":
            return "estimator", "a cube map environment is baked by spherical harmonics (auto or harmonic)"
        n, size = env.faces.shape[1], int(o.get("size", 1))
        if spec.kind == "environment_specular" and n % size and size % n:
            return "size", (
                f"mip 0 from a {n}^2 cube environment is its exact box average: size must divide {n} or be a "
                f"multiple of it, got {size}"
            )
    return None


def environment_inputs(spec) -> bytes:
    """What an environment table's values depend on besides its config and lutbake's sources (Kind.inputs): the
    environment file's sha256 (read now) and the prefilter's sources (ENVIRONMENT_SOURCES)."""
    try:
        digest = sha256_file(environment_path(spec))
    except OSError as e:  # removed since the config was read: a hash that matches no file; the bake says why
        digest = f"unreadable: {e}"
    return inputs_of(digest)


def inputs_of(sha256: str) -> bytes:
    """The inputs of a table baked from an environment whose bytes have ``sha256`` (CubeTable.inputs)."""
    return b"\0".join((b"environment", sha256.encode(), sources_digest(ENVIRONMENT_SOURCES)))


def mip_count(options) -> int:
    """The mips of a specular cube: ``mips``, or the full chain floor(log2 size) + 1 (the last mip 1 x 1)."""
    full = int(options["size"]).bit_length()
    return full if options.get("mips") is None else int(options["mips"])


def cube_texels(size: int, mips: int) -> int:
    """6 sum_m max(1, size >> m)^2."""
    return 6 * sum(max(1, size >> m) ** 2 for m in range(mips))


def specular_texels(options) -> int:
    """6 x size^2 over every mip"""
    return cube_texels(int(options["size"]), mip_count(options))


def irradiance_texels(options) -> int:
    """6 x size^2"""
    return cube_texels(int(options["size"]), 1)


def check_specular(spec):
    """``mips`` within the chain ``size`` has, the storage (check_ktx1), then the environment file."""
    o = spec.options
    full = int(o["size"]).bit_length()
    if o.get("mips") is not None and o["mips"] > full:
        return "mips", f"a {o['size']}^2 cube has at most {full} mips (the last 1 x 1): floor(log2 size) + 1"
    return check_ktx1(spec) or check_environment(spec)


def check_ktx1(spec) -> tuple[str, str] | None:
    """Filament's KTX 1 (format ktx1) holds the cube in one of KTX1_DTYPES, and r11g11b10f is written in it only; a
    half face of odd size (a 1 x 1 is 6 bytes) needs KTX padding Filament's Ktx1Bundle does not read
    (lutbake.io.ktx1)."""
    o = spec.options
    fmt, dtype = o.get("format"), o.get("dtype")
    if fmt == "ktx1" and dtype not in KTX1_DTYPES:
        return "dtype", f"format ktx1 takes dtype {', '.join(KTX1_DTYPES)}, not {dtype!r}"
    if dtype == "r11g11b10f" and fmt != "ktx1":
        return "dtype", f"r11g11b10f (cmgen's R11F_G11F_B10F) is written in format ktx1 only, not {fmt}"
    odd = [n for n in (max(1, int(o["size"]) >> m) for m in range(mip_count(o))) if n % 2] if fmt == "ktx1" else []
    if dtype == "half" and odd:
        return "mips", (
            f"a ktx1 half face of {odd[0]} x {odd[0]} ({6 * odd[0] ** 2} bytes, not a multiple of 4) needs KTX "
            "padding Filament's Ktx1Bundle does not read: a size and mips whose every mip is even (the last 2 x 2 "
            "or larger), or dtype r11g11b10f / float32"
        )
    return None


def quality(o):
    from ..environment.prefilter import Quality

    return Quality(o["tau"], o["k_geo"], o["order"])


def read_source(spec):
    """(the environment as read, its pyramid): the source turned by the spec's orientation. A lookup vector d
    stands for the world direction d x flip (cube.ORIENTATIONS); flipping z is phi -> -phi, the columns reversed
    (u -> 1 - u, exact for texel-constant radiance), so the cube is baked from the mirrored image. A cube map
    environment has no pyramid (None): lutbake.environment.cube_source turns it."""
    from ..environment import latlong

    env = read_environment(environment_path(spec))
    if isinstance(env, CubeEnvironment):
        return env, None
    flip = cube.ORIENTATIONS[spec.options["orientation"]].flip
    if flip != (1.0, 1.0, -1.0) and flip != (1.0, 1.0, 1.0):
        raise ValueError(f"orientation {spec.options['orientation']!r}: only a z flip is baked")
    key = (env.sha256, flip[2] < 0)
    with _PYRAMID_LOCK:
        pyr = _PYRAMID.get(key)
    if pyr is None:  # a preset's specular and irradiance tables of one source share one pyramid
        pyr = latlong.pyramid(env.image[:, ::-1] if flip[2] < 0 else env.image)
        with _PYRAMID_LOCK:
            _PYRAMID.clear()
            _PYRAMID[key] = pyr
    return env, pyr


_PYRAMID: dict = {}  # the last source's pyramid, by (sha256, mirrored): it is read-only
_PYRAMID_LOCK = threading.Lock()


def base_record(spec, env, baked) -> dict:
    """The record every environment file carries (lutbake.io.cubemap): the conventions, the source, the lobes and
    the per-mip error estimate of ``baked`` (lutbake.environment.prefilter.Baked)."""
    o = spec.options
    orientation = cube.ORIENTATIONS[o["orientation"]]
    source_convention, error_method = SOURCE_CONVENTION, ERROR_METHOD
    if isinstance(env, CubeEnvironment):
        from ..environment.cube_source import ERROR_METHOD as error_method

        n = env.faces.shape[1]
        source_convention = (
            f"cube: mip 0 of a {n}^2 {env.container} {env.pixel_format} cube (of {env.mips} mips), faces +X -X +Y -Y "
            f"+Z -Z in the face table of lutbake.environment.cube, orientation {env.orientation}; texel-constant "
            "radiance over each texel's footprint (lutbake.environment.cube_source)"
        )
    return {
        "face_convention": f"{orientation.name}: faces +X -X +Y -Y +Z -Z in the OpenGL / KTX / Vulkan face table "
        "(lutbake.environment.cube)",
        "orientation": orientation.doc,
        "source": Path(o["environment"]).name,
        "source_sha256": env.sha256,
        "source_negative_values_zeroed": env.negatives,
        "source_convention": source_convention,
        "split_sum": "n = v = r",
        "lobes": baked.lobes,
        "method_per_mip": baked.methods,
        "harmonic_lmax": baked.lmax,
        "error_estimate_per_mip": baked.errors,
        "error_estimate_method": error_method,
        "quality": {"tau": o["tau"], "k_geo": o["k_geo"], "order": o["order"]},
    }


def bake_specular(spec, workers: int | None = None, device: str = "cpu") -> CubeTable:
    """The prefiltered specular cube of ``spec`` (nothing written): mip m at the curve's r_m, alpha = r_m^2; mip 0
    (r = 0) the exact area average over each texel's footprint."""

    o = spec.options
    curve, lobe = spec.records["curve"], spec.records["lobe"]
    ndf = "charlie" if lobe.name == "charlie" else "ggx"
    env, pyr = read_source(spec)
    mips = mip_count(o)
    roughness = [curve.obj.roughness(m, mips) for m in range(mips)]
    baked = bake_lobe(spec, env, pyr, roughness, lobe.name, workers, device)
    record = base_record(spec, env, baked) | {
        "ndf": ndf,
        "roughness_definition": ROUGHNESS[ndf],
        "weighting": f"{lobe.name}: {lobe.description} ({lobe.citation})",
        "mip_curve": f"{curve.name}: {curve.obj.lod} ({curve.obj.source})",
        "roughness": baked.roughness,
        "alpha": baked.alphas,
        "mip0": "the exact area average of the source over each texel's footprint"
        if baked.lobes[0] == "footprint"
        else baked.lobes[0],
    }
    if o["format"] == "ktx1":
        record |= filament_sh(env)
    return CubeTable(spec.name, spec.kind, baked.mips, record, specular_reconstruction(spec), inputs_of(env.sha256))


def filament_sh(env) -> dict:
    """What a ktx1 cube records of the environment's L2 SH (lutbake.environment.sh form ``filament`` of source_sh, the
    world's directions: the orientation turns the cube only), also written as the file's key ``sh``
    (lutbake.io.ktx1)."""
    from ..environment import sh

    return {
        "sh_form": "filament",
        "sh_form_meaning": sh.FORMS["filament"],
        "sh_key": "sh: the KTX 1 key, 9 lines 'r g b' (float32), what IndirectLight.Builder.irradiance(3, sh) takes",
        "sh": sh.convolve(source_sh(env), "filament").tolist(),
    }


def bake_irradiance(spec, workers: int | None = None, device: str = "cpu") -> CubeTable:
    """The irradiance cube E / pi of ``spec`` and its L2 SH (nothing written); the SH of the world's directions
    (the orientation turns the cube only)."""
    from ..environment import sh

    o = spec.options
    env, pyr = read_source(spec)
    baked = bake_lobe(spec, env, pyr, [1.0], "cosine", workers, device)
    coefficients = sh.convolve(source_sh(env), o["sh_form"])
    doc = {
        "basis": "real SH, Ramamoorthi & Hanrahan 2001 / three.js order: Y00; Y1-1 y, Y10 z, Y11 x; Y2-2 xy, "
        "Y2-1 yz, Y20 3z^2-1, Y21 xz, Y22 x^2-y^2 (lutbake.environment.sh), on the y-up world direction",
        "integration": "exact per source texel (closed-form theta and phi integrals), texel-constant radiance",
        "source": Path(o["environment"]).name,
        "source_sha256": env.sha256,
        "form": o["sh_form"],
        "form_meaning": SH_FORMS[o["sh_form"]],
        "coefficients": coefficients.tolist(),
    }
    record = base_record(spec, env, baked) | {
        "weighting": "cosine: (n.l)+, P = E / pi",
        "sh_file": f"{spec.name}{SH_SUFFIX}",
        "sh_form": o["sh_form"],
        "sh": coefficients.tolist(),
    }
    return CubeTable(
        spec.name, spec.kind, baked.mips, record, irradiance_reconstruction(spec), inputs_of(env.sha256), sh=doc
    )


SH_SUFFIX = "_sh.json"


def bake_lobe(spec, env, pyr, roughness: list[float], lobe: str, workers, device: str):
    """prefilter.bake_cube of a lat-long source (its pyramid ``pyr``), or cube_source.bake_from_cube of a cube map
    environment, at the spec's size, orientation and estimator."""
    from ..environment import cube_source, prefilter

    o = spec.options
    if isinstance(env, CubeEnvironment):
        flip = cube.ORIENTATIONS[o["orientation"]].flip
        source_flip = cube.ORIENTATIONS[env.orientation].flip
        return cube_source.bake_from_cube(env.faces, o["size"], roughness, lobe, source_flip, flip, workers)
    return prefilter.bake_cube(
        pyr, o["size"], roughness, lobe, quality(o), workers, device=device, method=o["estimator"]
    )


def source_sh(env):
    """(9, 3) radiance coefficients of the world's radiance: of the lat-long image, or of a cube map environment
    turned to the world (its lookup vector d is the world direction d x flip)."""
    from ..environment import cube_source, sh

    if isinstance(env, CubeEnvironment):
        flip = cube.ORIENTATIONS[env.orientation].flip
        return cube_source.project_cube(cube_source.remap(env.faces, flip))
    return sh.project(env.image)


def specular_reconstruction(spec) -> str:
    """How a shader reads the specular cube (lutbake's own text; an engine's line is put first where the table is
    one of its records, lutbake.layouts.reconstruction_with_engine_line)."""
    curve = spec.records["curve"].obj
    text = (
        f"lod = {curve.lod.removeprefix('lod = ')} (M = {mip_count(spec.options)} mips, r = perceptual roughness); "
        "prefiltered = textureLod(cube, R, lod).rgb, R = reflect(-V, N); "
        "specular = prefiltered * (f0 * dfg.r + f90 * dfg.g) with the DFG table of the same roughness"
    )
    if spec.options["format"] == "ktx1":
        text += "; irradiance_over_pi = sh[0] + sh[1] N.y + sh[2] N.z + sh[3] N.x + ... (form filament, key sh)"
    return text


def reconstruction(spec) -> str:
    """How a shader reads the cube of ``spec`` (either environment kind), before any engine's line."""
    return specular_reconstruction(spec) if spec.kind == "environment_specular" else irradiance_reconstruction(spec)


def irradiance_reconstruction(spec) -> str:
    return (
        "irradiance_over_pi = texture(cube, N).rgb (E / pi); diffuse = albedo * irradiance_over_pi; "
        f"SH ({spec.options['sh_form']}): {spec.name}{SH_SUFFIX}"
    )


COMMON = _common()
HEAD = ("name", "kind", "environment")  # the kind's own keys follow these, then the rest of COMMON


def _keys(own: dict[str, Key]) -> dict[str, Key]:
    """HEAD, the kind's own keys, then the rest of COMMON (an own key of a common name replaces it in its place)."""
    fresh = {k: v for k, v in own.items() if k not in COMMON}
    return {**{k: COMMON[k] for k in HEAD}, **fresh, **{k: own.get(k, v) for k, v in COMMON.items() if k not in HEAD}}


SPECULAR_KEYS = _keys(
    {
        "size": Key("size", "int", 256, "face size of mip 0 (texels a side); mip m is max(1, size >> m)", minimum=1),
        "mips": Key(
            "mips",
            "int",
            None,
            "mip count (unset: the full chain, floor(log2 size) + 1, the last 1 x 1)",
            minimum=1,
            maximum=MAX_MIPS,
        ),
        "curve": Key(
            "curve",
            "str",
            "linear",
            "the engine's roughness -> mip curve: mip m holds the perceptual roughness the curve gives it",
            choices(MIP_CURVE),
        ),
        "lobe": Key(
            "lobe", "str", "ggx_nl", "the weight each texel integrates the source against", choices(ENVIRONMENT_LOBE)
        ),
        "format": replace(COMMON["format"], choices={**COMMON["format"].choices, "ktx1": KTX1_FORMAT}),
        "dtype": replace(COMMON["dtype"], choices={**COMMON["dtype"].choices, "r11g11b10f": R11G11B10F}),
    }
)
IRRADIANCE_KEYS = _keys(
    {
        "size": Key("size", "int", 32, "face size (texels a side); one mip", minimum=1),
        "sh_form": Key("sh_form", "str", "radiance", "the L2 SH coefficients written to <name>_sh.json", SH_FORMS),
    }
)


ENVIRONMENT_SPECULAR = Kind(
    "environment_specular",
    "prefiltered specular cube map with mips (GGX, one perceptual roughness per mip by the engine's curve) of a "
    "lat-long environment",
    SPECULAR_KEYS,
    None,
    check=check_specular,
    texels=specular_texels,
    texels_doc=specular_texels.__doc__,
    bake=bake_specular,
    inputs=environment_inputs,
)
ENVIRONMENT_IRRADIANCE = Kind(
    "environment_irradiance",
    "irradiance cube map (E / pi) and its L2 spherical harmonics (<name>_sh.json) of a lat-long environment",
    IRRADIANCE_KEYS,
    None,
    check=check_environment,
    texels=irradiance_texels,
    texels_doc=irradiance_texels.__doc__,
    bake=bake_irradiance,
    inputs=environment_inputs,
    outputs=((SH_SUFFIX, "L2 SH coefficients"),),
)
