"""Outputs of several data files: the names of each file of one table's output, written and verified as one unit.

The first file of a set is the one the output's sidecar ``<first>.json`` describes (``file``); the sidecar lists
every file (``files``) and names the sha256 of the others (``files_sha256``, lutbake.io.integrity), so a missing or
edited member makes the output not up to date. A set is chosen by (kind, format): ``format = "ktx2"`` of a kind
``ltc_aniso`` table is three 3D textures per lobe (its ``lobes`` option: 3, 6 or 9 files), of any other kind one file.

| kind | format | files | sidecar ``format`` |
| --- | --- | --- | --- |
| any (``ltc`` only) | ``ltc_dds`` | <name>_1.dds, <name>_2.dds | ``ltc_dds`` |
| ``ltc_aniso`` | ``ktx2`` | <name>_t0.ktx2 ... _t2.ktx2 (2, 3 lobes: _t5, _t8.ktx2) | ``ltc_aniso_ktx2`` |
| ``ltc_aniso`` | ``dds`` | <name>_t0.dds ... _t2.dds (2, 3 lobes: _t5, _t8.dds) | ``ltc_aniso_dds`` |

A set's suffixes are the most it may hold; ``set_size`` the count a table's options choose (the first that many).
"""

from __future__ import annotations

from pathlib import Path

ANY_KIND = None
TEXTURES_PER_LOBE = 3  # an ltc_aniso table's 3D textures per lobe (lutbake.io.ltc_aniso_textures)
MAX_LOBES = 3  # the most lobes an ltc_aniso table has (its ``lobes`` key's maximum)


def texture_suffixes(ext: str) -> tuple[str, ...]:
    """_t0<ext>, _t1<ext>, ...: the most textures an ltc_aniso table writes."""
    return tuple(f"_t{k}{ext}" for k in range(TEXTURES_PER_LOBE * MAX_LOBES))


FILE_SETS = {  # (kind, format) -> (the files' suffixes after the table's name, the sidecar's ``format``)
    (ANY_KIND, "ltc_dds"): (("_1.dds", "_2.dds"), "ltc_dds"),  # ltc_code's pair (lutbake.io.ltc)
    ("ltc_aniso", "ktx2"): (texture_suffixes(".ktx2"), "ltc_aniso_ktx2"),  # lutbake.io.ltc_aniso_textures
    ("ltc_aniso", "dds"): (texture_suffixes(".dds"), "ltc_aniso_dds"),
}


def file_set(kind: str | None, fmt: str) -> tuple[tuple[str, ...], str] | None:
    """(suffixes, sidecar format) of the output of a ``kind`` table in ``fmt``; None for a one-file output."""
    return FILE_SETS.get((kind, fmt)) or FILE_SETS.get((ANY_KIND, fmt))


def set_size(kind: str | None, options: dict | None) -> int | None:
    """How many files of its set a ``kind`` table of ``options`` (a config's table) writes: an ltc_aniso table
    three per lobe (``lobes``, default 1); None: every suffix of its set."""
    if kind == "ltc_aniso":
        return TEXTURES_PER_LOBE * int((options or {}).get("lobes", 1))
    return None


def set_files(name: str, kind: str | None, fmt: str, options: dict | None = None) -> list[str] | None:
    """The file names of table ``name``'s output (file_set; as many as set_size of its ``options``), the first the
    one its sidecar describes; None for a one-file output."""
    found = file_set(kind, fmt)
    return None if found is None else [name + suffix for suffix in found[0][: set_size(kind, options)]]


def members(path) -> list[Path]:
    """Every file of the set a data file ``path`` may belong to, judged by its name alone (``foo_t1.ktx2`` ->
    ``foo_t0.ktx2`` ... ``foo_t8.ktx2``: the most its set may hold), the first the one whose sidecar lists them; []
    when its name ends in no set's suffix. A plain table named ``foo_t1`` matches too: readers check the sidecar's
    ``files``, which names the set's own."""
    path = Path(path)
    for suffixes, _ in FILE_SETS.values():
        for suffix in suffixes:
            if path.name.endswith(suffix) and len(path.name) > len(suffix):
                stem = path.name[: -len(suffix)]
                return [path.with_name(stem + s) for s in suffixes]
    return []
