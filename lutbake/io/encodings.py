"""Texel encodings of HDR cube maps: the packed unsigned float formats, encoded exactly and decoded, and sRGB:

- **RGB9E5** (VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, DXGI_FORMAT_R9G9B9E5_SHAREDEXP, GL_RGB9_E5): three 9-bit mantissas
  and one shared 5-bit exponent, E << 27 | B << 18 | G << 9 | R; value = mantissa 2^(E - B - N), N = 9, B = 15
  (EXT_texture_shared_exponent, "Encoding an RGB9E5 value"; OpenGL 4.6 §8.25; Vulkan 1.3 §3.9 "Shared Exponent").
  The encoding is the extension's, step by step, in exact arithmetic:
  red_c = max(0, min(sharedexp_max, red)), sharedexp_max = (2^N - 1) / 2^N 2^(Emax - B) = 65408;
  exp_shared_p = max(-B - 1, floor(log2(max_c))) + 1 + B; max_s = floor(max_c / 2^(exp_shared_p - B - N) + 1/2);
  exp_shared = exp_shared_p + 1 where max_s = 2^N, else exp_shared_p; red_s = floor(red_c / 2^(exp_shared - B - N)
  + 1/2). floor(log2 x) is taken from the float's exponent (np.frexp), never from a rounded log2.
- **B10G11R11** (VK_FORMAT_B10G11R11_UFLOAT_PACK32, DXGI_FORMAT_R11G11B10_FLOAT, GL_R11F_G11F_B10F): unsigned
  11-bit (5-bit exponent, 6-bit mantissa) R and G, 10-bit (5, 5) B, B << 22 | G << 11 | R, exponent bias 15, with
  subnormals (Vulkan 1.3 §3.9 "Unsigned 11-Bit / 10-Bit Floating-Point Numbers"; OpenGL 4.6 §2.3.4.3, §2.3.4.4).
  Encoded by rounding to the nearest representable value, ties to even (the mantissa step 2^(e - M) is exact in
  float64; np.rint rounds half to even); a carry into the exponent is the next binade's code, as the bit layout gives.

lutbake refuses rather than clamps: a NaN, an infinity or a value past the format's largest finite value
(RGB9E5 65408; B10G11R11 65024 in R and G, 64512 in B) is a ValueError; a negative value is stored as 0 (these
formats hold none; radiance is >= 0 and the prefilter's rounding leaves at most -1e-12 or so).

- **sRGB** (IEC 61966-2-1): ``srgb_eotf`` is what a sampler returns for a texel of an ``*_SRGB`` format,
  ``srgb_oetf`` its inverse.
"""

from __future__ import annotations

import numpy as np

RGB9E5_N, RGB9E5_B, RGB9E5_EMAX = 9, 15, 31
RGB9E5_MAX = (2**RGB9E5_N - 1) / 2**RGB9E5_N * 2.0 ** (RGB9E5_EMAX - RGB9E5_B)  # 65408
SMALL_FLOAT_BITS = ((6, 0), (6, 11), (5, 22))  # (mantissa bits, shift) of R, G (11-bit) and B (10-bit)
SMALL_FLOAT_BIAS = 15


def small_float_max(mantissa: int) -> float:
    """The largest finite unsigned small float: exponent 30, every mantissa bit set."""
    return 2.0 ** (30 - SMALL_FLOAT_BIAS) * (2 - 2.0**-mantissa)


B10G11R11_MAX = tuple(small_float_max(m) for m, _ in SMALL_FLOAT_BITS)  # 65024, 65024, 64512


def _checked(rgb: np.ndarray, limits, name: str) -> np.ndarray:
    """(..., 3) float64 with negatives set to 0; ValueError for a non-finite value or one past ``limits``."""
    a = np.asarray(rgb, np.float64)
    if a.shape[-1:] != (3,):
        raise ValueError(f"{name} packs RGB triples, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: a value is not finite; nothing written")
    over = a > np.asarray(limits, np.float64)
    if np.any(over):
        raise ValueError(
            f"{name}: {int(over.sum())} value(s) past the largest the format holds (max {float(a.max()):g}; "
            f"limits {', '.join(f'{x:g}' for x in np.broadcast_to(limits, (3,)))}); nothing written"
        )
    return np.maximum(a, 0.0)


def encode_rgb9e5(rgb: np.ndarray) -> np.ndarray:
    """(...) uint32 of (..., 3) values in [0, 65408] (module docstring: the extension's exact encoding)."""
    a = _checked(rgb, RGB9E5_MAX, "RGB9E5")
    n, bias = RGB9E5_N, RGB9E5_B
    max_c = a.max(axis=-1)
    _, e = np.frexp(max_c)  # max_c = f 2^e, f in [0.5, 1): floor(log2 max_c) = e - 1 (max_c > 0)
    floor_log2 = np.where(max_c > 0, e - 1, -bias - 1)
    exp_p = np.maximum(-bias - 1, floor_log2) + 1 + bias
    max_s = np.floor(np.ldexp(max_c, -(exp_p - bias - n)) + 0.5)
    exp_shared = np.where(max_s >= 2**n, exp_p + 1, exp_p)
    scaled = np.floor(np.ldexp(a, -(exp_shared[..., None] - bias - n)) + 0.5).astype(np.uint32)
    out = exp_shared.astype(np.uint32) << np.uint32(27)
    for c in range(3):
        out |= scaled[..., c] << np.uint32(9 * c)
    return out


def decode_rgb9e5(packed: np.ndarray) -> np.ndarray:
    """(..., 3) float64 of RGB9E5 texels: mantissa 2^(E - 24)."""
    p = np.asarray(packed, np.uint32)
    scale = np.ldexp(1.0, (p >> np.uint32(27)).astype(np.int64) - RGB9E5_B - RGB9E5_N)
    return np.stack([((p >> np.uint32(9 * c)) & np.uint32(511)) * scale for c in range(3)], axis=-1)


def _small_float_code(v: np.ndarray, mantissa: int) -> np.ndarray:
    """The unsigned small float code (5-bit exponent, ``mantissa`` bits) nearest to v >= 0, ties to even."""
    _, e = np.frexp(v)
    exponent = np.maximum(e - 1, 1 - SMALL_FLOAT_BIAS)  # below 2^-14: the subnormal step 2^(-14 - M)
    step = np.ldexp(1.0, exponent - mantissa)
    units = np.rint(v / step)  # v / step is exact: a power-of-two scaling
    # normal: (exponent + bias) << M plus the fraction's units above 2^M; subnormal: the units themselves. A carry
    # (units = 2^(M + 1), or 2^M for a subnormal) is the next binade's code.
    biased = np.where(v >= 2.0 ** (1 - SMALL_FLOAT_BIAS), exponent + SMALL_FLOAT_BIAS - 1, 0)
    return (biased.astype(np.int64) << mantissa) + units.astype(np.int64)


def encode_b10g11r11(rgb: np.ndarray) -> np.ndarray:
    """(...) uint32 of (..., 3) values, R and G <= 65024, B <= 64512 (module docstring)."""
    a = _checked(rgb, B10G11R11_MAX, "B10G11R11")
    out = np.zeros(a.shape[:-1], np.uint32)
    for c, (m, shift) in enumerate(SMALL_FLOAT_BITS):
        out |= _small_float_code(a[..., c], m).astype(np.uint32) << np.uint32(shift)
    return out


def decode_b10g11r11(packed: np.ndarray) -> np.ndarray:
    """(..., 3) float64 of B10G11R11 texels: 2^(e - 15) (1 + m / 2^M), subnormals 2^-14 m / 2^M; the exponent
    31 codes (infinity, NaN) decode to inf / nan."""
    p = np.asarray(packed, np.uint32)
    out = []
    for m, shift in SMALL_FLOAT_BITS:
        code = (p >> np.uint32(shift)) & np.uint32((1 << (m + 5)) - 1)
        e = (code >> np.uint32(m)).astype(np.int64)
        frac = (code & np.uint32((1 << m) - 1)).astype(np.float64)
        value = np.where(e == 0, np.ldexp(frac, -14 - m), np.ldexp(frac + 2**m, e - 15 - m))
        special = np.where(frac == 0, np.inf, np.nan)
        out.append(np.where(e == 31, special, value))
    return np.stack(out, axis=-1)


ENCODERS = {"rgb9e5": encode_rgb9e5, "b10g11r11": encode_b10g11r11}
DECODERS = {"rgb9e5": decode_rgb9e5, "b10g11r11": decode_b10g11r11}
LIMITS = {"rgb9e5": (RGB9E5_MAX,) * 3, "b10g11r11": B10G11R11_MAX}


def srgb_eotf(v):
    """sRGB decoding (IEC 61966-2-1): what a sampler returns for a texture stored as sRGB."""
    v = np.clip(v, 0.0, None)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def srgb_oetf(v):
    """sRGB encoding (IEC 61966-2-1), the inverse of srgb_eotf."""
    v = np.clip(v, 0.0, None)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)
