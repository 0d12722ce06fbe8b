"""The executor: bit-identical output for any worker count; the table's axes and values."""

import numpy as np
import pytest

DFG = {"name": "t", "kind": "dfg", "size": [24, 20]}
MIRROR_ATOL = 1e-5  # the r = 0 row (alpha = ALPHA_MIN) vs the mirror's closed form away from grazing: measured 2e-7


@pytest.fixture(scope="module")
def one_worker(bake):
    return bake(DFG, workers=1)


def test_output_is_bit_identical_for_1_and_n_workers(one_worker, bake):
    from lutbake.runtime import executor

    old = executor.TILE_TEXELS
    try:
        executor.TILE_TEXELS = 37  # odd tiles too
        for w in (2, 3):
            t = bake(DFG, workers=w)
            assert np.array_equal(t.data, one_worker.data)
    finally:
        executor.TILE_TEXELS = old


def test_table_layout_row0_is_smoothest_and_col0_is_grazing(one_worker):
    rough, nov = one_worker.axes
    assert (rough.dim, nov.dim) == ("y", "x")
    assert one_worker.data.shape == (20, 24, 2)
    np.testing.assert_allclose(nov.values(), (np.arange(24) + 0.5) / 24, rtol=1e-6)
    np.testing.assert_allclose(rough.alpha(), np.maximum(((np.arange(20) + 0.5) / 20) ** 2, 1e-4), rtol=1e-6)
    # smooth row: bias is the Schlick mirror value (1 - NoV)^5
    np.testing.assert_allclose(one_worker.data[0, :, 1], (1 - nov.values()) ** 5, atol=2e-3)


def test_endpoint_texels_cover_the_whole_range(bake):
    t = bake(DFG, texel="endpoint", size=[5, 3], workers=1)
    rough, nov = t.axes
    np.testing.assert_allclose(nov.values(), [1e-4, 0.25, 0.5, 0.75, 1.0], rtol=1e-6)
    np.testing.assert_allclose(rough.values(), [0.0, 0.5, 1.0])
    # the r = 0 row is a mirror for NoV >= 0.25: bias = Schlick's (1 - NoV)^5 and scale + bias = 1 (F = 1)
    c = nov.values()[1:].astype(np.float64)
    np.testing.assert_allclose(t.data[0, 1:, 1], (1 - c) ** 5, atol=MIRROR_ATOL)
    np.testing.assert_allclose(t.data[0, 1:].sum(-1), 1.0, atol=MIRROR_ATOL)


def test_multiscatter_layout_relates_to_scale_bias(one_worker, bake):
    ms = bake(DFG, layout="multiscatter")
    scale, bias = one_worker.data[..., 0], one_worker.data[..., 1]
    # R = ∫Fc f = bias, G = ∫f = scale + bias
    np.testing.assert_allclose(ms.data[..., 0], bias, atol=1e-6)
    np.testing.assert_allclose(ms.data[..., 1], scale + bias, atol=1e-6)
