"""Verified outputs: every file lutbake writes records a sha256 of its own bytes, and a skip trusts a file
only after checking it (issue 11: "nothing wrong survives a rerun").

One output is one *unit*, written so that a crash at any instant leaves either the old unit, or something
the check refuses (then the next run bakes the table again):

- **EXR** (one file, one rename): the header attribute ``lutbake:data_hash`` holds the sha256 of the file's
  bytes with the 64 hex digits of that attribute (every part's copy) set to ``0``. The writer writes the file
  with the zeros, hashes it and patches the digest in place, before the rename. Where the output has other files
  (an environment irradiance cube's SH, lutbake.io.cubemap), they are written first and ``lutbake:files_sha256``
  names their sha256.
- **Every other format** (npy, png16, dds, ktx2, h): the data file, then its sidecar ``<file>.json``
  (e.g. ``dfg.npy.json``: one sidecar per output file, so ``dfg.npy`` and ``dfg.h`` never share one),
  written *last*. The sidecar names the data file (``file``), the sha256 of its bytes (``data_sha256``)
  and a sha256 of the sidecar's own canonical JSON (``sidecar_sha256``, computed with that field absent).
  A crash between the two renames leaves new data beside an old sidecar (``data_sha256`` differs) or no
  sidecar: never a skip. The digests are those of the bytes the writer wrote, not of the file on disk after its
  rename, and the pair is written under lutbake.io.atomic.unit_lock: two runs writing one path (two configs with
  the same table names, one out-dir) leave one run's data with that run's sidecar, and never a sidecar naming
  the other run's bytes.

``verified_attributes(path)`` returns an output's ``lutbake:*`` attributes only if every check passes;
anything else (missing, truncated, garbled, foreign, half-written unit) returns None: not up to date.
"""

from __future__ import annotations

import hashlib
import json
import re
import struct
from pathlib import Path

from ..limits import MAX_SIDECAR_BYTES
from .atomic import atomic_write_bytes

HASH_KEY = "data_hash"  # the EXR header attribute lutbake:data_hash
PLACEHOLDER = b"0" * 64
SIDECAR_SUFFIX = ".json"
SIDECAR_VERSION = 2  # 1: the old shared <stem>.json (no data hash), never trusted for a skip
# an EXR string attribute: name \0 type \0 int32 size, then the value (OpenEXR file layout, "Header Attributes")
_EXR_HASH_ATTR = re.compile(
    re.escape(b"lutbake:" + HASH_KEY.encode() + b"\0string\0" + struct.pack("<i", 64)) + b"([0-9a-f]{64})"
)


CHUNK = 8 << 20  # files are hashed in chunks: a 1 GiB table is never read into memory at once
_CARRY = 128  # > the length of one lutbake:data_hash attribute (name, type, size, 64 digits)


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def sha256_file(path) -> str:
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def sidecar_path(path) -> Path:
    """``out/t.npy`` -> ``out/t.npy.json``: one sidecar per output file."""
    path = Path(path)
    return path.with_name(path.name + SIDECAR_SUFFIX)


# ---------------------------------------------------------------------------------------------- EXR


def _scan_exr(path) -> tuple[str, list[tuple[int, bytes]]]:
    """(sha256 of the file with every lutbake:data_hash value set to the placeholder, [(offset, value)])."""
    h, found, buf, base = hashlib.sha256(), [], b"", 0
    with open(path, "rb") as f:
        while True:
            chunk = f.read(CHUNK)
            buf += chunk
            cut = len(buf) if not chunk else max(len(buf) - _CARRY, 0)  # a match starting before cut is whole
            matches = []
            for m in _EXR_HASH_ATTR.finditer(buf):
                if m.start() >= cut:
                    break
                if m.end() > cut:  # straddles the cut: hash it with the next chunk
                    cut = m.start()
                    break
                matches.append(m)
            part = bytearray(buf[:cut])
            for m in matches:
                found.append((base + m.start(1), m.group(1)))
                part[m.start(1) : m.end(1)] = PLACEHOLDER
            h.update(part)
            buf, base = buf[cut:], base + cut
            if not chunk:
                return h.hexdigest(), found


def seal_exr(path) -> str:
    """Replace the placeholder digits of every ``lutbake:data_hash`` in the EXR at ``path`` (a temporary file,
    before its rename) by the sha256 of the file with the placeholders; returns the digest."""
    digest, found = _scan_exr(path)
    if not found or any(value != PLACEHOLDER for _, value in found):
        raise OSError(f"{path}: the writer left no lutbake:{HASH_KEY} placeholder to seal")
    with open(path, "r+b") as f:
        for offset, _ in found:
            f.seek(offset)
            f.write(digest.encode())
    return digest


def exr_intact(path) -> bool:
    """True if the EXR holds ``lutbake:data_hash`` (every copy equal) matching its own bytes."""
    digest, found = _scan_exr(path)
    values = {value for _, value in found}
    return len(values) == 1 and values.pop().decode() == digest != PLACEHOLDER.decode()


def _exr_attributes(path: Path) -> dict[str, str] | None:
    import OpenImageIO as oiio

    inp = oiio.ImageInput.open(str(path))
    if inp is None:
        oiio.geterror()
        return None
    try:
        return {
            p.name[len("lutbake:") :]: str(p.value) for p in inp.spec().extra_attribs if p.name.startswith("lutbake:")
        }
    finally:
        inp.close()


# ------------------------------------------------------------------------------------------ sidecars


def _canonical(doc: dict) -> bytes:
    return json.dumps(doc, sort_keys=True, ensure_ascii=False, separators=(",", ":")).encode("utf-8")


def sidecar_document(
    path, fmt: str, attributes: dict[str, str], digests: dict[str, str], extra: dict | None = None
) -> dict:
    """The sidecar of the data file ``path``. ``digests``: file name -> sha256 of the bytes this writer wrote, for
    ``path`` and each other file of the output (``extra["files"]``), taken from the bytes in hand
    (lutbake.io.atomic.atomic_write_hashed), never from the disk after the rename: another run writing the same path
    may have replaced the file in between, and this sidecar must not vouch for its bytes."""
    path = Path(path)
    others = [n for n in (extra or {}).get("files", []) if n != path.name]  # e.g. ltc_dds's <name>_2.dds
    doc = {
        "file": path.name,
        "format": fmt,
        "sidecar_version": SIDECAR_VERSION,
        "row_order": "file row 0 = table row 0 (y index 0); column 0 = x index 0",
        **(extra or {}),
        "data_sha256": digests[path.name],
        "lutbake": dict(attributes),
    }
    if others:
        doc["files_sha256"] = {n: digests[n] for n in others}
    doc["sidecar_sha256"] = sha256_bytes(_canonical(doc))
    return doc


def write_sidecar(
    path, fmt: str, attributes: dict[str, str], digests: dict[str, str], extra: dict | None = None
) -> Path:
    """Write ``<path>.json`` (atomically) naming the bytes written to ``path`` (``digests``, sidecar_document): the
    last step of writing an output, under lutbake.io.atomic.unit_lock."""
    doc = sidecar_document(path, fmt, attributes, digests, extra)
    return atomic_write_bytes(sidecar_path(path), (json.dumps(doc, indent=1, ensure_ascii=False) + "\n").encode())


def read_sidecar(path) -> dict | None:
    """The sidecar document of data file ``path`` if it is intact and names ``path``'s current bytes."""
    path = Path(path)
    try:
        side = sidecar_path(path)
        if side.stat().st_size > MAX_SIDECAR_BYTES:
            return None
        doc = json.loads(side.read_bytes().decode("utf-8"))
        if not isinstance(doc, dict) or doc.get("file") != path.name or not isinstance(doc.get("lutbake"), dict):
            return None
        claimed = doc.pop("sidecar_sha256", None)
        if claimed != sha256_bytes(_canonical(doc)):
            return None
        if doc.get("data_sha256") != sha256_file(path):
            return None
        for name, digest in doc.get("files_sha256", {}).items():  # the other files of a multi-file output
            if Path(name).name != name or sha256_file(path.with_name(name)) != digest:
                return None
        return doc
    except (OSError, ValueError, RecursionError):  # missing, unreadable, not JSON, not UTF-8
        return None


def legacy_sidecar(path) -> Path | None:
    """The pre-issue-11 shared sidecar ``<stem>.json`` if it is lutbake's and describes ``path``."""
    path = Path(path)
    old = path.with_suffix(SIDECAR_SUFFIX)
    try:
        doc = json.loads(old.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return old if isinstance(doc, dict) and doc.get("file") == path.name and "lutbake" in doc else None


# ------------------------------------------------------------------------------------------ checking


def _others_intact(path: Path, text: str | None) -> bool:
    """The other files of an EXR's output (``lutbake:files_sha256``: name -> sha256, beside it; an environment
    irradiance table's SH) hold the bytes it names; True where it names none."""
    if text is None:
        return True
    named = json.loads(text)
    return all(Path(n).name == n and sha256_file(path.with_name(n)) == d for n, d in named.items())


def verified_attributes(path) -> dict[str, str] | None:
    """The ``lutbake:*`` attributes (prefix removed) of the output at ``path`` if the file and its metadata
    pass every integrity check; None otherwise (missing, corrupt, half-written, foreign: bake it again)."""
    path = Path(path)
    try:
        if not path.is_file():
            return None
        if path.suffix == ".exr":
            attrs = _exr_attributes(path) if exr_intact(path) else None
            return attrs if attrs is not None and _others_intact(path, attrs.get("files_sha256")) else None
        doc = read_sidecar(path)
        if doc is None:
            return None
        return {k[len("lutbake:") :] if k.startswith("lutbake:") else k: str(v) for k, v in doc["lutbake"].items()}
    except Exception:  # noqa: BLE001 - any failure to verify means "not up to date", never a crash
        return None
