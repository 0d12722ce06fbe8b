"""A cube map as the environment (lutbake.environment.cube_source, harmonic.analyse_cube): the a_lm of a texel-constant
cube against the lat-long analysis of the same function (an octant-constant radiance lies on both grids' texel edges)
and against scipy's adaptive integral for one texel; the L2 SH against the lat-long's closed form; mip 0's box average
against scipy's solid angles; the bake against the lat-long bake of the same function; orientations as exact
remaps; the environment key taking a cube file (records, refusals). Small sizes and a lowered harmonic floor
(LMAX_FLOOR, monkeypatched where a bake runs): seconds."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy import integrate
from scipy.special import sph_harm_y

import lutbake
from lutbake.environment import cube, cube_source, harmonic, latlong, prefilter, sh
from lutbake.io.cube_read import read_cube
from lutbake.io.cubemap import write_cube

RNG = np.random.default_rng(3)
OCTANT_VALUES = RNG.random((2, 2, 2, 3)) + 0.2
ALM_TOL = 1e-11  # the cube's a_lm vs the lat-long's, both exact to ~1e-13 (relative to max |a_lm|)
SCIPY_TOL = 1e-9  # one texel's a_lm vs scipy's dblquad (epsabs 1e-12)
BAKE_TOL = 1e-9  # the two bakes share the kernel and the synthesis: their a_lm differences only
SMALL_LMAX = 63  # harmonic.LMAX_FLOOR in the bakes here (the horizon kink's 1e-5 floor needs 1023: slow)
SMALL_CAP = 127  # harmonic.LMAX_CAP likewise (plan_lmax's g_l to the cap take seconds a mip at 1535)


def octant(d: np.ndarray) -> np.ndarray:
    """A radiance constant on each octant: on the texel edges of an even cube and of a lat-long with w % 4 == 0."""
    return OCTANT_VALUES[(d[..., 0] > 0).astype(int), (d[..., 1] > 0).astype(int), (d[..., 2] > 0).astype(int)]


def octant_latlong(h: int) -> np.ndarray:
    theta = (np.arange(h) + 0.5) / h * np.pi
    phi = (np.arange(2 * h) + 0.5) / (2 * h) * 2 * np.pi - np.pi
    return octant(latlong.directions(theta[:, None], phi[None, :]))


@pytest.fixture
def small_floor(monkeypatch):
    monkeypatch.setattr(harmonic, "LMAX_FLOOR", SMALL_LMAX)
    monkeypatch.setattr(harmonic, "LMAX_CAP", SMALL_CAP)


def alm_index(lmax: int, l: int, m: int) -> int:
    """ducc0's (healpy's) a_lm order: m = 0..lmax, l = m..lmax."""
    return m * (2 * lmax + 1 - m) // 2 + l


def test_the_cube_analysis_equals_the_latlong_analysis_of_the_same_function():
    lmax = 24
    faces = octant(cube.texel_centres(8))
    from_cube = harmonic.analyse_cube(faces, lmax, order=16)  # the default (8 here) leaves 2.6e-11
    from_latlong = harmonic.analyse(octant_latlong(16), lmax)
    scale = np.abs(from_latlong.alm).max()
    assert np.abs(from_cube.alm - from_latlong.alm).max() / scale < ALM_TOL


@pytest.mark.parametrize("l, m", [(0, 0), (3, 2), (7, 5), (12, 0)])
def test_one_texels_alm_is_scipys_integral_of_y_lm_over_it(l, m):
    n, lmax, face, row, col = 4, 12, 2, 1, 2  # a +Y texel off the face centre
    faces = np.zeros((6, n, n, 3))
    faces[face, row, col] = 1.0
    got = harmonic.analyse_cube(faces, lmax).alm[0, alm_index(lmax, l, m)]
    u0, v0 = -1 + 2 * col / n, -1 + 2 * row / n

    def integrand(v, u, part):
        d = cube.face_directions(np.array(face), np.array(u), np.array(v))
        d = d / np.linalg.norm(d)
        y = np.conj(sph_harm_y(l, m, math.acos(d[1]), math.atan2(d[2], d[0]) + math.pi))
        return (y.real if part == "re" else y.imag) * (1 + u * u + v * v) ** -1.5

    ref = complex(
        *(
            integrate.dblquad(integrand, u0, u0 + 2 / n, v0, v0 + 2 / n, args=(p,), epsabs=1e-12, epsrel=1e-12)[0]
            for p in ("re", "im")
        )
    )
    assert abs(got - ref) < SCIPY_TOL


def test_the_cube_sh_equals_the_latlong_closed_form():
    from_cube = cube_source.project_cube(octant(cube.texel_centres(8)))
    np.testing.assert_allclose(from_cube, sh.project(octant_latlong(16)), rtol=0, atol=1e-12)


def test_the_box_average_is_the_solid_angle_weighted_mean_scipy_integrates():
    n, k = 8, 4
    faces = np.zeros((6, n, n, 3))
    faces[4, 5, 6] = 1.0  # one fine texel of +Z
    coarse = cube_source.box_average(faces, n // k)

    def omega(u0, u1, v0, v1):
        return integrate.dblquad(lambda v, u: (1 + u * u + v * v) ** -1.5, u0, u1, v0, v1, epsabs=1e-13)[0]

    e = cube.texel_edges(n)
    fine, block = omega(e[6], e[7], e[5], e[6]), omega(e[4], e[8], e[4], e[8])
    assert coarse[4, 1, 1, 0] == pytest.approx(fine / block, rel=1e-10)
    assert np.count_nonzero(coarse) == 3  # the one block, three channels
    np.testing.assert_array_equal(cube_source.box_average(faces, 2 * n)[4, 10:12, 12:14], 1.0)  # finer: the value
    with pytest.raises(ValueError, match="divides"):
        cube_source.box_average(faces, 3)


def test_a_cube_bake_equals_the_latlong_bake_of_the_same_function(small_floor):
    faces = octant(cube.texel_centres(8)).astype(np.float32).astype(np.float64)  # the pyramid holds float32
    roughness = [0.6, 1.0]
    from_cube = cube_source.bake_from_cube(faces, 4, roughness)
    pyr = latlong.pyramid(octant_latlong(16).astype(np.float32))
    from_latlong = prefilter.bake_cube(pyr, 4, roughness, estimate=False, method="harmonic")
    assert from_cube.lmax == from_latlong.lmax and from_cube.methods == ["harmonic"] * 2
    for a, b in zip(from_cube.mips, from_latlong.mips):
        np.testing.assert_allclose(a, b, rtol=BAKE_TOL)
    irr = cube_source.bake_from_cube(faces, 2, [1.0], "cosine")
    ref = prefilter.bake_cube(pyr, 2, [1.0], "cosine", estimate=False, method="harmonic")
    np.testing.assert_allclose(irr.mips[0], ref.mips[0], rtol=BAKE_TOL)


def test_the_truncation_estimate_bounds_the_error_against_a_bake_at_twice_lmax(small_floor, monkeypatch):
    faces = octant(cube.texel_centres(8))
    baked = cube_source.bake_from_cube(faces, 4, [0.6, 1.0])
    monkeypatch.setattr(harmonic, "LMAX_FLOOR", 2 * SMALL_LMAX + 1)
    finer = cube_source.bake_from_cube(faces, 4, [0.6, 1.0], estimate=False)
    assert finer.lmax == 2 * baked.lmax + 1
    for m, (a, b) in enumerate(zip(baked.mips, finer.mips)):
        actual = float(np.max(np.abs(a - b) / b))
        assert 0 < actual <= baked.errors[m] < 1e-5, (m, actual, baked.errors[m])


def test_orientations_are_exact_remaps(small_floor):
    faces = RNG.random((6, 4, 4, 3))
    mirror = (1.0, 1.0, -1.0)
    np.testing.assert_array_equal(cube_source.remap(cube_source.remap(faces, mirror), mirror), faces)
    # +Z and -Z swap, each mirrored in s: the table's (u, -v, 1) and (-u, -v, -1)
    np.testing.assert_array_equal(cube_source.remap(faces, mirror)[4], faces[5][:, ::-1])
    plain = cube_source.bake_from_cube(faces, 4, [0.0, 1.0], estimate=False)
    turned = cube_source.bake_from_cube(faces, 4, [0.0, 1.0], flip=mirror, estimate=False)
    for a, b in zip(plain.mips, turned.mips):
        np.testing.assert_allclose(cube_source.remap(a, mirror), b, rtol=1e-10)
    np.testing.assert_array_equal(plain.mips[0], faces)  # the same size: the source itself


def test_a_too_narrow_lobe_is_refused_from_a_cube_source(small_floor):
    with pytest.raises(ValueError, match="narrower than the spherical harmonics reach"):
        cube_source.bake_from_cube(np.ones((6, 4, 4, 3)), 4, [0.0, 0.01], estimate=False)


# ----------------------------------------------------------------------------- the environment key takes a cube


def write_source(tmp_path, faces, record=None):
    return write_cube([faces], tmp_path / "env.ktx2", record or {"kind": "environment_specular"}, "ktx2", "float32")


def test_a_config_bakes_from_a_cube_file_and_records_it(tmp_path, small_floor):
    faces = octant(cube.texel_centres(8)).astype(np.float32).astype(np.float64)
    write_source(tmp_path, faces)
    (tmp_path / "c.toml").write_text(
        '[[table]]\nname = "spec"\nkind = "environment_specular"\nenvironment = "env.ktx2"\nsize = 4\nmips = 2\n'
        'format = "ktx2"\ndtype = "float32"\n'
        '[[table]]\nname = "irr"\nkind = "environment_irradiance"\nenvironment = "env.ktx2"\nsize = 2\n'
        'format = "ktx2"\ndtype = "float32"\n'
    )
    results = lutbake.bake([tmp_path / "c.toml"], out_dir=tmp_path / "out")
    assert {r.name: r.status for r in results} == {"spec": "baked", "irr": "baked"}
    spec = read_cube(tmp_path / "out" / "spec.ktx2")
    assert "cube: mip 0 of a 8^2 ktx2 R32G32B32A32_SFLOAT cube" in spec.record["source_convention"]
    assert spec.record["method_per_mip"] == ["box average", "harmonic"]
    want = cube_source.bake_from_cube(faces, 4, [0.0, 1.0])
    for got, ref in zip(spec.mips, want.mips):
        np.testing.assert_allclose(got, ref.astype(np.float32), rtol=1e-7)
    doc = json.loads((tmp_path / "out" / "irr_sh.json").read_text())
    np.testing.assert_allclose(doc["coefficients"], cube_source.project_cube(faces), rtol=1e-12)


@pytest.mark.parametrize(
    "keys, fragment",
    [("size = 3", "size must divide 8"), ('estimator = "quadrature"', "baked by spherical harmonics")],
)
def test_a_cube_environment_refuses_what_it_cannot_bake_at_config_time(tmp_path, keys, fragment):
    from test_environment_kinds import refusal

    write_source(tmp_path, np.ones((6, 8, 8, 3)))
    table = f'name = "spec"\nkind = "environment_specular"\nenvironment = "env.ktx2"\n{keys}'
    assert fragment in refusal(tmp_path, table)
