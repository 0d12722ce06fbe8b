"""Compare two directories of baked tables texel by texel (a dev tool: bit-identity before/after a refactor).

    python benchmarks/compare_outputs.py BASELINE_DIR NEW_DIR [--json report.json]

Every file lutbake writes is decoded to a float64 array with readers independent of lutbake's writers
(OpenImageIO for EXR/PNG, the DDS/KTX2 headers parsed here (KTX2 Zstandard levels decompressed), numpy for .npy,
the C array text for .h, every number outside the comments of .js/.cc/.cs);
metadata (content hash, versions, axes text) is ignored. For each table it prints ``identical`` or the number
of differing texels, the largest absolute difference and where the differing texels lie (index ranges per
array dimension).
"""

from __future__ import annotations

import argparse
import json
import re
import struct
import sys
from pathlib import Path

import numpy as np

SUFFIXES = (".exr", ".npy", ".png", ".dds", ".ktx2", ".h", ".js", ".cc", ".cs")


def read_exr(path: Path) -> np.ndarray:
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        raise OSError(oiio.geterror())
    parts = []
    try:
        sub = 0
        while inp.seek_subimage(sub, 0):
            spec = inp.spec()
            parts.append(
                # (subimage, miplevel, chbegin, chend, format): read_image(chbegin, chend, format) returns part 0
                np.asarray(inp.read_image(sub, 0, 0, spec.nchannels, oiio.FLOAT), np.float64).reshape(
                    spec.height, spec.width, spec.nchannels
                )
            )
            sub += 1
    finally:
        inp.close()
    return parts[0] if len(parts) == 1 else np.stack(parts)


def read_png(path: Path) -> np.ndarray:
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    spec = inp.spec()
    a = np.asarray(inp.read_image(0, spec.nchannels, oiio.UINT16), np.float64)
    inp.close()
    return a.reshape(spec.height, spec.width, spec.nchannels)  # raw 16-bit codes


def read_dds(path: Path) -> np.ndarray:
    blob = path.read_bytes()
    assert blob[:4] == b"DDS "
    height, width = struct.unpack_from("<II", blob, 12)
    depth = struct.unpack_from("<I", blob, 24)[0] or 1
    dxgi = struct.unpack_from("<I", blob, 128)[0]
    fmt = {54: ("<f2", 1), 34: ("<f2", 2), 10: ("<f2", 4), 41: ("<f4", 1), 16: ("<f4", 2), 2: ("<f4", 4)}[dxgi]
    data = np.frombuffer(blob, dtype=fmt[0], offset=148, count=depth * height * width * fmt[1])
    return (
        data.astype(np.float64).reshape(depth, height, width, fmt[1]).squeeze(0)
        if depth == 1
        else data.astype(np.float64).reshape(depth, height, width, fmt[1])
    )


def read_ktx2(path: Path) -> np.ndarray:
    blob = path.read_bytes()
    vk, size = struct.unpack_from("<II", blob, 12)
    w, h, d = struct.unpack_from("<III", blob, 20)
    fmts = {76: ("<f2", 1), 83: ("<f2", 2), 97: ("<f2", 4), 100: ("<f4", 1), 103: ("<f4", 2), 109: ("<f4", 4)}
    dt, nch = fmts[vk]
    scheme = struct.unpack_from("<I", blob, 44)[0]  # supercompressionScheme: 0 none, 2 Zstandard
    off, length = struct.unpack_from("<QQ", blob, 80)  # level 0 byteOffset, byteLength
    n = max(d, 1) * max(h, 1) * w * nch
    level = blob[off : off + length]
    if scheme == 2:
        import zstandard

        level = zstandard.ZstdDecompressor().decompress(level, max_output_size=n * np.dtype(dt).itemsize)
    return np.frombuffer(level, dtype=dt, count=n).astype(np.float64).reshape(max(d, 1), max(h, 1), w, nch)


def read_h(path: Path) -> np.ndarray:
    text = path.read_text()
    m = re.search(r"^static const \w+ \w+\[[^\]]*\] = \{", text, flags=re.M)
    body = text[m.end() : text.index("};", m.end())]
    body = re.sub(r"/\*.*?\*/", "", body, flags=re.S)
    tokens = [t.strip().rstrip("fFuU") for t in body.split(",") if t.strip()]
    if "0x" in body:
        return np.array([int(t, 16) for t in tokens], np.uint16).view(np.float16).astype(np.float64)
    return np.array([float(t) for t in tokens], np.float64)


NUMBER = re.compile(r"0x[0-9a-fA-F]+|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def read_code(path: Path) -> np.ndarray:
    """Every number of a source-code table (.js, .cc, .cs) outside its comments, declarations' sizes included (a
    texel-by-texel comparison of two files of the same layout)."""
    text = re.sub(r"/\*.*?\*/", "", path.read_text(), flags=re.S)
    text = "\n".join(line.split("//")[0] for line in text.splitlines())
    return np.array([int(t, 16) if t.startswith("0x") else float(t) for t in NUMBER.findall(text)], np.float64)


def read(path: Path) -> np.ndarray:
    return {
        ".exr": read_exr,
        ".npy": lambda p: np.load(p).astype(np.float64),
        ".png": read_png,
        ".dds": read_dds,
        ".ktx2": read_ktx2,
        ".js": read_code,
        ".cc": read_code,
        ".cs": read_code,
        ".h": read_h,
    }[path.suffix](path)


def ranges(idx: np.ndarray) -> str:
    u = np.unique(idx)
    out, start = [], u[0]
    for a, b in zip(u, np.append(u[1:], -10)):
        if b != a + 1:
            out.append(f"{start}" if start == a else f"{start}-{a}")
            start = b
    return ",".join(out)


def compare(a: np.ndarray, b: np.ndarray) -> dict:
    if a.shape != b.shape:
        return {"status": "shape", "detail": f"{a.shape} vs {b.shape}"}
    diff = ~((a == b) | (np.isnan(a) & np.isnan(b)))
    if not diff.any():
        return {"status": "identical", "texels": int(a.size)}
    where = np.nonzero(diff)
    d = np.abs(a - b)[diff]
    return {
        "status": "differs",
        "texels": int(a.size),
        "differing": int(diff.sum()),
        "max_abs": float(d.max()),
        "where": {f"dim{k}": ranges(w) for k, w in enumerate(where)},
        "shape": list(a.shape),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("baseline", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    files = sorted(p for p in args.baseline.iterdir() if p.suffix in SUFFIXES)
    report, bad = {}, 0
    for f in files:
        g = args.new / f.name
        r = compare(read(f), read(g)) if g.is_file() else {"status": "missing"}
        report[f.name] = r
        bad += r["status"] != "identical"
        line = f"{f.name:<40} {r['status']}"
        if r["status"] == "identical":
            line += f" ({r['texels']} values)"
        elif r["status"] == "differs":
            line += f": {r['differing']} of {r['texels']} values, max |diff| {r['max_abs']:.3e}, at {r['where']}"
        elif r["status"] == "shape":
            line += f": {r['detail']}"
        print(line)
    print(f"{len(files) - bad} of {len(files)} tables identical")
    if args.json:
        args.json.write_text(json.dumps(report, indent=1) + "\n")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
