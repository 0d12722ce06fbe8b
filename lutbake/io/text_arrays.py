"""Array literals in source text (C/C++ headers, JS/TS, WGSL, Rust): comments stripped, numbers read by one tokenizer
(parse_numbers: hex integer literals are IEEE half bits, decimals and C99 hex floats are floats, exactly as many as
the declared shape), the layout from ``lutbake:shape`` or lutbake's ``#define *_HEIGHT/_WIDTH/_CHANNELS``; every scan
linear and bounded (lutbake.io.bounded). Read by lutbake.io.lut_files (audit) and lutbake.io.engine_files (the
engines' own layouts)."""

from __future__ import annotations

import re
import warnings

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


SEPARATORS = str.maketrans({c: " " for c in ",[](){}\n\r\t"})  # the array's punctuation: between numbers
CHUNK_CHARS = 1 << 20  # the token-by-token path reads this many characters at a time (bounded lists)
MAX_TOKEN_CHARS = 64  # the longest number shown in a message
# C's 0.5f / 1e-3F and Rust's 0.5_f32 / 1f64 type suffixes of a decimal literal, each before a separator (str.replace:
# a pattern with a look-behind took 2 s over 10^7 numbers); "_f32" before "f32"
DECIMAL_SUFFIXES = ("_f32 ", "_f64 ", "f32 ", "f64 ", "f ", "F ")
# one literal of the token-by-token path (a body with hex literals): group 1 a hex integer, IEEE 754 binary16 bits
# (C/C# ``u``, Rust ``_u16`` suffixes); group 2 a C99 hex float (``printf("%a")``: 0x1.8p-1); group 3 a decimal
_LITERAL = re.compile(
    r"(0[xX][0-9a-fA-F]{1,16})(?:_?u16|[uU])?"
    r"|([-+]?0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)[pP][-+]?\d{1,5})[fFlL]?"
    r"|([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d{1,5})?|[-+]?(?:nan|inf(?:inity)?))(?:_?f(?:32|64)|[fF])?",
    re.I,
)
HALF_MAX_BITS = 0xFFFF


def _count_problem(got: int, n: int, more: bool = False) -> ValueError:
    return ValueError(
        f"the array holds {'more than ' if more else ''}{got} values, its declared shape needs {n} "
        f"({'extra values after the table' if more or got > n else 'values missing'}: refused, not cut or padded)"
    )


def _chunks(text: str):
    """``text`` (separators already spaces) in pieces of about CHUNK_CHARS, each cut at a space."""
    pos = 0
    while pos < len(text):
        end = len(text) if len(text) - pos <= CHUNK_CHARS else text.rfind(" ", pos, pos + CHUNK_CHARS) + 1
        if end <= pos:
            raise ValueError(f"a token of more than {CHUNK_CHARS} characters: {text[pos : pos + MAX_TOKEN_CHARS]!r}")
        yield text[pos:end]
        pos = end


def _without_suffixes(text: str) -> str:
    """Decimal literals without their type suffixes, for numpy's bulk parser ("inf" loses its "f" too: numpy then
    stops there, and the token-by-token path reads it)."""
    if "f" in text or "F" in text:
        for suffix in DECIMAL_SUFFIXES:
            text = text.replace(suffix, " ")
    return text


def _bad_token(token: str) -> ValueError:
    return ValueError(f"{token[:MAX_TOKEN_CHARS]!r} is not a number (a decimal, C99 hex float or hex literal)")


def _token_values(text: str, n: int, bits: bool) -> tuple[np.ndarray, str]:
    """The token-by-token path (hex literals, and every error message): at most ``n`` values kept, in chunks."""
    out = np.empty(n, np.float64)
    kinds = set()
    got = 0
    for chunk in _chunks(text):
        tokens = chunk.split()
        if got + len(tokens) > n:
            raise _count_problem(n, n, more=True)
        for token in tokens:
            m = _LITERAL.fullmatch(token)
            if m is None:
                raise _bad_token(token)
            hexint, hexfloat, decimal = m.groups()
            if hexint is not None:
                value = int(hexint, 16)
                if value > HALF_MAX_BITS:
                    raise ValueError(
                        f"hex literal {hexint[:MAX_TOKEN_CHARS]} is not an IEEE half bit pattern (0 to 0xffff)"
                    )
                kinds.add("bits")
            elif bits:
                if decimal is None or not decimal.isdigit() or int(decimal) > HALF_MAX_BITS:
                    raise ValueError(f"{token[:MAX_TOKEN_CHARS]!r} is not a 16-bit pattern (0 to 65535)")
                value = int(decimal)
            else:
                value = float.fromhex(hexfloat) if hexfloat is not None else float(decimal)
                kinds.add("float")
            out[got] = value
            got += 1
    if got != n:
        raise _count_problem(got, n)
    if kinds == {"bits", "float"}:
        raise ValueError("the array mixes hex bit patterns (IEEE half) with floats: one storage per array")
    if bits or kinds == {"bits"}:
        return out.astype(np.uint16).view(np.float16).astype(np.float64), "half"
    return out, "float32"


def parse_numbers(body: str, n: int, bits: bool = False) -> tuple[np.ndarray, str]:
    """Exactly the ``n`` numbers of an array literal's body (comments stripped), as float64, and how they are stored:
    hex integer literals (``0x3c00``) are IEEE 754 binary16 bit patterns ("half"; ``bits``: every literal is, also in
    decimal, as a C ``uint16_t`` array), decimals and C99 hex floats (``0x1.0p-1``, ``printf("%a")``) floats
    ("float32"). More or fewer values than ``n``, or a token that is no number, is a ValueError. The one tokenizer of
    every text array (inspect's C header, audit, the engines' layouts); decimals are parsed in bulk (numpy, no Python
    object per number: 10^7 values in about 2 s and 100 MB)."""
    text = body.translate(SEPARATORS) + " "
    if not bits and "0x" not in text and "0X" not in text:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # numpy warns (DeprecationWarning) or raises on a token it cannot read
            try:
                values = np.fromstring(_without_suffixes(text), dtype=np.float64, sep=" ")
            except (ValueError, DeprecationWarning):
                values = None
        if values is not None:
            if values.size != n:
                raise _count_problem(values.size, n)
            return values, "float32"
    return _token_values(text, n, bits)


def literal_values(payload: str, n: int) -> tuple[np.ndarray, str]:
    """``parse_numbers(payload, n)``: the ``n`` numbers of an array literal's body and how they are stored."""
    return parse_numbers(payload, n)


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
    bounded.check_texels(shp, "the declared shape", itemsize=8)  # parsed as float64
    n = int(np.prod(shp))
    arr, storage = parse_numbers(body, n)
    return arr.reshape(shp), storage
