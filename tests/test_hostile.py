"""Hostile configs (issue 7), property-based: random keys, wrong types, bad sizes, unicode and
path-traversal names, huge sizes, zero/negative/huge samples, NaN/Inf values, duplicate names,
conflicting options, hostile --set overrides and garbage documents.

Each must raise a ConfigError naming the file and the key, and through the CLI exit with status 2,
print no traceback and write nothing."""

import functools
import json
import math
import os
import re
import tempfile
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from lutbake.cli import main
from lutbake.config import MAX_TEXELS, NAME_RE, load_configs
from lutbake.errors import ConfigError
from lutbake.kinds import KINDS, lookup_kind
from lutbake.limits import MAX_SAMPLES
from lutbake.textsafe import safe_repr

KEYS = KINDS["dfg"].keys

# In CI (CI set) the examples are derandomized: the same inputs every run, so a landing never hinges on a
# random draw; locally hypothesis explores new inputs each run.
SETTINGS = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=bool(os.environ.get("CI"))
)
BASE = {"name": "ok", "kind": "dfg", "size": [8, 4], "samples": 48}
UNSAFE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f]")  # no terminal control character reaches the user


# ----------------------------------------------------------------------------------- TOML writing


def tv(v) -> str:
    """A TOML value for any JSON-like Python value (nan/inf too; strings escaped)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(v, list):
        return "[" + ", ".join(tv(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{tv(str(k))} = {tv(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def toml_tables(*tables) -> str:
    return "".join("[[table]]\n" + "".join(f"{tv(k)} = {tv(v)}\n" for k, v in t.items()) + "\n" for t in tables)


# ------------------------------------------------------------------------------------- the check


def assert_rejected(text: str | bytes, key: str | None, fragment: str | None = None, overrides=(), extra=None):
    """``text`` as a config file: ConfigError naming the file and the key; CLI exit 2, nothing written."""
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        cfg = d / "hostile.toml"
        cfg.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
        files = [cfg]
        if extra is not None:
            (d / "other.toml").write_text(extra, encoding="utf-8")
            files.append(d / "other.toml")
        with pytest.raises(ConfigError) as e:
            load_configs(files, overrides)
        msg = str(e.value)
        named = [str(f) for f in files] + ["--set"]
        assert any(n in msg for n in named), msg
        if key is not None:
            assert safe_repr(key) in msg, msg
        if fragment is not None:
            assert fragment in msg, msg
        args = ["bake", *map(str, files), "--out-dir", str(d / "out"), "--report", str(d / "r.json")]
        for o in overrides:
            args += ["--set", o]
        r = CliRunner().invoke(main, args)
        assert r.exit_code == 2, (r.exit_code, r.output)
        assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
        assert "Traceback" not in r.output
        assert not UNSAFE.search(r.output), repr(r.output)  # keys and values are printed escaped (issue 11)
        assert "error:" in r.output and (key is None or safe_repr(key) in r.output)
        assert sorted(p.name for p in d.iterdir()) == sorted(f.name for f in files)  # nothing written


def with_key(key, value, **more):
    return toml_tables({**BASE, key: value, **more})


# ---------------------------------------------------------------------------------- value sources

scalars = st.one_of(
    st.booleans(), st.integers(-(2**70), 2**70), st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12)
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=5), inner, max_size=3)),
    max_leaves=6,
)


def bad_for(key):
    """Values of ``key`` that are always invalid."""
    k = KEYS[key]
    not_str = st.one_of(
        st.booleans(),
        st.integers(),
        st.floats(),
        st.lists(scalars, max_size=3),
        st.dictionaries(st.text(max_size=4), scalars, max_size=2),
    )
    if k.type in ("str", "name"):
        if k.type == "name":
            return st.one_of(not_str, st.text(max_size=140).filter(lambda s: not NAME_RE.fullmatch(s)))
        return st.one_of(not_str, st.text(max_size=20).filter(lambda s: s not in k.choices and s != "split_sum"))
    if k.type == "int":
        hi = int(k.maximum) if k.maximum is not None else 2**64
        return st.one_of(
            st.floats(),
            st.text(max_size=8),
            st.booleans(),
            st.lists(st.integers(1, 9), max_size=2),
            st.integers(max_value=int(k.minimum) - 1),
            st.integers(min_value=hi + 1, max_value=hi * 4),
        )
    if k.type == "int_pair":
        return st.one_of(
            st.integers(),
            st.text(max_size=6),
            st.floats(),
            st.lists(st.integers(1, 64), max_size=5).filter(lambda v: len(v) != 2),
            st.tuples(st.integers(max_value=0), st.integers(1, 64)).map(list),
            st.tuples(st.integers(1, 64), st.integers(max_value=0)).map(list),
            st.tuples(st.floats(), st.integers(1, 9)).map(list),
            st.tuples(st.integers(1, 9), st.one_of(st.text(max_size=3), st.booleans())).map(list),
        )
    if k.type == "float_range":
        unit = st.floats(0.0, 1.0)
        return st.one_of(
            st.integers(),
            st.text(max_size=6),
            st.booleans(),
            st.lists(unit, max_size=4).filter(lambda v: len(v) != 2),
            st.tuples(st.floats(allow_nan=True, allow_infinity=True).filter(lambda x: not math.isfinite(x)), unit).map(
                list
            ),
            st.tuples(unit, st.sampled_from([math.nan, math.inf, -math.inf])).map(list),
            st.tuples(unit, unit).filter(lambda v: v[0] > v[1]).map(list),
            st.tuples(st.floats(max_value=-1e-9, allow_nan=False, allow_infinity=False), unit).map(list),
            st.tuples(unit, st.floats(min_value=1.0000001, allow_nan=False, allow_infinity=False)).map(list),
            st.tuples(unit, st.text(max_size=3)).map(list),
        )
    if k.type == "bool":  # TOML's true / false only: 0, 1, "true" are not booleans
        return st.one_of(st.integers(), st.floats(), st.text(max_size=6), st.lists(scalars, max_size=3))
    if k.type == "float":
        return st.one_of(
            st.text(max_size=6),
            st.booleans(),
            st.lists(st.floats(0.0, 1.0), max_size=3),
            st.floats(allow_nan=True, allow_infinity=True).filter(lambda x: not math.isfinite(x)),
            st.floats(max_value=k.minimum, exclude_max=True, allow_nan=False, allow_infinity=False),
            st.floats(min_value=k.maximum, exclude_min=True, allow_nan=False, allow_infinity=False),
        )
    raise AssertionError(key)


# -------------------------------------------------------------------------------------------- tests


@SETTINGS
@given(key=st.text(min_size=1, max_size=24).filter(lambda k: k not in KEYS), value=values)
@example(key="path", value="../../etc/passwd")
@example(key="名前", value="ℌ")
@example(key="out", value={"dir": "/tmp"})
def test_random_unknown_keys(key, value):
    assert_rejected(with_key(key, value), key, "not a key")


@SETTINGS
@given(data=st.data(), key=st.sampled_from([k for k in KEYS if k != "kind"]))
def test_wrong_types_and_values_for_every_key(data, key):
    value = data.draw(bad_for(key), label="value")
    assert_rejected(with_key(key, value), key)


def is_kind(name: str) -> bool:
    """A registered kind or alias (hypothesis also draws the string constants of the code under test, such
    as "diffuse": a real kind is not a bad one)."""
    try:
        lookup_kind(name)
    except KeyError:
        return False
    return True


@SETTINGS
@given(
    value=st.one_of(
        st.text(max_size=8).filter(lambda s: not is_kind(s)),
        st.integers(),
        st.lists(st.text(max_size=3), max_size=2),
    )
)
def test_bad_kind(value):
    assert_rejected(with_key("kind", value), "kind")


@SETTINGS
@given(
    name=st.one_of(
        st.text(max_size=140),
        st.sampled_from(
            [
                "../../x",
                "..",
                "../x",
                "/etc/passwd",
                "a/b",
                "a\\b",
                "C:\\x",
                "x.exr",
                "",
                " ",
                "x" * 129,
                "ｄｆｇ",
                "名前",
                "dfg\x00",
                "dfg\n",
                "é",
                "🙂",
                "-" * 129,
            ]
        ),
    ).filter(lambda s: not NAME_RE.fullmatch(s))
)
def test_unicode_and_path_traversal_names(name):
    assert_rejected(with_key("name", name), "name", "letters")


@SETTINGS
@given(
    size=st.tuples(st.integers(1, 10**30), st.integers(1, 10**30)).filter(lambda s: s[0] * s[1] > MAX_TEXELS).map(list)
)
@example(size=[100000, 100000])
@example(size=[2**26, 2])
@example(size=[10**200, 10**200])
def test_huge_sizes_are_refused_with_the_memory_they_would_take(size):
    assert_rejected(with_key("size", size), "size", "of memory")
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "c.toml"
        p.write_text(with_key("size", size))
        with pytest.raises(ConfigError, match=r"would need (about )?(~2\^\d+ B|[\d.]+ [KMGTPE]iB) of memory"):
            load_configs([p])


@SETTINGS
@given(samples=st.one_of(st.integers(max_value=0), st.integers(MAX_SAMPLES + 1, 2**80)))
@example(samples=0)
@example(samples=-1)
def test_zero_negative_and_huge_samples(samples):
    assert_rejected(with_key("samples", samples), "samples")


@SETTINGS
@given(
    key=st.sampled_from(["nov_range", "roughness_range"]),
    rng=st.tuples(
        st.sampled_from([0.0, 0.5, math.nan, math.inf, -math.inf]),
        st.sampled_from([1.0, math.nan, math.inf, -math.inf]),
    )
    .filter(lambda r: not all(map(math.isfinite, r)))
    .map(list),
)
def test_nan_and_inf_in_ranges(key, rng):
    assert_rejected(with_key(key, rng), key, "finite")


@SETTINGS
@given(value=st.sampled_from([math.nan, math.inf, -math.inf]), key=st.sampled_from(["samples", "seed", "size"]))
def test_nan_and_inf_where_integers_belong(value, key):
    assert_rejected(with_key(key, [value, 4] if key == "size" else value), key)


@SETTINGS
@given(name=st.from_regex(r"[A-Za-z0-9_-]{1,16}", fullmatch=True), across=st.booleans())
def test_duplicate_table_names(name, across):
    t = {**BASE, "name": name}
    if across:
        assert_rejected(toml_tables(t), "name", "duplicate", extra=toml_tables(t))
    else:
        assert_rejected(toml_tables(t, {**t, "layout": "multiscatter"}), "name", "duplicate")


@pytest.mark.parametrize(
    "opts, key, fragment",
    [
        ({"estimator": "sobol_vndf", "ndf": "beckmann"}, "estimator", "visible-normal"),
    ],
)
def test_conflicting_options(opts, key, fragment):
    assert_rejected(toml_tables({**BASE, **opts}), key, fragment)
    assert_rejected(toml_tables({**BASE, "ndf": "beckmann"}), key, fragment, overrides=["estimator=sobol_vndf"])


@SETTINGS
@given(
    override=st.sampled_from(
        [
            "size=[0,0]",
            "size=[100000,100000]",
            "name=../../x",
            "nov_range=[nan, 1.0]",
            "roughness_range=[0.0, inf]",
            "samples=inf",
            "samples=-3",
            "samples=0",
            "seed=-1",
            "nosuch=1",
            "ghost.samples=3",
            "=1",
            "ok.=1",
            "ndf=phong",
            "dtype=float16",
            "kind=nope",
            'size="big"',
            "layout=[1,2]",
            "estimator=sobol_vndf",
        ]
    )
    | st.builds(
        "{}={}".format,
        st.text(max_size=8).filter(lambda k: "=" not in k and "." not in k and k.strip() == k and k not in KEYS),
        st.text(max_size=8),
    )
)
def test_hostile_set_overrides(override):
    base = toml_tables({**BASE, "ndf": "beckmann"})
    key = override.split("=", 1)[0].rpartition(".")[2] if "=" in override else override
    if override.startswith("ghost."):
        key = "ghost"
    if override.startswith("estimator="):
        key = "estimator"
    assert_rejected(base, key, overrides=[override])


@SETTINGS
@given(doc=st.dictionaries(st.text(min_size=1, max_size=8), values, max_size=3))
@example(doc={})
@example(doc={"table": 5})
@example(doc={"table": []})
@example(doc={"table": [1, 2]})
@example(doc={"table": ["x"]})
def test_garbage_documents(doc):
    text = "".join(f"{tv(k)} = {tv(v)}\n" for k, v in doc.items())
    extra = sorted(doc.keys() - {"table"})
    tables = doc.get("table")
    if extra:
        key = extra[0]
    elif isinstance(tables, list) and tables and isinstance(tables[0], dict):
        key = None  # an array of inline tables: the first one's own error (e.g. 'kind' is missing)
    else:
        key = "table"
    assert_rejected(text, key)


@SETTINGS
@given(raw=st.binary(max_size=64))
@example(raw=b"\xff\xfe\x00")
@example(raw=b"[[table]\nname=")
@example(raw=b"[[table]]\nname = 'a'\n[[table]]\n[table.x]\ny = 1\n")
def test_binary_and_broken_toml(raw):
    assert_rejected(raw, None)


def test_missing_directory_and_unreadable_configs(tmp_path):
    r = CliRunner().invoke(main, ["bake", str(tmp_path), "--out-dir", str(tmp_path / "o")])
    assert r.exit_code == 2 and "is a directory, not a config file" in r.output and not (tmp_path / "o").exists()
    f = tmp_path / "file"
    f.write_text("")
    cfg = tmp_path / "c.toml"
    cfg.write_text(toml_tables(BASE))
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(f)])
    assert r.exit_code == 2 and "not a directory" in r.output and "Traceback" not in r.output


# ------------------------------------------------------------ issue 11: more hostile inputs, counted

SIZE_KEYS = {kind: [k for k in KINDS[kind].keys if k == "size" or k.endswith("_size")] for kind in KINDS}
CONTROL = st.characters(categories=["Cc", "Cf", "Zl", "Zp"], exclude_characters="\x00")


@SETTINGS
@given(
    depth=st.integers(1_000, 100_000),
    how=st.sampled_from(["array", "inline_table", "dotted", "dotted_in_table", "set", "set_closed"]),
)
@example(depth=100_000, how="array")
@example(depth=50_000, how="inline_table")
@example(depth=20_000, how="dotted")
@example(depth=20_000, how="dotted_in_table")
@example(depth=60_000, how="set")
def test_deep_nesting_is_a_config_error(depth, how):
    """RecursionError in the TOML parser or in printing the value: a ConfigError, exit 2."""
    if how in ("set", "set_closed"):
        value = "[" * depth + ("]" * depth if how == "set_closed" else "")
        assert_rejected(toml_tables(BASE), None, overrides=["size=" + value])
        return
    text = {
        "array": "x = " + "[" * depth + "]" * depth + "\n",
        "inline_table": "x = " + "{a = " * depth + "1" + "}" * depth + "\n",
        "dotted": ".".join(["k"] * depth) + " = 1\n",
        "dotted_in_table": toml_tables(BASE) + ".".join(["k"] * depth) + " = 1\n",
    }[how]
    assert_rejected(text, None)


@SETTINGS
@given(
    name=st.from_regex(r"[A-Za-z0-9_-]{1,16}", fullmatch=True),
    tail=st.sampled_from(["\n", "\r\n", "\r", " ", "\t", "\u2028", "\x1b[2J", "\u202e"]),
)
@example(name="t", tail="\n")
def test_a_valid_name_with_a_trailing_character_is_refused(name, tail):
    assert_rejected(with_key("name", name + tail), "name", "letters")


@SETTINGS
@given(data=st.data(), kind=st.sampled_from(sorted(KINDS)))
@example(data=None, kind="albedo_avg")
def test_every_size_key_is_under_the_one_texel_cap(data, kind):
    """Any size key (size, roughness_size, f0_size, phi_size ...) pushing the texel count over MAX_TEXELS is
    refused at load, naming a size key and the memory it would take."""
    keys = SIZE_KEYS[kind]
    key = data.draw(st.sampled_from(keys), label="key") if data is not None else "roughness_size"
    k = KINDS[kind].keys[key]
    raw = {"name": "t", "kind": kind}
    if k.type == "int_pair":
        raw[key] = (
            [MAX_TEXELS + 1, 1]
            if data is None
            else data.draw(
                st.tuples(*[st.integers(int(k.minimum or 1), 10**12)] * 2)  # ltc's sizes start at 2
                .filter(lambda s: s[0] * s[1] > MAX_TEXELS)
                .map(list),
                label="value",
            )
        )
    elif k.maximum is None:
        raw[key] = 10**12 if data is None else data.draw(st.integers(MAX_TEXELS + 1, 2**62), label="value")
    else:  # a capped slice count: over the cap together with a big size
        raw[key] = int(k.maximum)
        if "size" in KINDS[kind].keys:
            raw["size"] = [8192, 8192]
        else:  # another size key without a maximum carries the rest (dielectric_avg: roughness_size)
            other = next(o for o in keys if o != key and KINDS[kind].keys[o].maximum is None)
            raw[other] = MAX_TEXELS
    text = toml_tables(raw)
    assert_rejected(text, None, "of memory")
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "c.toml"
        p.write_text(text)
        with pytest.raises(ConfigError) as e:
            load_configs([p])
        assert e.value.key in keys, str(e.value)


@SETTINGS
@given(payload=st.text(CONTROL, min_size=1, max_size=12), where=st.sampled_from(["key", "ndf", "name", "set_key"]))
@example(payload="\u001b]0;PWNED\u0007\u001b[2J", where="key")
@example(payload="\u001b]0;PWNED\u0007\u001b[2J", where="ndf")
def test_escape_sequences_are_printed_escaped(payload, where):
    if where == "key":
        assert_rejected(with_key(payload, 1), payload)
    elif where == "set_key":
        # --set strips the key as str.strip does (some control characters count as white space)
        assert_rejected(toml_tables(BASE), payload.strip(), overrides=[f"{payload}=1"])
    else:
        assert_rejected(with_key(where, "x" + payload), where)


FORMAT_EXT = {"exr": ".exr", "npy": ".npy", "png16": ".png", "dds": ".dds", "ktx2": ".ktx2", "h": ".h"}


@SETTINGS
@given(
    fmt=st.sampled_from(sorted(FORMAT_EXT)),
    sidecar=st.booleans(),
    name=st.from_regex(r"[A-Za-z0-9_-]{1,12}", fullmatch=True),
)
def test_a_report_over_an_output_or_its_sidecar_is_refused(fmt, sidecar, name):
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        cfg = d / "c.toml"
        cfg.write_text(toml_tables({**BASE, "name": name, "format": fmt}))
        target = d / "out" / (name + FORMAT_EXT[fmt] + (".json" if sidecar else ""))
        r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(d / "out"), "--report", str(target)])
        assert r.exit_code == 2 and "--report" in r.output and "Traceback" not in r.output, r.output
        assert sorted(p.name for p in d.iterdir()) == ["c.toml"]


def _catalogue():
    """Issue 11's hostile inputs, one per line: (id, config text or a path maker, extra CLI args, exit)."""
    deep = {
        "array-100000": "x = " + "[" * 100_000 + "]" * 100_000 + "\n",
        "inline-50000": "x = " + "{a = " * 50_000 + "1" + "}" * 50_000 + "\n",
        "dotted-20000": ".".join(["k"] * 20_000) + " = 1\n",
    }
    cases = [(k, v, [], 2) for k, v in deep.items()]
    cases += [
        ("set-60000", toml_tables(BASE), ["--set", "size=" + "[" * 60_000], 2),
        ("name-newline", with_key("name", "t\n"), [], 2),
        (
            "albedo_avg-roughness_size-1e12",
            toml_tables({"name": "t", "kind": "albedo_avg", "roughness_size": 10**12}),
            [],
            2,
        ),
        (
            "albedo_avg-roughness_size-1e8",
            toml_tables({"name": "t", "kind": "albedo_avg", "roughness_size": 10**8}),
            [],
            2,
        ),
        ("png16-charlie", toml_tables({**BASE, "layout": "charlie", "format": "png16"}), [], 2),
        ("png16-blinn_phong", toml_tables({**BASE, "model": "blinn_phong"}), ["--format", "png16"], 2),
        ("escape-key", with_key("\u001b]0;PWNED\u0007\u001b[2J", 1), [], 2),
        ("escape-value", with_key("ndf", "\u001b]0;PWNED\u0007\u001b[2J"), [], 2),
        ("escape-set", toml_tables(BASE), ["--set", "\u001b[2J=1"], 2),
    ]
    for fmt, ext in FORMAT_EXT.items():
        cases.append(
            (f"report-is-output-{fmt}", toml_tables({**BASE, "format": fmt}), ["--report", "{out}/ok" + ext], 2)
        )
        cases.append(
            (
                f"report-is-sidecar-{fmt}",
                toml_tables({**BASE, "format": fmt}),
                ["--report", "{out}/ok" + ext + ".json"],
                2,
            )
        )
    cases += [
        ("report-is-config", toml_tables(BASE), ["--report", "{cfg}"], 2),
        ("report-under-file", toml_tables(BASE), ["--report", "{cfg}/r.json"], 2),
        ("out-dir-under-file", toml_tables(BASE), ["--out-dir", "{cfg}/o"], 2),
        ("out-dir-dangling-symlink", toml_tables(BASE), ["--out-dir", "{dangling}"], 2),
        ("config-is-directory", "{dir}", [], 2, "is a directory, not a config file"),
        ("config-is-fifo", "{fifo}", [], 2, "is a FIFO (named pipe), not a config file"),
        ("config-is-dev-zero", "/dev/zero", [], 2, "is a character device, not a config file"),
    ]
    return cases


CATALOGUE = _catalogue()


def run_catalogue_case(case) -> tuple[bool, str]:
    """(handled cleanly, why not): the expected exit, no traceback, no control character, nothing written."""
    cid, text, args, want, *fragment = case  # fragment: the words the message must say, where given
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        cfg = d / "c.toml"
        if text == "{dir}":
            cfg.mkdir()
        elif text == "{fifo}":
            os.mkfifo(cfg)
        elif text.startswith("/dev/"):
            cfg = Path(text)
        else:
            cfg.write_text(text, encoding="utf-8")
        (d / "dangling").symlink_to(d / "gone")
        subst = {"{out}": str(d / "out"), "{cfg}": str(cfg), "{dangling}": str(d / "dangling")}
        args = [functools.reduce(lambda a, kv: a.replace(*kv), subst.items(), a) for a in args]
        if "--out-dir" not in args:
            args += ["--out-dir", str(d / "out")]
        before = sorted(p.name for p in d.iterdir())
        r = CliRunner().invoke(main, ["bake", str(cfg), *args])
        problems = []
        if r.exit_code != want:
            problems.append(f"exit {r.exit_code}")
        if "Traceback" in r.output or (r.exception is not None and not isinstance(r.exception, SystemExit)):
            problems.append(f"traceback {r.exception!r}")
        if UNSAFE.search(r.output):
            problems.append("control characters printed")
        if sorted(p.name for p in d.iterdir()) != before:
            problems.append("wrote files")
        if fragment and fragment[0] not in r.output:
            problems.append(f"does not say {fragment[0]!r}")
        return not problems, f"{cid}: {', '.join(problems)}: {r.output[:300]!r}"


@pytest.mark.parametrize("case", CATALOGUE, ids=[c[0] for c in CATALOGUE])
def test_issue11_hostile_catalogue(case):
    ok, why = run_catalogue_case(case)
    assert ok, why


if __name__ == "__main__":
    handled = 0
    for case in CATALOGUE:
        ok, why = run_catalogue_case(case)
        handled += ok
        print("ok  " if ok else "FAIL", why if not ok else case[0])
    print(f"hostile inputs handled cleanly: {handled} / {len(CATALOGUE)}")
