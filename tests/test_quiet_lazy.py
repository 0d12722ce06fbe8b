"""The commands print their own lines only (Warp's banner, CUDA-driver warning and module-load lines only
when asked), the commands that do not bake import neither Warp, SciPy nor OpenImageIO where they need not,
a bake explains a rounded sample count, `make luts` asks lutbake every time (which notices a table
overwritten with other settings), and `make figures` writes under outputs/ only."""

import json
import os
import subprocess
import sys
from pathlib import Path

from test_formats import table2d

from lutbake.io.formats import write_table

ROOT = Path(__file__).resolve().parents[1]
CONFIG = '[[table]]\nname = "small"\nkind = "dfg"\nsize = [8, 4]\nsamples = 48\n'
HEAVY = ("warp", "scipy", "OpenImageIO", "matplotlib")
MARK = "heavy modules: "  # starts the line loaded_after prints after each run


def python(code: str, env_extra=None, cwd=None) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "LUTBAKE_VERBOSE"}
    env.update(env_extra or {})
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=cwd or ROOT)


def loaded_after(*runs: list[str]) -> list[list[str]]:
    """Which heavy modules were imported after each `lutbake ARGS` run, the runs made in this order in one fresh
    interpreter: each list holds what that run and the runs before it imported, so where the lists before it are
    empty, it is what that run imports alone (one interpreter start for several runs, not one each)."""
    code = (
        "import json, sys\nfrom lutbake.cli import main\n"
        f"for args in {list(runs)!r}:\n    try:\n        main(args)\n    except SystemExit:\n        pass\n"
        f"    print('\\n' + {MARK!r} + json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    )
    r = python(code)
    assert r.returncode == 0, r.stderr
    return [json.loads(line[len(MARK) :]) for line in r.stdout.splitlines() if line.startswith(MARK)]


def test_help_and_version_import_nothing_heavy():
    assert loaded_after(["--help"], ["bake", "--help"], ["--version"]) == [[], [], []]


def test_list_and_every_commands_help_import_nothing_heavy():
    """`lutbake list` prints every kind, NDF, model and estimator from warp-free records (lutbake.records)."""
    commands = ("validate", "audit", "inspect", "preview", "size", "fit", "plot", "spheres")
    lists = (
        ["list"],
        ["list", "kinds"],
        ["list", "presets"],
        ["list", "formats"],
        ["list", "keys", "ltc"],
        ["list", "terms"],
    )
    loaded = loaded_after(*lists, *([command, "--help"] for command in commands))
    names = [" ".join(a) for a in lists] + list(commands)
    assert dict(zip(names, loaded)) == dict.fromkeys(names, [])


def test_the_kind_registry_and_config_checks_import_no_warp(tmp_path):
    """Only planning a table imports its Warp modules (lutbake.kinds.*.plan); a config loads without them."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG + 'layout = "multiscatter_disney"\nestimator = "sobol_vndf"\n')
    code = (
        f"import sys; from lutbake.config import load_configs; load_configs([{str(cfg)!r}])\n"
        f"print([m for m in {HEAVY!r} if m in sys.modules])"
    )
    r = python(code)
    assert r.returncode == 0 and r.stdout.strip() == "[]", r.stdout + r.stderr


def test_inspect_imports_only_what_the_format_needs(tmp_path):
    dds = write_table(table2d(2), tmp_path, "dds")
    exr = write_table(table2d(2), tmp_path / "e", "exr")
    js = write_table(table2d(2), tmp_path / "j", "js")  # an engine layout: values read back with its sidecar
    assert loaded_after(["inspect", str(dds)], ["inspect", str(js)], ["inspect", str(exr)]) == [[], [], ["OpenImageIO"]]


def test_preview_imports_no_warp_or_scipy(tmp_path):
    npy = write_table(table2d(2), tmp_path, "npy")
    assert loaded_after(["preview", str(npy), "-o", str(tmp_path / "p.png")]) == [["matplotlib"]]


def test_import_lutbake_is_lazy():
    code = f"import sys, lutbake; print([m for m in {HEAVY!r} if m in sys.modules]); print(lutbake.bake.__module__)"
    r = python(code)
    assert r.stdout.split("\n")[:2] == ["[]", "lutbake.api"], r.stdout


def test_bake_and_the_python_api_print_no_warp_lines_unless_asked(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG)
    cli = f"from lutbake.cli import main; main(['bake', {str(cfg)!r}, '--out-dir', {str(tmp_path / 'o')!r}, '--force'])"
    api = f"import lutbake; lutbake.bake([{str(cfg)!r}], out_dir={str(tmp_path / 'p')!r})"
    for code in (cli, api):
        r = python(code)
        out = r.stdout + r.stderr
        assert r.returncode == 0, out
        assert "Warp" not in out and "Module" not in out and "CUDA" not in out, out
    r = python(api)  # the table is up to date now: nothing at all is printed
    assert r.stdout == "" and r.stderr == ""
    fresh = api.replace(repr(str(tmp_path / "p")), repr(str(tmp_path / "v")))  # a skipped table starts no Warp
    for extra, code in (({"LUTBAKE_VERBOSE": "1"}, fresh), ({}, cli.replace("['bake'", "['--verbose', 'bake'"))):
        r = python(code, extra)
        assert r.returncode == 0 and "Warp " in r.stdout + r.stderr and "initialized" in r.stdout, r.stdout


def test_bake_says_why_its_sample_count_differs_from_the_config(tmp_path):
    from click.testing import CliRunner

    from lutbake.cli import main

    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG.replace("samples = 48", "samples = 2048"))
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(tmp_path / "o")])
    assert r.exit_code == 0, r.output
    assert "2028 samples/texel (samples = 2048 asked; gauss_legendre" in r.output and "3 x 26^2 = 2028" in r.output
    r = CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(tmp_path / "q"), "--set", "samples=2028"])
    assert "2028 samples/texel\n" in r.output  # no note when nothing was rounded


def test_make_luts_asks_lutbake_even_when_every_file_is_newer_than_its_sources(tmp_path):
    """The Makefile has no stamp that sees only files: lutbake's content hash decides."""
    out = tmp_path / "o"
    out.mkdir()
    for p in [out / ".luts.stamp", out / "dfg.exr"]:
        p.write_bytes(b"")
    r = subprocess.run(["make", "-n", "luts", f"OUT={out}", "VENV=.venv"], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    assert "lutbake bake" in r.stdout and f"--out-dir {out}" in r.stdout, r.stdout


def test_a_table_overwritten_with_other_settings_is_rebaked(tmp_path):
    """What `make luts` relies on: the README's example with --set into the same folder, then the original."""
    from click.testing import CliRunner

    from lutbake.cli import main

    cfg = tmp_path / "c.toml"
    cfg.write_text(CONFIG)
    run = lambda *a: CliRunner().invoke(main, ["bake", str(cfg), "--out-dir", str(tmp_path / "o"), *a])  # noqa: E731
    assert "small.exr" in run().output
    assert "small.exr" in run("--set", "samples=192").output
    again = run()
    assert again.exit_code == 0 and "skipped" not in again.output and "48 samples/texel" in again.output


def test_make_figures_writes_under_outputs_and_leaves_tracked_figures_alone(tmp_path):
    import runpy

    r = subprocess.run(
        ["make", "-n", "figures", f"OUT={tmp_path}", "VENV=.venv"], capture_output=True, text=True, cwd=ROOT
    )
    assert r.returncode == 0 and f"docs/plot_fresnel.py {tmp_path}/figures" in r.stdout, r.stdout
    script = runpy.run_path(str(ROOT / "docs" / "plot_fresnel.py"))  # not as __main__: nothing drawn yet
    assert script["DEFAULT_OUT"] == ROOT / "outputs" / "figures"
    tracked = {p: p.read_bytes() for p in (ROOT / "docs" / "figures").glob("fig*.png")}
    script["main"](tmp_path / "figures")
    assert all(p.read_bytes() == b for p, b in tracked.items())
    written = sorted((tmp_path / "figures").glob("*.png"))
    assert len(written) == 3 and all(p.read_bytes()[:4] == b"\x89PNG" for p in written)


def test_dir_lists_the_public_api_without_importing_it():
    """``dir(lutbake)`` names every entry of ``__all__`` (module ``__dir__``, PEP 562) while the package stays lazy:
    listing it imports neither the API modules nor Warp."""
    code = (
        "import json, sys, lutbake\n"
        "loaded = ['lutbake.api' in sys.modules, 'warp' in sys.modules]\n"
        "print(json.dumps([sorted(lutbake.__all__), dir(lutbake), *loaded]))"
    )
    r = python(code)
    assert r.returncode == 0, r.stderr
    public, listed, api_loaded, warp_loaded = json.loads(r.stdout)
    assert set(public) <= set(listed), set(public) - set(listed)
    assert not api_loaded and not warp_loaded


def test_the_api_docs_example_shows_overrides_and_they_load():
    """docs/batch.md's Python example passes ``overrides=`` (the --set texts), accepted as written."""
    import ast
    import re

    from lutbake.config import load_configs

    doc = (ROOT / "docs" / "batch.md").read_text()
    m = re.search(r"overrides=(\[[^\]]*\])", doc.split("## Python API", 1)[1])
    assert m, "docs/batch.md's API example does not show overrides="
    spec = load_configs([ROOT / "configs" / "dfg.toml"], ast.literal_eval(m.group(1)))[0]
    assert (spec.options["samples"], spec.options["dtype"]) == (2048, "half")
