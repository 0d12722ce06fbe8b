"""Hostile configs (issue 7), property-based: random keys, wrong types, bad sizes, unicode and
path-traversal names, huge sizes, zero/negative/huge samples, NaN/Inf values, duplicate names,
conflicting options, hostile --set overrides and garbage documents.

Each must raise a ConfigError naming the file and the key, and through the CLI exit with status 2,
print no traceback and write nothing."""

import json
import math
import os
import tempfile
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from lutbake.cli import main
from lutbake.config import MAX_TEXELS, NAME_RE, load_configs
from lutbake.errors import ConfigError
from lutbake.tables.dfg import KEYS, MAX_SAMPLES

# In CI (CI set) the examples are derandomized: the same inputs every run, so a landing never hinges on a
# random draw; locally hypothesis explores new inputs each run.
SETTINGS = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=bool(os.environ.get("CI"))
)
BASE = {"name": "ok", "kind": "dfg", "size": [8, 4], "samples": 48}


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
            assert f"'{key}'" in msg, msg
        if fragment is not None:
            assert fragment in msg, msg
        args = ["bake", *map(str, files), "--out-dir", str(d / "out"), "--report", str(d / "r.json")]
        for o in overrides:
            args += ["--set", o]
        r = CliRunner().invoke(main, args)
        assert r.exit_code == 2, (r.exit_code, r.output)
        assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
        assert "Traceback" not in r.output
        # click's test runner reads the output in text mode: a key holding "\r\n" comes back as "\n"
        assert "error:" in r.output and (key is None or f"'{key}'".replace("\r\n", "\n") in r.output)
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
            return st.one_of(not_str, st.text(max_size=140).filter(lambda s: not NAME_RE.match(s)))
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


@SETTINGS
@given(
    value=st.one_of(
        st.text(max_size=8).filter(lambda s: s not in ("dfg", "split_sum")),
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
    ).filter(lambda s: not NAME_RE.match(s))
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
        with pytest.raises(ConfigError, match=r"would need (~2\^\d+ B|[\d.]+ [KMGTPE]iB) of memory"):
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
    assert r.exit_code == 2 and "no such config file" in r.output and not (tmp_path / "o").exists()
    f = tmp_path / "file"
    f.write_text("")
    cfg = tmp_path / "c.toml"
    cfg.write_text(toml_tables(BASE))
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(f)])
    assert r.exit_code == 2 and "not a directory" in r.output and "Traceback" not in r.output
