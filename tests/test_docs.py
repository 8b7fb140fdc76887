"""The manual builds (Sphinx, warnings as errors), and every command the README and the
manual quote is run: here, when it takes seconds, or by the test, script or CI step
named for it in ``ELSEWHERE``. A command quoted anew fails here until it is placed."""

import json
import re
import subprocess
import sys
from pathlib import Path


from jkrdt import rundir
from jkrdt.campaign import read_spec

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
PROGRAMS = ("./run", "jkrdt", "lmp", "mpirun", "srun")

#: the quoted commands that take minutes or a cluster, and what runs each: a file that
#: must name the command's distinctive word
ELSEWHERE = {
    "./run test": (".ci/run", "./run test"),
    "./run demo": ("run", "jkrdt\" demo"),
    "jkrdt demo": ("tests/test_docs.py", "test_jkrdt_demo_as_the_quick_start_runs_it"),
    "mpirun -np 2 lmp -in inputs/bpca_3d_oblique.lmp": ("tests/test_decks.py",
                                                        "bpca_3d_oblique"),
    "jkrdt setup --n-tar 50000 --n-pro 50000 --v 39.8 --model frictionless --b-off 0 --seed 1 "
    "--dt auto --tolerance 1e-3 --out runs/paper": ("validation/paper_size.py", "--tolerance"),
    "jkrdt run runs/paper --np 2": ("validation/paper_size.py", '"run"'),
    "jkrdt analyse runs/paper": ("validation/paper_size.py", '"analyse"'),
    "srun jkrdt campaign spec.json /shared/runs/c --ranks-per-run 1": (
        "tests/test_campaign.py", "--ranks-per-run"),
    "jkrdt summarise /shared/runs/c": ("tests/test_campaign.py", "summarise"),
}
#: the quoted commands run here, in this order, in a scratch directory holding inputs/
HERE = [
    "lmp -in inputs/two_particle.lmp -var v 4",
    "jkrdt build --kind bcca --dim 3 --n 4096 --out runs/agg",
    "jkrdt setup --kind bcca --dim 2 --n-tar 64 --n-pro 64 --v 10 --b-off 0 --seed 4 "
    "--out runs/s",
    "jkrdt run runs/s --np 2",
    "jkrdt analyse runs/s",
    "jkrdt campaign spec.json runs/c",
    "jkrdt summarise runs/c",
]


def quoted_commands(page: Path) -> list[str]:
    """The commands of ``page``'s code blocks: the ``$`` lines of console blocks, and the
    lines of bash blocks that start with one of PROGRAMS; comments and spacing dropped."""
    found, block = [], None
    for line in page.read_text().splitlines():
        fence = re.match(r"\s*```(\w*)", line)
        if fence:
            block = None if block is not None else fence.group(1)
            continue
        text = line.strip()
        if block == "console" and text.startswith("$ "):
            text = text[2:]
        elif block != "bash" or not text.startswith(PROGRAMS):
            continue
        found.append(" ".join(text.split("#", 1)[0].split()))
    return found


def test_the_manual_builds_with_warnings_as_errors(tmp_path):
    done = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b",
                           "html", str(ROOT / "docs"), str(tmp_path / "html")],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "html" / "pair_jkr_dt.html").exists()


def test_the_readme_is_a_manual_not_a_notebook():
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= 300, f"README.md has {len(lines)} lines: move the detail to docs/"
    # every page of docs/ is in the manual's table of contents, and in the README's list
    index = (ROOT / "docs" / "index.md").read_text()
    readme = "\n".join(lines)
    for page in sorted((ROOT / "docs").glob("*.*")):
        if page.suffix in (".md", ".rst") and page.stem != "index":
            assert f"\n{page.stem}\n" in index, f"{page.name} is not in docs/index.md"
            assert f"docs/{page.name}" in readme, f"the README does not point to {page.name}"


def test_every_quoted_command_is_run_somewhere():
    """HERE runs here; ELSEWHERE names what runs it; './run validate NAME ...' runs
    validation/NAME.py, whose quick variant tests/test_validation.py runs."""
    quoted = {c for page in PAGES for c in quoted_commands(page)}
    studies = {c for c in quoted if c.startswith("./run validate ")}
    quick = (ROOT / "tests" / "test_validation.py").read_text()
    for command in studies:
        name = command.split()[2]
        assert (ROOT / "validation" / f"{name}.py").exists(), f"{command!r}: no such study"
        assert f'"{name}"' in quick, f"{command!r}: test_validation.py runs no quick {name}"
    unplaced = quoted - studies - set(HERE) - set(ELSEWHERE)
    assert not unplaced, f"quoted but run nowhere: {sorted(unplaced)}; add each to HERE or " \
                         "ELSEWHERE in tests/test_docs.py"
    for command, (path, word) in ELSEWHERE.items():
        assert command in quoted, f"{command!r} is no longer quoted: drop it from ELSEWHERE"
        assert word in (ROOT / path).read_text(), f"{path} does not run {command!r}"
    assert "./run test" in (ROOT / ".ci" / "run").read_text()


def test_the_readmes_campaign_spec_is_a_valid_spec(tmp_path):
    readme = (ROOT / "README.md").read_text()
    block = re.search(r"```json\n(.*?)```", readme, re.S).group(1)
    (tmp_path / "spec.json").write_text(block)
    spec = read_spec(tmp_path / "spec.json")
    assert len(spec["b_off2"]) == 12 and spec["model"] == "frictionless"


def test_the_quoted_commands_run(tmp_path):
    """HERE, as a user types them. A small spec.json of the test's own for the campaign.
    Physics fixed on the way: two grains at 4 m/s, below v_stick = 5.96 m/s, stick; a BCCA
    has N - 1 bonds; the 2D collision's energy budget closes."""
    (tmp_path / "inputs").symlink_to(ROOT / "inputs")
    (tmp_path / "spec.json").write_text(json.dumps(dict(
        n_tar=16, n_pro=16, v_col=[10.0], b_off2=[0.0, 0.5], seeds=[1],
        settle=dict(check_tc=10, cap_tc=4000))))
    for command in HERE:
        words = command.split()
        if words[0] in ("jkrdt", "lmp"):
            words[0] = str(BIN / words[0])
        done = subprocess.run(words, cwd=tmp_path, capture_output=True, text=True,
                              timeout=600)
        assert done.returncode == 0, f"{command}: {done.stderr}"
    stuck = re.search(r"final relative speed \S+ m/s, bonded contacts (\d+)",
                      (tmp_path / "log.lammps").read_text())
    assert stuck and int(stuck.group(1)) == 1
    agg = json.loads((tmp_path / "runs" / "agg" / "aggregate.json").read_text())
    assert agg["n_bonds"] == 4095
    out = json.loads((tmp_path / "runs" / "s" / rundir.OUTCOME).read_text())
    assert out["settled"] and out["energy_error"] < 1e-4
    assert abs(out["kinetic_left"] + out["potential_change"] + out["dissipated_fraction"]
               - out["energy_drift"] - out["kinetic_start"]) < 1e-12
    assert (tmp_path / "runs" / "c" / "summary.csv").exists()


def test_jkrdt_demo_as_the_quick_start_runs_it(tmp_path):
    """The quick start's main job (./run demo is jkrdt demo in .venv): a real collision
    of two 500-grain BPCAs run until it settles, a line per check, the summary and the
    picture; its energy budget closes."""
    done = subprocess.run([str(BIN / "jkrdt"), "demo", "--out", str(tmp_path / "demo")],
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr
    assert "growth efficiency f_gro" in done.stdout and "t_c  N_lar" in done.stdout
    out = json.loads((tmp_path / "demo" / rundir.OUTCOME).read_text())
    assert out["settled"] and out["n_total"] == 1000 and out["energy_error"] < 1e-3
    assert abs(out["kinetic_left"] + out["potential_change"] + out["dissipated_fraction"]
               - out["energy_drift"] - out["kinetic_start"]) < 1e-12
    assert (tmp_path / "demo" / "outcome.png").stat().st_size > 10_000
