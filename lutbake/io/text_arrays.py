"""Array literals in source text (C/C++ headers, JS/TS, WGSL, Rust): comments stripped, numbers read (hex literals are
IEEE half bits), the layout from ``lutbake:shape`` or lutbake's ``#define *_HEIGHT/_WIDTH/_CHANNELS``. Read by
lutbake.io.lut_files (audit) and lutbake.io.engine_files (the engines' own layouts)."""

from __future__ import annotations

import re

import numpy as np


def _text_shape(text: str, shape) -> tuple[int, ...]:
    if shape is not None:
        return tuple(int(s) for s in shape)
    m = re.search(r"lutbake:shape\s*[=:]\s*\[?\s*(\d+)\s*,\s*(\d+)\s*,\s*(\d+)", text)
    if m:
        return tuple(int(g) for g in m.groups())
    dims = {k: int(v) for k, v in re.findall(r"#define\s+\w+?_(HEIGHT|WIDTH|CHANNELS)\s+(\d+)", text)}
    if len(dims) == 3:
        return dims["HEIGHT"], dims["WIDTH"], dims["CHANNELS"]
    raise ValueError(
        "the array's layout is not declared in the file: give shape=(rows, columns, channels) "
        "(CLI: --shape ROWSxCOLUMNSxCHANNELS)"
    )


def strip_comments(text: str) -> str:
    """Source text without its /* ... */ and // comments."""
    return re.sub(r"//[^\n]*", " ", re.sub(r"/\*.*?\*/", " ", text, flags=re.S))


def literal_values(payload: str, n: int) -> tuple[np.ndarray, str]:
    """The first ``n`` numbers of an array literal's body (float64) and how they are stored: hex literals are
    IEEE 754 binary16 bit patterns ("half"), decimal literals floats ("float32")."""
    hexes = re.findall(r"0x([0-9a-fA-F]{1,4})\b", payload)
    if hexes:
        bits = np.array([int(h, 16) for h in hexes[:n]], dtype=np.uint16)
        return bits.view(np.float16).astype(np.float64), "half"
    payload = re.sub(r"_?f(?:32|64)\b", "", payload)  # Rust's 0.5_f32 / 1f64 type suffixes
    nums = re.findall(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?", payload)
    return np.array([float(x) for x in nums[:n]], dtype=np.float64), "float32"


def parse_text_array(text: str, shape=None) -> tuple[np.ndarray, str]:
    """The values of the first ``{...}`` / ``[...]`` array literal after its declaration (literal_values);
    comments are skipped."""
    # "= {", "= [", "( [" (JS), or "= array<f32, N>(" (WGSL): the literal's first number follows
    m = re.search(r"(?:=|\()\s*[^{\[;(]*?(?:[{\[]|\()\s*((?:0x|[-+.\d])[^;]*)", strip_comments(text))
    if not m:
        raise ValueError("no array literal found")
    shp = _text_shape(text, shape)
    n = int(np.prod(shp))
    arr, storage = literal_values(m.group(1), n)
    if arr.size != n:
        raise ValueError(f"the array holds {arr.size} values, the declared shape {shp} needs {n}")
    return arr.reshape(shp), storage
