"""The scene contract: one module writes a scene directory and reads it back, turns a
material and a model into the pair_coeff line, and every route runs the scene's own deck."""

import ast
import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jkrdt import ledger
from jkrdt import rundir
from jkrdt.materials import ICE, QUARTZ, material
from jkrdt.scene import Scene, pair_coeff

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def test_pair_coeff_is_one_translation_of_material_and_model():
    assert pair_coeff(ICE) == "gamma 0.1 E 7000000000.0 nu 0.25 xi_crit 8e-10"
    assert pair_coeff(ICE, "frictionless") == "gamma 0.1 E 7000000000.0 nu 0.25 frictionless"
    damped = dataclasses.replace(QUARTZ, G=2e10, tvis=6e-12)
    assert pair_coeff(damped) == ("gamma 0.025 E 54000000000.0 nu 0.17 G 20000000000.0 "
                                  "tvis 6e-12 xi_crit 2e-10")
    with pytest.raises(ValueError, match="has no xi_crit: give one, or use the 'frictionless'"):
        pair_coeff(material("ice", xi_crit=None))
    with pytest.raises(ValueError, match="unknown model 'sticky'"):
        pair_coeff(ICE, "sticky")
    with pytest.raises(ValueError, match="has no xi_crit"):       # a scene is checked at once
        Scene(material("ice", xi_crit=None), 8, 8, v_col=1.0)


def test_a_written_scene_reads_back_and_holds_its_impact_energy(tmp_path):
    scene = Scene(ICE, 40, 24, v_col=25.0, b_off=0.4, seed=3, dim=3, model="frictionless",
                  dt_over_tc=0.01, dt_reason="a test's dt")
    rundir.write(tmp_path, scene)
    back = rundir.read(tmp_path)
    assert back == scene
    # E_imp = mu v^2 / 2 is the kinetic energy of the data file's velocities (CM frame)
    rows = (tmp_path / rundir.DATA).read_text().split("Velocities")[1].split()
    v = np.array(rows, dtype=float).reshape(-1, 7)[:, 1:4]
    s = scene.scales
    assert 0.5 * s.mass * (v ** 2).sum() == pytest.approx(scene.E_imp, rel=1e-12)
    assert np.abs(v.sum(axis=0)).max() < 1e-12 * 25.0
    deck = (tmp_path / rundir.DECK).read_text()
    assert f'variable coeffs     index "{pair_coeff(ICE, "frictionless")}"' in deck
    assert f'variable dt         index "{0.01 * s.t_c!r}"' in deck
    assert deck.endswith(rundir.find_template().read_text())


def test_the_set_ups_open_choices_place_bonds_and_gap_as_asked(tmp_path):
    # bonds at delta_0 (the JKR equilibrium, at rest) or touching (1e-3 delta_0, inside
    # contact: no bond lost); the gap is the distance between the nearest grains of the two
    # aggregates at the start; both read back from collision.json
    from scipy.spatial import cKDTree

    from jkrdt.scene import BONDS

    r = 1.0e-7
    for bond in BONDS:
        scene = Scene(ICE, 60, 40, v_col=10.0, seed=5, model="frictionless", bond=bond,
                      gap=2.0e-8)
        placed = scene.collide()
        x, body = placed.x, placed.body
        delta = BONDS[bond] * scene.scales.delta0
        for b in (1, 2):
            pairs = cKDTree(x[body == b]).query_pairs(2 * r + 1e-3 * scene.scales.delta0,
                                                      output_type="ndarray")
            d = np.linalg.norm(np.diff(x[body == b][pairs], axis=1)[:, 0], axis=1)
            assert len(pairs) >= (body == b).sum() - 1         # a tree of bonds at least
            assert np.abs(d - (2 * r - delta)).max() < 1e-6 * scene.scales.delta0
        nearest = cKDTree(x[body == 1]).query(x[body == 2])[0].min()
        assert nearest - 2 * r == pytest.approx(2.0e-8, rel=1e-9)
        rundir.write(tmp_path / bond, scene, placed)
        assert rundir.read(tmp_path / bond) == scene
    with pytest.raises(ValueError, match="unknown bond 'glued'"):
        Scene(ICE, 8, 8, v_col=1.0, bond="glued")
    with pytest.raises(ValueError, match="initial gap must be >= 0 m"):
        Scene(ICE, 8, 8, v_col=1.0, gap=-1e-9)


def test_committed_scene_decks_are_what_rundir_writes(tmp_path):
    for name in ("bcca_2d_head_on", "bpca_3d_oblique"):
        committed = ROOT / "inputs" / "data" / name
        copy = tmp_path / name
        copy.mkdir()
        (copy / rundir.META).write_text((committed / rundir.META).read_text())
        rundir.write_deck(copy)
        assert (copy / rundir.DECK).read_text() == \
            (committed / rundir.DECK).read_text(), \
            f"regenerate with jkrdt.rundir.write_deck('inputs/data/{name}')"


def test_the_template_carries_the_ledger_and_refuses_to_run_without_a_scene(tmp_path):
    template = rundir.find_template().read_text()
    assert ledger.THERMO_STYLE in template.splitlines()
    done = subprocess.run([str(BIN / "lmp"), "-in", str(ROOT / "inputs" / "collision.lmp"),
                           "-log", "none"], capture_output=True, text=True, cwd=tmp_path)
    said = [line for line in done.stdout.splitlines() if line.startswith("ERROR")]
    assert done.returncode != 0 and said == [
        "ERROR: inputs/collision.lmp runs a scene: give -var coeffs and -var dt, or run the "
        "in.collision.lmp that jkrdt setup wrote into the scene directory"]


def test_jkrdt_run_runs_the_scenes_own_deck(tmp_path):
    scene = Scene(ICE, 8, 8, v_col=5.0, seed=2, model="frictional")
    rundir.write(tmp_path, scene)
    deck = tmp_path / rundir.DECK
    # an edit to the scene's deck is what runs: here its pair_coeff words
    deck.write_text(deck.read_text().replace(pair_coeff(ICE), pair_coeff(ICE, "frictionless")))
    subprocess.run([str(BIN / "jkrdt"), "run", str(tmp_path), "--steps", "200"], check=True,
                   capture_output=True)
    log = (tmp_path / "log.lammps").read_text()
    assert f"pair_coeff      * * {pair_coeff(ICE, 'frictionless')}" in log


def test_the_skin_follows_the_scene_so_10_micron_grains_run_as_set_up(tmp_path):
    """A pair at 2 v_col closes a quarter of the skin per step: 8 v_col dt for 10 micron
    ice at 20 m/s (0.13 micron), where 10 nm (the skin of 0.1 micron grains) stops the run."""
    ran = {}
    for name, skin in (("given", ["--skin", "1e-8"]), ("chosen", [])):
        d = tmp_path / name
        subprocess.run([str(BIN / "jkrdt"), "setup", "--n-tar", "8", "--n-pro", "8", "--v",
                        "20", "--radius", "1e-5", "--out", str(d), *skin], check=True,
                       capture_output=True, timeout=120)
        ran[name] = subprocess.run([str(BIN / "jkrdt"), "run", str(d), "--steps", "3000"],
                                   capture_output=True, text=True, timeout=300)
    meta = rundir.read_metadata(tmp_path / "chosen")
    t_c = rundir.from_metadata(meta).scales.t_c
    assert meta["skin"] == pytest.approx(8 * 20.0 * 0.014 * t_c, rel=1e-12)
    assert meta["skin"] == pytest.approx(1.32e-7, rel=0.01)
    assert ran["chosen"].returncode == 0, ran["chosen"].stderr
    assert ran["given"].returncode != 0 and "raise the skin above" in ran["given"].stderr


CORE = ["aggregates", "atomic", "collision", "datafile", "instance", "ledger", "materials",
        "plugin", "rundir", "scene", "session", "stopping", "timestep"]


def imported(path: Path) -> set[str]:
    """Every module ``path`` imports, at any depth of its code, relative ones resolved."""
    names = set()
    package = "jkrdt" if path.parent.name == "jkrdt" else "jkrdt.analysis"
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = package.rsplit(".", node.level - 1)[0] if node.level else ""
            module = ".".join(p for p in (base, node.module or "") if p)
            names |= {module} | {f"{module}.{a.name}" for a in node.names}
    return names


def test_the_packages_depend_one_way():
    # core -> (nothing of ours above it); analysis -> core; cli, campaign -> both
    for name in CORE:
        uses = imported(ROOT / "pylammps" / "jkrdt" / f"{name}.py")
        assert not {u for u in uses if u.startswith("jkrdt.analysis")}, name
        assert not uses & {"jkrdt.cli", "jkrdt.campaign"}, name
    for path in (ROOT / "analysis").glob("*.py"):
        uses = imported(path)
        assert not uses & {"jkrdt.cli", "jkrdt.campaign", "jkrdt.session"}, path.name
    # the scene is a value: its directory, deck and runs are rundir's and session's
    assert not imported(ROOT / "pylammps" / "jkrdt" / "scene.py") & {
        "jkrdt.rundir", "jkrdt.session", "jkrdt.instance"}


def test_no_two_modules_import_each_other_in_a_circle():
    modules = {f"jkrdt.{p.stem}": p for p in (ROOT / "pylammps" / "jkrdt").glob("*.py")}
    modules |= {f"jkrdt.analysis.{p.stem}": p for p in (ROOT / "analysis").glob("*.py")}
    graph = {name: {u for u in imported(path) if u in modules and u != name}
             for name, path in modules.items()}

    def reaches(start, goal, seen):
        return any(n == goal or (n not in seen and reaches(n, goal, seen | {n}))
                   for n in graph[start])
    circles = sorted(name for name in graph if reaches(name, name, {name}))
    assert not circles, f"modules in an import circle: {circles}"
