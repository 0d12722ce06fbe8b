"""specular_3d: with Schlick it is the dfg table (f0 scale + bias); metals reach their mirror limit."""

import numpy as np
import pytest

from lutbake.integrands.fresnel import evaluate
from lutbake.metals import METALS

SIZE = [20, 10]
COLLAPSE_TOL = 1e-6


def test_specular_3d_schlick_is_f0_scale_plus_bias_of_dfg(bake):
    t3 = bake(kind="specular_3d", size=SIZE, fresnel="schlick", f0_size=5)
    d = bake(kind="dfg", size=SIZE)
    assert t3.data.shape == (5, SIZE[1], SIZE[0], 1)
    assert [a.dim for a in t3.axes] == ["z", "y", "x"]
    f0 = t3.axes[0].values().astype(np.float64)
    np.testing.assert_allclose(f0, (np.arange(5) + 0.5) / 5, rtol=1e-6)
    want = f0[:, None, None] * d.data[None, :, :, 0] + d.data[None, :, :, 1]
    np.testing.assert_allclose(t3.data[..., 0], want, atol=COLLAPSE_TOL)


def test_specular_3d_metal_reaches_the_conductor_mirror_limit(bake):
    t = bake(kind="specular_3d", metal="aluminium", size=[20, 40])
    assert t.data.shape == (40, 20, 3)
    nov = t.axes[1].values().astype(np.float64)
    m = METALS["aluminium"]
    F = np.stack([evaluate(nov, n=n, k=k)["conductor"] for n, k in zip(m.n, m.k)], axis=-1)
    ok = nov > 0.3  # row 0 has alpha = (1/80)^2; its grazing texels still lose energy to G2
    np.testing.assert_allclose(t.data[0][ok], F[ok], atol=2e-3)
    assert np.all(t.data <= 1.0) and np.all(np.diff(t.data[:, -1, :], axis=0) < 0)


def test_metal_key_is_validated(spec):
    with pytest.raises(Exception, match="aluminium"):
        spec(kind="specular_3d", metal="unobtainium")
