"""The plugin keeps its layers, and no function grows past what one reads at once
(issue 49): a header includes only headers of lower layers (the kernel knows no
LAMMPS), and a function in plugin/, pylammps/ or analysis/ is at most MAX_LINES long,
but for those still to be split, which may not grow."""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PLUGIN = ROOT / "plugin"

#: the plugin's headers by layer: 0 the contact kernel (the papers' equations, no
#: LAMMPS), 1 helpers on LAMMPS types, 2 the contact store and the settle rule's parts,
#: 3 the styles a deck names, 4 the pair loop's own parts
LAYERS = {
    "jkr_dt_normal.h": 0, "jkr_dt_tangential.h": 0, "jkr_dt_contact.h": 0,
    "jkr_dt_lanes.h": 0, "jkr_dt_arena.h": 0,
    "jkr_dt_fragments.h": 1, "jkr_dt_order.h": 1,
    "fix_jkr_dt_contacts.h": 2, "fix_jkr_dt_settle_depart.h": 2,
    "fix_jkr_dt_settle_table.h": 2,
    "pair_jkr_dt.h": 3, "fix_jkr_dt_settle.h": 3, "compute_jkr_dt.h": 3,
    "pair_jkr_dt_step.h": 4,
}
MAX_LINES = 120
#: the functions still longer, with the length they may not pass
TO_SPLIT = {}


def included(header: Path) -> list[str]:
    return re.findall(r'^#include "([^"]+)"', header.read_text(), re.M)


def test_every_header_has_a_layer():
    headers = {p.name for p in PLUGIN.glob("*.h")}
    assert headers == set(LAYERS), f"place these in LAYERS: {sorted(headers ^ set(LAYERS))}"


def test_a_header_includes_only_lower_layers():
    for name, layer in LAYERS.items():
        for inc in included(PLUGIN / name):
            if inc in LAYERS:
                # the kernel's headers build on each other; above it, strictly downwards
                ok = LAYERS[inc] < layer or (layer == 0 and LAYERS[inc] == 0)
                assert ok, f"{name} (layer {layer}) includes {inc} (layer {LAYERS[inc]})"
            else:                          # a LAMMPS header: not in the kernel
                assert layer > 0, f"the kernel header {name} includes LAMMPS's {inc}"


def function_lengths() -> dict[str, int]:
    """name -> lines, for Python functions (ast) and C++ functions whose body opens with
    a '{' alone at the start of a line (the plugin's style)."""
    lengths = {}
    for path in [*(ROOT / "pylammps").rglob("*.py"), *(ROOT / "analysis").glob("*.py")]:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                key = f"{path.relative_to(ROOT)}:{node.name}"
                lengths[key] = max(lengths.get(key, 0), node.end_lineno - node.lineno + 1)
    for path in [*PLUGIN.glob("*.cpp"), *PLUGIN.glob("*.h")]:
        lines = path.read_text().splitlines()
        k = 1
        while k < len(lines):
            if lines[k] == "{":
                end = next(j for j in range(k + 1, len(lines)) if lines[j] == "}")
                head = " ".join(lines[max(0, k - 3):k])
                names = re.findall(r"([A-Za-z_][A-Za-z_0-9]*)\s*\(", head)
                key = f"{path.relative_to(ROOT)}:{names[0] if names else head.strip()}"
                lengths[key] = max(lengths.get(key, 0), end - k + 2)
                k = end
            k += 1
    return lengths


def test_no_function_passes_max_lines():
    lengths = function_lengths()
    too_long = {k: n for k, n in lengths.items() if n > MAX_LINES and k not in TO_SPLIT}
    assert not too_long, f"split these by job (at most {MAX_LINES} lines): {too_long}"
    for key, ceiling in TO_SPLIT.items():
        assert key in lengths, f"{key} is gone: drop it from TO_SPLIT"
        assert lengths[key] <= ceiling, f"{key} grew to {lengths[key]} lines"


def test_the_layout_page_names_every_source_file():
    """docs/layout.md names each file of plugin/ and pylammps/jkrdt/ (by its path, its
    name, or a pattern such as plugin/fix_jkr_dt_contacts.*)."""
    import fnmatch

    page = (ROOT / "docs" / "layout.md").read_text()
    named = set(re.findall(r"`([^`\s]+)`", page))
    sources = [*PLUGIN.glob("*.h"), *PLUGIN.glob("*.cpp"),
               *(ROOT / "pylammps" / "jkrdt").glob("*.py")]
    missing = [str(p.relative_to(ROOT)) for p in sorted(sources) if p.name != "__init__.py"
               and not any(fnmatch.fnmatch(str(p.relative_to(ROOT)), n)
                           or fnmatch.fnmatch(p.name, n) for n in named)]
    assert not missing, f"docs/layout.md does not say what these are: {missing}"


def test_rundir_declares_every_field_of_outcome_json_and_the_manual_names_them():
    """outcome.json's schema is written once (jkrdt.rundir.OUTCOME_FIELDS): the manual's
    page of records names exactly those fields (the parameters' paragraph and the first
    column of the table), the outcome's measures are among them, and a field not declared
    is refused when the record is written."""
    from jkrdt import rundir
    from jkrdt.analysis.outcome import Outcome
    import dataclasses
    import pytest

    page = (ROOT / "docs" / "records.md").read_text()
    section = page[page.index("### `outcome.json`"):page.index("An `outcome.json` whose")]
    opening = section[section.index("The run's parameters open it"):
                      section.index("A failed run adds")]
    named = [n for n in re.findall(r"`([A-Za-z_0-9]+)`", opening)]
    for row in section.splitlines():
        if row.startswith("| `"):
            named += re.findall(r"`([A-Za-z_0-9]+)`", row.split("|")[1])
    assert named[:len(rundir.PARAMETER_FIELDS)] == list(rundir.PARAMETER_FIELDS)
    assert sorted(named) == sorted(rundir.OUTCOME_FIELDS)
    assert {f.name for f in dataclasses.fields(Outcome)} <= set(rundir.ANALYSIS_FIELDS)
    with pytest.raises(ValueError, match="declare it in jkrdt.rundir.OUTCOME_FIELDS"):
        rundir.write_outcome(ROOT / "no-such-run", {"run": "x", "speed_of_light": 3e8})
