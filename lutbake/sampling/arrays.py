"""Names for the Warp array types the kernels take (short signatures, one meaning each), and ``store_row``: a texel's
closed-form row written into a Rows64 output."""

import warp as wp

Floats = wp.array(dtype=float)  # one float32 per texel
Vec3s = wp.array(dtype=wp.vec3)  # one direction per texel
LightView = wp.array2d(dtype=wp.vec3)  # (l, v) per texel: row i = (l_i, v_i), unit directions in the shading frame
Points2 = wp.array2d(dtype=float)  # QMC points, one row each (float32)
Rule = wp.array(dtype=wp.vec2d)  # a Gauss-Legendre rule on [0, 1]: (node, weight) pairs, float64
Levels = wp.array(dtype=wp.vec2i)  # a ladder of rules: (offset, order) into concatenated Rules (rules.gl_levels)
PhiRule = wp.array(dtype=wp.vec3d)  # an inner rule in phi: (cos phi, sin phi, weight) rows, float64
Rows64 = wp.array2d(dtype=wp.float64)  # the float64 output, one row per texel
Values64 = wp.array(dtype=wp.float64)  # the float64 output, one value per texel


@wp.func
def store_row(out: wp.array2d(dtype=wp.float64), i: int, m: wp.vec2):
    """out[i] = m (float64): a texel's closed-form value (the mirror limit)."""
    out[i, 0] = wp.float64(m[0])
    out[i, 1] = wp.float64(m[1])


@wp.func
def store_row(out: wp.array2d(dtype=wp.float64), i: int, m: wp.vec3):  # noqa: F811 (a Warp overload)
    out[i, 0] = wp.float64(m[0])
    out[i, 1] = wp.float64(m[1])
    out[i, 2] = wp.float64(m[2])


@wp.func
def store_row(out: wp.array2d(dtype=wp.float64), i: int, m: wp.vec4):  # noqa: F811 (a Warp overload)
    for c in range(4):
        out[i, c] = wp.float64(m[c])
