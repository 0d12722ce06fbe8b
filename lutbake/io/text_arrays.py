"""Array literals in source text (C/C++ headers, JS/TS, WGSL, Rust): comments stripped, numbers read (hex literals are
IEEE half bits), the layout from ``lutbake:shape`` or lutbake's ``#define *_HEIGHT/_WIDTH/_CHANNELS``; every scan
linear and bounded (lutbake.io.bounded). Read by lutbake.io.lut_files (audit) and lutbake.io.engine_files (the
engines' own layouts)."""

from __future__ import annotations

import re

import numpy as np

from . import bounded


def _text_shape(text: str, shape) -> tuple[int, ...]:
    if shape is not None:
        return tuple(int(s) for s in shape)
    m = re.search(
        r"lutbake:shape[ \t]{0,8}[=:][ \t]{0,8}\[?[ \t]{0,8}(\d{1,9})\s{0,8},\s{0,8}(\d{1,9})\s{0,8},\s{0,8}(\d{1,9})",
        text,
    )
    if m:
        return tuple(int(g) for g in m.groups())
    dims = {
        k: int(v)
        for k, v in re.findall(r"#define[ \t]{1,64}\w{0,128}?_(HEIGHT|WIDTH|CHANNELS)[ \t]{1,64}(\d{1,9})", text)
    }
    if len(dims) == 3:
        return dims["HEIGHT"], dims["WIDTH"], dims["CHANNELS"]
    raise ValueError(
        "the array's layout is not declared in the file: give shape=(rows, columns, channels) "
        "(CLI: --shape ROWSxCOLUMNSxCHANNELS)"
    )


def strip_comments(text: str) -> str:
    """Source text without its /* ... */ and // comments, in one pass (linear time: an unclosed ``/*`` ends the
    text, it is never searched for again from each later ``/*``)."""
    out, pos, n = [], 0, len(text)
    block = line = 0  # the next "/*" and "//" at or after pos (-1: none left), each searched for again only once passed
    while pos < n:
        if 0 <= block < pos:
            block = text.find("/*", pos)
        if 0 <= line < pos:
            line = text.find("//", pos)
        if pos == 0:
            block, line = text.find("/*"), text.find("//")
        if block < 0 and line < 0:
            out.append(text[pos:])
            break
        start = min(x for x in (block, line) if x >= 0)
        out.append(text[pos:start])
        out.append(" ")
        if start == block:
            end = text.find("*/", start + 2)
            pos = n if end < 0 else end + 2
        else:
            end = text.find("\n", start)
            pos = n if end < 0 else end
    return "".join(out)


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


_TOKENS = re.compile(r"[=;({\[]")
_NUMBER_START = re.compile(r"\s*(?:0x|[-+.\d])")


def literal_body(code: str) -> str | None:
    """The body of the first array literal of ``code`` (comments stripped): from the first number after the first
    ``{``, ``[`` or ``(`` that follows an ``=`` or a ``(`` in the same statement ("= {", "= [", "( [" in JS,
    "= array<f32, N>(" in WGSL), up to the next ``;``. One pass over the text (a tokenizer, not a backtracking
    pattern: 10^6 ``=`` take milliseconds)."""
    armed = False
    for m in _TOKENS.finditer(code):
        c = m.group()
        if c == ";":
            armed = False
        elif c == "=":
            armed = True
        else:
            if armed:
                num = _NUMBER_START.match(code, m.end())
                if num:
                    start = num.end() - len(num.group().lstrip())
                    end = code.find(";", start)
                    return code[start : end if end >= 0 else len(code)]
            armed = c == "("
    return None


def parse_text_array(text: str, shape=None) -> tuple[np.ndarray, str]:
    """The values of the first ``{...}`` / ``[...]`` array literal after its declaration (literal_values);
    comments are skipped."""
    body = literal_body(strip_comments(text))
    if body is None:
        raise ValueError("no array literal found")
    shp = _text_shape(text, shape)
    bounded.check_texels(shp, "the declared shape")
    n = int(np.prod(shp))
    arr, storage = literal_values(body, n)
    if arr.size != n:
        raise ValueError(f"the array holds {arr.size} values, the declared shape {shp} needs {n}")
    return arr.reshape(shp), storage
