"""Hostile files, paths and addresses (issue 38): every output a batch plans is known before any work and none is
written twice; every reader survives any file in bounded memory and time and says in one line what is wrong; the
values cache and the scheduler believe nothing they cannot check. Hostile files are made here, small on disk; the
decompression bombs are read in one subprocess under a memory limit (resource.setrlimit)."""

from __future__ import annotations

import json
import os
import socket
import struct
import subprocess
import sys
import textwrap
import time
import warnings
import zipfile
import zlib
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from lutbake.cli import main
from lutbake.io import bounded, ktx2
from lutbake.io.lut_files import parse_text_array
from lutbake.io.readers import ReadError, read
from lutbake.runtime import cluster

ROOT = Path(__file__).resolve().parents[1]
SMALL = '[[table]]\nname = "{name}"\nkind = "dfg"\nsize = [8, 4]\nsamples = 48\n'
LTC_DDS = '[[table]]\nname = "{name}"\nkind = "ltc"\nsize = [8, 8]\nformat = "ltc_dds"\ndtype = "half"\n'
READ_LIMIT_BYTES = 1 << 30  # address space of the subprocess that reads the bombs (imports take ~200 MiB)
BOMB_RSS_BYTES = 400 << 20  # the most any hostile file may cost it (a refused header costs nothing)
LINEAR_S = 3.0  # 200 KB parsed in linear time: a fraction of a second (quadratic: 10^10 steps, minutes)


def bake(*args, **kw):
    r = CliRunner().invoke(main, ["bake", *map(str, args)], **kw)
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "Traceback" not in r.output
    return r


def one_line_error(r, code=2) -> str:
    assert r.exit_code == code, (r.exit_code, r.output)
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    lines = [x for x in r.output.splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), r.output
    return lines[0]


# ------------------------------------------------------------------------- 1-3: one registry of output paths


def test_two_tables_writing_one_file_exit_2_naming_both(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        LTC_DDS.format(name="foo") + SMALL.format(name="foo_1").replace("samples", 'format = "dds"\nsamples')
    )
    line = one_line_error(bake(cfg, "--out-dir", tmp_path / "o"))
    assert "foo_1.dds" in line and "'foo'" in line and "foo_1" in line
    assert not (tmp_path / "o").exists()


def test_names_differing_only_in_case_collide(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(SMALL.format(name="D") + SMALL.format(name="d"))
    line = one_line_error(bake(cfg, "--out-dir", tmp_path / "o"))
    assert "differ only in case" in line and "'D'" in line and "'d'" in line


def test_report_onto_an_ltc_second_texture_is_refused(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(LTC_DDS.format(name="l"))
    line = one_line_error(bake(cfg, "--out-dir", tmp_path / "o", "--report", tmp_path / "o" / "l_2.dds"))
    assert "second texture of table 'l'" in line


@pytest.mark.parametrize("out", ["t.npy", "t.npy.json", "c.toml", "t.jpg", "sub"])
def test_preview_and_error_map_never_overwrite_an_input_a_sidecar_a_config_or_a_non_png(tmp_path, out):
    (tmp_path / "t.npy").write_bytes(b"keep")
    (tmp_path / "t.npy.json").write_text("{}")
    (tmp_path / "c.toml").write_text("keep")
    (tmp_path / "sub").mkdir()
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    for args in (
        ["preview", tmp_path / "t.npy", "-o", tmp_path / out],
        ["audit", tmp_path / "t.npy", "--preset", "default", "--error-map", tmp_path / out],
    ):
        r = CliRunner().invoke(main, list(map(str, args)))
        line = one_line_error(r)
        assert out in line
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before


def test_preview_into_a_directory_that_takes_no_file_says_so_before_drawing(tmp_path):
    (tmp_path / "t.npy").write_bytes(b"not read")
    line = one_line_error(CliRunner().invoke(main, ["preview", str(tmp_path / "t.npy"), "-o", "/proc/lutbake.png"]))
    assert "/proc/lutbake.png" in line and ".tmp" not in line and "Errno" not in line


def test_an_out_dir_that_takes_no_file_exits_2_before_any_kernel(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(SMALL.format(name="t"))
    t0 = time.perf_counter()
    line = one_line_error(bake(cfg, "--out-dir", "/proc/lutbake-x"))
    assert "--out-dir" in line and time.perf_counter() - t0 < 3
    assert not os.path.exists("/proc/lutbake-x")


def test_a_non_utf8_byte_in_out_dir_or_config_name_exits_2_up_front(tmp_path):
    bad = os.fsdecode(b"out\xff")
    cfg = tmp_path / "c.toml"
    cfg.write_text(SMALL.format(name="t"))
    line = one_line_error(bake(cfg, "--out-dir", tmp_path / bad))
    assert "\\xff" in line and not (tmp_path / bad).exists()
    odd = tmp_path / os.fsdecode(b"c\xff.toml")
    try:
        odd.write_text(SMALL.format(name="t"))
    except OSError:  # a file system that takes UTF-8 names only (APFS): no such config can exist there
        pytest.skip("this file system refuses a name that is not UTF-8")
    line = one_line_error(bake(odd, "--out-dir", tmp_path / "o"))
    assert "\\xff" in line and not (tmp_path / "o").exists()


# ----------------------------------------------------------------------- 4: decompression and size bombs


def _png(width: int, height: int, bit_depth: int = 8, color: int = 0, rows_of_zeros: bool = True) -> bytes:
    """A PNG of ``width`` x ``height`` zeros, deflated in a stream (a few hundred KiB for 2^28 pixels)."""

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    z = zlib.compressobj(1)  # zeros deflate about 1000:1 even at level 1, in a fraction of the time of level 9
    row = bytes(1 + width * bit_depth // 8)
    idat = b"".join(z.compress(row) for _ in range(height if rows_of_zeros else 1)) + z.flush()
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, color, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat) + chunk(b"IEND", b"")


def _npy_header(shape, descr="<f4") -> bytes:
    head = repr({"descr": descr, "fortran_order": False, "shape": tuple(shape)}).encode()
    head += b" " * (-(len(head) + 11) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(head)) + head


def _ktx2_zstd(shape, payload: bytes, declared: int | None = None) -> bytes:
    """A zstd KTX2 whose header declares ``shape`` (R32G32B32A32) and whose level is ``payload`` compressed (with no
    content size in the frame)."""
    import zstandard

    blob = bytearray(ktx2.encode(np.zeros((1, 1, 4), np.float32), supercompression="zstd"))
    frame = zstandard.ZstdCompressor(level=1, write_content_size=False).compressobj()
    level = frame.compress(payload) + frame.flush()
    h, w = shape
    struct.pack_into("<II", blob, 20, w, h)
    level_off = struct.unpack_from("<Q", blob, 80)[0]
    del blob[level_off:]
    raw = declared if declared is not None else h * w * 16
    struct.pack_into("<QQQ", blob, 80, level_off, len(level), raw)
    return bytes(blob) + level


def _ktx2_zstd_of_zeros(shape) -> bytes:
    """A zstd KTX2 (R32G32B32A32) of ``shape`` whose frame really expands to its declared size, compressed in a
    stream of 16 MiB blocks (2 GiB of zeros: 68 KB, about a second)."""
    import zstandard

    h, w = shape
    raw, block = h * w * 16, bytes(16 << 20)
    frame = zstandard.ZstdCompressor(level=1).compressobj(size=raw)
    level = b"".join(frame.compress(block) for _ in range(raw // len(block))) + frame.flush()
    blob = bytearray(ktx2.encode(np.zeros((1, 1, 4), np.float32), supercompression="zstd"))
    struct.pack_into("<II", blob, 20, w, h)
    level_off = struct.unpack_from("<Q", blob, 80)[0]
    del blob[level_off:]
    struct.pack_into("<QQQ", blob, 80, level_off, len(level), raw)
    return bytes(blob) + level


@pytest.fixture(scope="module")
def bombs(tmp_path_factory):
    d = tmp_path_factory.mktemp("bombs")
    side = 11600  # 11600^2 = 1.35e8 texels: just past the cap (bounded.MAX_READ_TEXELS = 2^27)
    files = {
        "png_8bit_11600sq.png": _png(side, side),  # about 130 KiB on disk, 135 MB of pixels
        "png_16bit_20000sq_header.png": _png(20000, 20000, 16, rows_of_zeros=False),
        "ktx2_zstd_header_11600sq.ktx2": _ktx2_zstd((side, side), b"\0" * 64),
        "ktx2_zstd_no_size_64MiB.ktx2": _ktx2_zstd((8, 8), bytes(64 << 20), declared=8 * 8 * 16),
        "ktx2_zstd_truncated.ktx2": _ktx2_zstd((64, 64), bytes(64 * 64 * 16))[:-7],
        "npy_65536sq_x4.npy": _npy_header((65536, 65536, 4)) + bytes(64),
        # exactly the texel cap, a real 2 GiB frame: passes the bomb checks; inspect took 2.1 GB, audit 4 GiB more
        "ktx2_zstd_cap_8192x16384.ktx2": _ktx2_zstd_of_zeros((8192, 16384)),
        "npy_magic_then_garbage.npy": b"\x93NUMPY\x01\x00" + bytes(range(256)) * 4,
    }
    np.save(d / "npy_structured.npy", np.zeros((4, 4), dtype=[("a", "<f4"), ("b", "<f4")]))
    with zipfile.ZipFile(d / "npz_member_declares_2GiB.npz", "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("table.npy", _npy_header((16384, 16384, 2), "<f8") + bytes(1 << 20))
    for name, blob in files.items():
        (d / name).write_bytes(blob)
    assert max(p.stat().st_size for p in d.iterdir()) < 3 << 20  # small on disk
    return d


READ_ALL = textwrap.dedent(
    """
    import json, resource, sys, time
    from pathlib import Path
    resource.setrlimit(resource.RLIMIT_AS, ({limit}, {limit}))
    from lutbake.io.bounded import reading_for
    from lutbake.io.lut_files import read_lut
    from lutbake.io.readers import read
    def audit_read(p):
        with reading_for("audit"):  # as lutbake audit reads: its budget counts the audit's work
            return read_lut(p)
    out = {{}}
    for p in sorted(Path(sys.argv[1]).iterdir()):
        for name, fn in (("inspect", read), ("audit", audit_read)):
            t0 = time.perf_counter()
            try:
                fn(p)
                what = "read"
            except ValueError as e:  # ReadError is a ValueError
                what = "refused: " + str(e)
            except BaseException as e:
                what = "CRASH " + type(e).__name__ + ": " + str(e)[:200]
            status = Path("/proc/self/status").read_text()  # VmHWM: this process' peak (ru_maxrss keeps the parent's)
            rss = int(status.split("VmHWM:")[1].split()[0]) * 1024
            out[p.name + " " + name] = (what, time.perf_counter() - t0, rss)
    print(json.dumps(out))
    """
)


def test_decompression_and_size_bombs_are_refused_before_allocating(bombs):
    code = READ_ALL.format(limit=READ_LIMIT_BYTES)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-c", code, str(bombs)], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr[-2000:]
    results = json.loads(r.stdout)
    for key, (what, seconds, rss) in results.items():
        assert what.startswith("refused: "), (key, what)
        assert "\n" not in what and len(what) < 1000, (key, what)
        assert seconds < 10 and rss < BOMB_RSS_BYTES, (key, seconds, rss)
    refused = {k: v[0] for k, v in results.items()}
    cap = str(bounded.MAX_READ_TEXELS)
    for key in ("png_8bit_11600sq.png", "png_16bit_20000sq_header.png", "ktx2_zstd_header_11600sq.ktx2"):
        assert "11600 x 11600" in refused[key + " inspect"] or "20000 x 20000" in refused[key + " inspect"]
        assert cap in refused[key + " inspect"] and cap in refused[key + " audit"]  # the claim and the cap
    assert "65536 x 65536 x 4" in refused["npy_65536sq_x4.npy audit"]
    assert "expands to more than" in refused["ktx2_zstd_no_size_64MiB.ktx2 inspect"]
    for command, need in (("inspect", "4.0 GiB"), ("audit", "54.0 GiB")):  # refused by the memory budget
        line = refused[f"ktx2_zstd_cap_8192x16384.ktx2 {command}"]
        assert "8192 x 16384 x 4" in line and f"{command} would need about {need}" in line, line
    print(
        "largest memory", max(v[2] for v in results.values()) >> 20, "MiB; longest", max(v[1] for v in results.values())
    )


# ------------------------------------------------------------------------------- 5: linear-time parsing


def test_c_header_of_repeated_declarations_is_parsed_in_linear_time(tmp_path):
    h = tmp_path / "a.h"
    h.write_text("// x\n" + "static const float a[" * 20_000)  # 420 KB: 6.3 s with the quadratic pattern
    t0 = time.perf_counter()
    with pytest.raises(ReadError):
        read(h)
    assert time.perf_counter() - t0 < LINEAR_S


@pytest.mark.parametrize(
    "body",
    ["=" * 200_000, "/*" * 100_000, "x = {" * 40_000, "( " * 100_000, "/*x*/" * 40_000],
    ids=["equals", "open_comments", "open_braces", "open_parens", "comments"],
)
def test_text_arrays_are_parsed_in_linear_time(body):
    t0 = time.perf_counter()
    with pytest.raises(ValueError):
        parse_text_array(body, (2, 2, 1))
    assert time.perf_counter() - t0 < LINEAR_S


def test_text_files_past_the_size_cap_are_refused_unread(tmp_path, monkeypatch):
    h = tmp_path / "big.h"
    h.write_text("// " + "x" * 5000)
    monkeypatch.setattr(bounded, "MAX_TEXT_BYTES", 4096)
    with pytest.raises(ValueError, match="at most 4096 bytes"):
        bounded.read_text(h, bounded.MAX_TEXT_BYTES)


# ---------------------------------------------------------------- 6, 7: strings and tracebacks from files


def _npy_with_sidecar(d: Path, **attrs) -> Path:
    from lutbake.axes import Axis
    from lutbake.io.formats import write_table
    from lutbake.table import Table

    axes = [Axis("perceptual_roughness", "y", 4, 0.0, 1.0), Axis("NoV", "x", 4, 0.0, 1.0)]
    t = Table(
        "t", "dfg", np.full((4, 4, 2), 0.5, np.float32), axes, {"scale": "s", "bias": "b"}, "see docs", {"terms": "{}"}
    )
    path = write_table(t, d, "npy")
    side = d / "t.npy.json"
    doc = json.loads(side.read_text())
    doc["lutbake"].update(attrs)
    side.write_text(json.dumps(doc))
    return path


def test_a_long_or_control_string_in_a_sidecar_previews_fast_without_glyph_warnings(tmp_path):
    pytest.importorskip("matplotlib")
    from lutbake.commands.preview import render

    (tmp_path / "plain").mkdir()
    t0 = time.perf_counter()
    render(_npy_with_sidecar(tmp_path / "plain"), tmp_path / "plain.png")  # the same table with its own strings
    plain = time.perf_counter() - t0
    path = _npy_with_sidecar(tmp_path, kind="dfg\x1b[2J\x07" + "k" * (1 << 20), table="$\\frac{$ " + "t\x01" * 1000)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # matplotlib's "Glyph 27 missing from font" is a UserWarning
        out = render(path, tmp_path / "p.png")  # "$\frac{$" drawn as text, not parsed as a formula
    assert out.is_file() and time.perf_counter() - t0 < 3 * plain + 2  # before: 1 MiB took over 120 s
    r = CliRunner().invoke(main, ["inspect", str(path)])
    assert "\x1b" not in r.output and max(map(len, r.output.splitlines())) < 5000


NESTED = "[" * 100_000 + "]" * 100_000


@pytest.mark.parametrize(
    "name, sidecar",
    [("nested", '{"lutbake": ' + NESTED + "}"), ("array", '[1, 2, {"lutbake": {}}]'), ("deep_raw", NESTED)],
    ids=["nested", "array", "deep_raw"],
)
def test_a_hostile_sidecar_is_one_line_in_inspect_preview_and_audit(tmp_path, name, sidecar):
    path = _npy_with_sidecar(tmp_path)
    (tmp_path / "t.npy.json").write_text(sidecar)
    for args in (
        ["inspect", path],
        ["preview", path, "-o", tmp_path / "p.png"],
        ["audit", path, "--preset", "default"],
    ):
        r = CliRunner().invoke(main, list(map(str, args)))
        line = one_line_error(r)
        assert "t.npy" in line, (args[0], line)


def test_a_structured_or_garbage_npy_is_one_line_in_inspect_and_audit(tmp_path, bombs):
    for name in ("npy_structured.npy", "npy_magic_then_garbage.npy", "ktx2_zstd_truncated.ktx2"):
        for args in (["inspect", bombs / name], ["audit", bombs / name, "--preset", "default"]):
            one_line_error(CliRunner().invoke(main, list(map(str, args))))


def test_set_of_5000_digits_exits_2(tmp_path):
    one_line_error(bake("--preset", "default", "--set", "samples=" + "9" * 5000, "--out-dir", tmp_path / "o"))


# -------------------------------------------------------------------------------------- 8: values cache


@pytest.fixture(scope="module")
def baked_cache(tmp_path_factory):
    """A values cache with one real entry: a tiny dfg table baked once for the module."""
    d = tmp_path_factory.mktemp("cache")
    cfg = d / "c.toml"
    cfg.write_text(SMALL.format(name="t"))
    assert bake(cfg, "--out-dir", d / "o", "--cache", d / "cache").exit_code == 0
    return d


@pytest.fixture()
def cached(baked_cache, tmp_path):
    """A copy of that cache and its output, and the command that uses it."""
    import shutil

    shutil.copytree(baked_cache, tmp_path, dirs_exist_ok=True)
    args = [tmp_path / "c.toml", "--out-dir", tmp_path / "o", "--cache", tmp_path / "cache"]
    (meta,) = (tmp_path / "cache").glob("*.json")
    return args, meta, tmp_path / "o" / "t.exr"


def _rerun(args, out):
    out.unlink()
    r = bake(*args)
    assert r.exit_code == 0, r.output
    return r


def _header(path):
    from lutbake.provenance import read_header

    return read_header(path)


def test_an_edited_cache_entry_is_a_miss(cached):
    args, meta, out = cached
    true_estimate = _header(out)["error_estimate"]
    for edit in ({"error_estimate": "1.000e-99"}, {"kind": "ltc"}):
        doc = json.loads(meta.read_text())
        doc["extra"].update(edit)
        meta.write_text(json.dumps(doc))
        _rerun(args, out)
        assert _header(out)["error_estimate"] == true_estimate and _header(out)["kind"] == "dfg"
        assert json.loads(meta.read_text())["extra"].get("error_estimate") == true_estimate  # rewritten


@pytest.mark.parametrize("what", ["fifo", "dev_zero", "nested_json"])
def test_a_cache_entry_that_is_not_its_own_regular_file_is_a_miss_without_blocking(cached, what):
    args, meta, out = cached
    data = meta.with_suffix(".npy")
    data.unlink()
    if what == "fifo":
        os.mkfifo(data)
    elif what == "dev_zero":
        data.symlink_to("/dev/zero")
    else:
        data.write_bytes(b"")
        meta.write_text(NESTED)
        (meta.parent / ("0" * 64 + ".json")).write_text(NESTED)  # prune reads every JSON of the directory
    t0 = time.perf_counter()
    _rerun(args, out)
    assert time.perf_counter() - t0 < 30 and out.is_file()


# ---------------------------------------------------------------------------------------- 9: scheduler


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:", "ucx://127.0.0.1:1", "tcp://127.0.0.1:99999"])
def test_a_malformed_or_unsupported_scheduler_address_exits_2_at_once(tmp_path, address):
    t0 = time.perf_counter()
    line = one_line_error(bake("--preset", "default", "--out-dir", tmp_path / "o", "--scheduler", address))
    assert "--scheduler" in line and time.perf_counter() - t0 < 5


def test_a_refused_scheduler_port_fails_in_about_a_second(tmp_path):
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()  # nothing listens there: the connection is refused
    t0 = time.perf_counter()
    line = one_line_error(
        bake("--preset", "default", "--out-dir", tmp_path / "o", "--scheduler", f"tcp://127.0.0.1:{port}")
    )
    assert "refused" in line and time.perf_counter() - t0 < 5


def test_a_scheduler_port_that_accepts_and_never_answers_is_bounded(tmp_path, monkeypatch):
    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT_S", 0.5)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(4)  # the kernel accepts the connection; nothing ever writes
        port = s.getsockname()[1]
        t0 = time.perf_counter()
        r = bake("--preset", "default", "--out-dir", tmp_path / "o", "--scheduler", f"tcp://127.0.0.1:{port}")
        line = one_line_error(r)
    assert "no Dask handshake within 0.5 s" in line and time.perf_counter() - t0 < 5


# ------------------------------------------------------------------------------- 10: paths and messages


def test_tolerance_zero_leaks_no_numpy_warning(tmp_path):
    """A tolerance of 0 no estimate meets (but an exact one): every texel over it, said as such (the ratio inf), with
    no numpy warning on the way; exit 1, or 0 where the config accepts it."""
    cfg = tmp_path / "c.toml"
    for accept, code in (("", 1), ("accept_over_tolerance = true\n", 0)):
        cfg.write_text(SMALL.format(name="t").replace("samples = 48", accept + "tolerance = 0"))
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            r = bake(cfg, "--out-dir", tmp_path / "o", "--force")
        assert r.exit_code == code and "RuntimeWarning" not in r.output, r.output
        assert "OVER TOLERANCE t:" in r.output and "worst estimate / tolerance inf" in r.output, r.output


def test_a_config_with_a_utf8_bom_is_read(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_bytes(b"\xef\xbb\xbf" + SMALL.format(name="t").encode())
    from lutbake.config import load_configs

    assert [s.name for s in load_configs([cfg])] == ["t"]


def test_a_10000_character_name_is_echoed_cut(tmp_path):
    for args in (["--preset", "p" * 10_000], [tmp_path / ("d" * 200) / ("c" * 10_000)]):
        line = one_line_error(bake(*args, "--out-dir", tmp_path / "o"))
        assert len(line) < 2100


@pytest.mark.parametrize("make", ["fifo", "dir"])
def test_audit_says_what_a_fifo_or_a_directory_is(tmp_path, make):
    p = tmp_path / "x.npy"
    os.mkfifo(p) if make == "fifo" else p.mkdir()
    line = one_line_error(CliRunner().invoke(main, ["audit", str(p), "--preset", "default"]))
    assert ("FIFO" if make == "fifo" else "directory") in line and "no such file" not in line


@pytest.mark.parametrize("item", ['samples=48\nkind="ltc"', ".samples=64", "samples=48 # x\nseed=3"])
def test_set_refuses_trailing_text_and_an_empty_table_name(tmp_path, item):
    line = one_line_error(bake("--preset", "default", "--set", item, "--out-dir", tmp_path / "o"))
    assert "--set" in line


# ------------------------------------------------------ readers again: EXR headers, text arrays, sidecars, memory


def _exr_end_of_header(blob: bytes) -> int:
    pos = 8
    while blob[pos] != 0:
        type_end = blob.index(b"\0", blob.index(b"\0", pos) + 1)
        pos = type_end + 5 + struct.unpack_from("<i", blob, type_end + 1)[0]
    return pos


def _exr_with_attributes(path: Path, count: int) -> Path:
    """A 4 x 4 RG EXR (no compression: one scanline per chunk) whose header gains ``count`` int attributes; the
    offset table after the header is moved by the bytes inserted."""
    oiio = pytest.importorskip("OpenImageIO")
    spec = oiio.ImageSpec(4, 4, 2, "float")
    spec.channelnames = ("R", "G")
    spec.attribute("compression", "none")
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec) and out.write_image(np.zeros((4, 4, 2), np.float32)) and out.close()
    blob = bytearray(path.read_bytes())
    end = _exr_end_of_header(blob)
    extra = b"".join(b"a%05d\0int\0" % k + struct.pack("<ii", 4, k) for k in range(count))
    offsets = struct.unpack_from("<4Q", blob, end + 1)
    struct.pack_into("<4Q", blob, end + 1, *(o + len(extra) for o in offsets))
    blob[end:end] = extra
    path.write_bytes(bytes(blob))
    return path


def _commands(path: Path, out: Path):
    return (["inspect", path], ["preview", path, "-o", out], ["audit", path, "--preset", "default"])


def test_an_exr_header_of_40000_attributes_is_refused_before_openimageio_parses_it(tmp_path):
    assert read(_exr_with_attributes(tmp_path / "ok.exr", 100)).data.shape == (4, 4, 2)  # a long header still reads
    path = _exr_with_attributes(tmp_path / "a.exr", 40_000)  # 760 KB; OpenImageIO: 8 s (10 000: 0.7 s)
    for args in _commands(path, tmp_path / "p.png"):
        t0 = time.perf_counter()
        line = one_line_error(CliRunner().invoke(main, list(map(str, args))))
        assert time.perf_counter() - t0 < LINEAR_S, args[0]  # preview: importing matplotlib too
        assert f"more than {bounded.MAX_EXR_ATTRIBUTES} attributes" in line and "a.exr" in line, line


def _c_header(path: Path, body: str, shape=(2, 2, 1), ctype="float") -> Path:
    h, w, c = shape
    path.write_text(
        f"// t\n#define T_HEIGHT {h}\n#define T_WIDTH {w}\n#define T_CHANNELS {c}\n"
        f"static const {ctype} t[{h * w * c}] = {{ {body} }};\n"
    )
    return path


def test_c99_hex_floats_are_read_as_floats_by_inspect_and_audit(tmp_path):
    from lutbake.io.lut_files import read_lut

    path = _c_header(tmp_path / "t.h", "0x1.0p-1, 0x1.8p+0, -0x1p-2, 0x0p+0")  # printf("%a")
    want = [0.5, 1.5, -0.25, 0.0]
    assert read(path).data.ravel().tolist() == want  # inspect refused the file
    lut = read_lut(path)
    assert lut.data.ravel().tolist() == want and lut.storage == "float32"  # audit: half bits 0x1, 0x1, ... (6e-8)
    bits = read_lut(_c_header(tmp_path / "b.h", "0x3c00, 0x3800, 0xb400, 0x0000", ctype="uint16_t"))
    assert bits.data.ravel().tolist() == [1.0, 0.5, -0.25, 0.0] and bits.storage == "half"


@pytest.mark.parametrize("values", [4 + 1000, 3], ids=["1000_more", "one_fewer"])
def test_a_text_array_with_other_than_its_declared_count_is_refused(tmp_path, values):
    path = _c_header(tmp_path / "t.h", ", ".join(["0.5"] * min(values, 4) + ["9.0"] * (values - 4)))
    for args in (["inspect", path], ["audit", path, "--preset", "default"]):
        line = one_line_error(CliRunner().invoke(main, list(map(str, args))))
        assert f"holds {values} values" in line and "needs 4" in line, line


def _edit_sidecar(path: Path, edit) -> None:
    side = path.with_name(path.name + ".json")
    doc = json.loads(side.read_text())
    edit(doc["lutbake"])
    side.write_text(json.dumps(doc))  # "\ud800" is written as the JSON escape \\ud800: valid JSON, no text


def _set_json(attrs, key, edit):
    value = json.loads(attrs[key])
    edit(value)
    attrs[key] = json.dumps(value)


SIDECAR_EDITS = {
    "kind": lambda a: a.update(kind="\ud800"),
    "table": lambda a: a.update(table="t\ud800"),
    "axis_name": lambda a: _set_json(a, "axes", lambda axes: axes[0].update(name="\ud800")),
    "channel_name": lambda a: _set_json(a, "channel_names", lambda c: c.update(R="\udfff")),
    "range_10e400": lambda a: _set_json(a, "axes", lambda axes: axes[0].update(range=[0, 10**400])),
    "count_5001_digits": lambda a: a.update(axes=a["axes"].replace('"count": 4', '"count": ' + "9" * 5001, 1)),
}


@pytest.mark.parametrize("edit", SIDECAR_EDITS, ids=list(SIDECAR_EDITS))
def test_a_valid_json_sidecar_with_no_text_or_no_number_is_one_line(tmp_path, edit):
    path = _npy_with_sidecar(tmp_path)
    _edit_sidecar(path, SIDECAR_EDITS[edit])
    for args in _commands(path, tmp_path / "p.png")[:2]:
        line = one_line_error(CliRunner().invoke(main, list(map(str, args))))
        assert "t.npy" in line and ("surrogate" in line or "range" in line or "4300 digits" in line), line


def test_preview_of_an_rgba_z_exr_draws_rgba_and_says_so(tmp_path):
    oiio = pytest.importorskip("OpenImageIO")
    pytest.importorskip("matplotlib")
    path = tmp_path / "render.exr"
    spec = oiio.ImageSpec(8, 4, 5, "float")
    spec.channelnames = ("R", "G", "B", "A", "Z")
    out = oiio.ImageOutput.create(str(path))
    pixels = np.arange(8 * 4 * 5, dtype=np.float32).reshape(4, 8, 5)
    assert out.open(str(path), spec) and out.write_image(pixels) and out.close()
    loaded = read(path)
    assert loaded.facts["channels"] == ["R", "G", "B", "A", "Z"]
    np.testing.assert_array_equal(loaded.data, pixels)
    r = CliRunner().invoke(main, ["preview", str(path), "-o", str(tmp_path / "p.png")])
    assert r.exit_code == 0 and r.exception is None, r.output  # was IndexError
    from lutbake.commands.preview import figure

    fig = figure(path)
    assert "5 channels: the first 4 are drawn, not channel Z" in fig._suptitle.get_text()


def test_preview_of_a_table_holding_nan_and_inf_masks_them_without_warnings(tmp_path):
    pytest.importorskip("matplotlib")
    from lutbake.commands.preview import figure

    path = _npy_with_sidecar(tmp_path)
    data = np.full((4, 4, 2), 0.5, np.float32)
    data[0, 0, 0], data[1, 2, 1], data[3, 3, 0] = np.nan, np.inf, -np.inf
    np.save(path, data)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's RuntimeWarnings (invalid value, All-NaN slice) named library paths
        fig = figure(path)
        fig.savefig(tmp_path / "p.png")
    assert "3 non-finite values (NaN/Inf) of 32 masked" in fig._suptitle.get_text()


def test_a_file_at_the_texel_cap_is_refused_by_the_memory_budget_in_one_line(tmp_path, bombs):
    path = bombs / "ktx2_zstd_cap_8192x16384.ktx2"
    for args in _commands(path, tmp_path / "p.png"):
        line = one_line_error(CliRunner().invoke(main, list(map(str, args))))
        assert path.name in line and "8192 x 16384 x 4" in line and "GiB" in line and "budget" not in line, line
        assert f"{args[0]} would need about" in line, line


def test_text_array_numbers_are_parsed_in_bulk_without_an_object_per_number(tmp_path):
    import tracemalloc

    n = 1 << 20
    path = _c_header(tmp_path / "big.h", ", ".join(["0.25f"] * n), shape=(256, 1024, 4))  # 7 MB of text
    text = path.read_text()
    tracemalloc.start()
    try:
        t0 = time.perf_counter()
        arr, storage = parse_text_array(text)
        seconds = time.perf_counter() - t0
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert arr.shape == (256, 1024, 4) and float(arr.min()) == float(arr.max()) == 0.25 and storage == "float32"
    # a str and a float per number: over 100 MB and 2 s; in bulk: the text's copies and the float64 values
    assert peak < 6 * len(text) + 2 * 8 * n and seconds < LINEAR_S, (peak >> 20, seconds)
