"""The layouts lutbake defines itself: the split-sum pairs of Karis 2013 (``scale_bias``) and of the multiple-scattering
form (``multiscatter``), and the rough-dielectric energies (``energy``, kinds dielectric / dielectric_avg).

    scale_bias    R = ∫ f/F (1 - Fc) (n.l) dω,  G = ∫ f/F Fc (n.l) dω       E = f0 R + G
    multiscatter  R = ∫ f/F Fc (n.l) dω,        G = ∫ f/F (n.l) dω          E = mix(R, G, f0); E(F = 1) = G
    energy        R = E_R, G = E_T, B = E_R + E_T (Walter et al. 2007, exact Fresnel), over NoV x roughness x IOR
Engines that store these pairs as they are (Unreal, Bevy, three.js, the glTF viewer, Godot) declare only their grid
and storage (lutbake.layouts.unreal, ...).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .base import EngineTable, Layout

SCALE_BIAS_CHANNELS = {
    "scale": "∫ f/F (1 - (1 - v.h)^5) (n.l) dω_l: multiplies f0",
    "bias": "∫ f/F (1 - v.h)^5 (n.l) dω_l: added",
}
MULTISCATTER_CHANNELS = {
    "fc": "∫ f/F (1 - v.h)^5 (n.l) dω_l: the f90 = 1 weight",
    "e_ss": "∫ f/F (n.l) dω_l: single-scattering directional albedo with F = 1",
}
SCALE_BIAS_SHADER = "{uv}; t = texture(lut, uv).rg; specular = prefiltered * (f0 * t.r + t.g)"
KARIS = "Karis 2013, Real Shading in Unreal Engine 4, Eq. 8"
FILAMENT = "Filament, Physically Based Rendering in Filament, 5.3.4.3 (DFG1, DFG2)"
MULTISCATTER_SHADER = (
    "{uv}; t = texture(lut, uv).rg; E = mix(t.r, t.g, f0) = (1 - f0) t.r + f0 t.g (f90 = 1; an engine's f90: "
    "E = (f90 - f0) t.r + f0 t.g); specular = prefiltered * E; "
    "energy compensation = 1 + f0 (1 / t.g - 1)"
)


def split_sum(name: str, summary: str, channels: dict, shader: str, source: str) -> Layout:
    """A layout of the split-sum pair itself: its integrand is its own channel set, its R, G the pair ``name``."""
    engine = "lutbake (Karis 2013 and the multiple-scattering form; Unreal, Bevy, three.js, glTF, Filament, Godot)"
    return Layout(name, "dfg", engine, summary, channels, shader, name, source, split_sum=name)


SCALE_BIAS = split_sum(
    "scale_bias", "R = scale, G = bias: E = f0 * R + G (Karis 2013)", SCALE_BIAS_CHANNELS, SCALE_BIAS_SHADER, KARIS
)
MULTISCATTER = split_sum(
    "multiscatter",
    "R = ∫Fc·f, G = ∫f: E = mix(R, G, f0), E(F=1) = G (Filament)",
    MULTISCATTER_CHANNELS,
    MULTISCATTER_SHADER,
    FILAMENT,
)

ENERGY = Layout(
    name="energy",
    kind="dielectric",
    engine="lutbake (Turquin 2019 compensation of rough glass)",
    summary="R = E_R, G = E_T, B = E_R + E_T over NoV x roughness x IOR (exact Fresnel)",
    channels={
        "e_r": "E_R = ∫ f_r |n.o| dω_o: directional reflectance of the rough interface",
        "e_t": "E_T = ∫ f_t |n.o| dω_o: directional transmittance",
        "e_sum": "E_R + E_T: single-scattering energy kept (1 - it is lost to multiple scattering)",
    },
    shader="E = texture(lut3d, vec3(u(NoV), u(roughness), u(eta))).rgb (texel conventions per lutbake:axes); "
    "Turquin 2019 compensation of the dielectric lobe: f_ms-scaled = f * (1 + (1 - E_sum) / E_sum) = f / E_sum; "
    "glass split sum: reflected = prefiltered_R * E_R, transmitted = prefiltered_T * E_T",
    integrand="exact",
    source="Walter, Marschner, Li & Torrance 2007; Turquin 2019",
    split_sum=None,
)


def energy_avg(avg: np.ndarray) -> np.ndarray:
    """(E_R, E_T, E(F = 1)) averages -> (E_R, E_T, E_R + E_T)."""
    return np.stack([avg[:, 0], avg[:, 1], avg[:, 0] + avg[:, 1]], axis=1)


ENERGY_AVG = replace(
    ENERGY,
    kind="dielectric_avg",
    channels={"e_r_avg": "2 ∫ E_R mu dmu", "e_t_avg": "2 ∫ E_T mu dmu", "e_sum_avg": "2 ∫ (E_R + E_T) mu dmu"},
    shader="E_avg = texture(lut2d, vec2(u(roughness), u(eta))).rgb: rows = IOR, columns = roughness",
    integrand="exact_metal",
    to_stored=energy_avg,
    error_to_stored=energy_avg,
)

LAYOUTS = (SCALE_BIAS, MULTISCATTER, ENERGY, ENERGY_AVG)
TURQUIN = {"layout": "energy", "ior_size": 32, "ior_mapping": "symmetric", "ior_range": [0.4, 2.5], "format": "exr"}
TABLES = (
    EngineTable(
        "lutbake",
        "default",
        "dfg",
        "dfg",
        "scale_bias",
        {"size": [128, 128], "roughness": "perceptual", "layout": "scale_bias", "dtype": "float32"},
        "Karis 2013",
        "any engine that samples E = f0 * R + G at vec2(NoV, roughness)",
        shader="t = texture(dfg, vec2(NoV, r)).rg; specular = prefiltered * (f0 * t.r + t.g)",
    ),
    EngineTable(
        "lutbake",
        "turquin",
        "turquin_dielectric_e",
        "dielectric",
        "energy",
        {**TURQUIN, "size": [32, 32], "masking": "smith_height_correlated"},
        "Turquin 2019, Practical multiple scattering compensation for microfacet models",
        "a 3D texture (NoV, roughness, IOR) of E_R, E_T, E_R + E_T",
        shader="E = texture(lut3d, vec3(NoV, r, (iorIndex(eta) + 0.5) / 32.0)).rgb; f / E.b",
    ),
    EngineTable(
        "lutbake",
        "turquin",
        "turquin_dielectric_e_avg",
        "dielectric_avg",
        "energy",
        {**TURQUIN, "roughness_size": 32, "masking": "smith_height_correlated"},
        "Turquin 2019",
        "a 2D texture (roughness, IOR) of the averages",
    ),
    EngineTable(
        "lutbake",
        "ltc-aniso",
        "ltc_aniso",
        "ltc_aniso",
        None,
        {"parametrisation": "alphax_alphay", "size": 8, "dtype": "half", "format": "ktx2"},
        "Kt, Heitz, Dupuy & Narayanan 2022, Bringing Linearly Transformed Cosines to Anisotropic GGX",
        "docs/shaders/ltc_aniso.glsl's sampler3D t0, t1, t2: three KTX 2.0 3D textures 8 x 8 x 64, RGBA16F",
    ),
)
