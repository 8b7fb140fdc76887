"""The decks in inputs/ run with lmp and under mpirun -np 2, from the repository
root, and conserve ke + erotate + pe + dissipated."""

import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ICE_SCALES as S
from jkrdt import rundir
from jkrdt.rundir import read_thermo
from jkrdt.ledger import energy_budget

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def run_deck(name, tmp_path, nproc=1, **variables):
    log = tmp_path / f"{name}.{nproc}.log"
    cmd = [str(BIN / "lmp"), "-in", f"inputs/{name}.lmp", "-log", str(log), "-screen", "none"]
    for k, v in variables.items():
        cmd += ["-var", k, str(v)]
    if nproc > 1:
        cmd = [str(BIN / "mpirun"), "-np", str(nproc)] + cmd
    subprocess.run(cmd, cwd=ROOT, check=True, timeout=300)
    return log


@pytest.mark.parametrize("nproc", [1, 2])
def test_two_particle_deck_bounces_with_the_energy_budget(tmp_path, nproc):
    # v_f^2 = v^2 - v_stick^2, v_stick = 1.9345 v0 (tests/test_collision_energy.py)
    log = run_deck("two_particle", tmp_path, nproc, v=8.0)
    final = float(re.search(r"final relative speed ([0-9.eE+-]+)", log.read_text()).group(1))
    assert final == pytest.approx(math.sqrt(8.0 ** 2 - (1.9345 * S.v0) ** 2), rel=0.02)


@pytest.mark.parametrize("deck", ["bcca_2d_head_on", "bpca_3d_oblique"])
@pytest.mark.parametrize("nproc", [1, 2])
def test_aggregate_decks_conserve_energy(tmp_path, deck, nproc):
    out = tmp_path / deck
    log = run_deck(deck, tmp_path, nproc, steps=4000, every=500, out=out)
    budget = energy_budget(read_thermo(log))
    e_imp = budget["kinetic"][0]
    assert abs(budget["total"] - budget["total"][0]).max() < 1e-5 * e_imp
    assert budget["rolling"][-1] > 0.0                  # the frictional model acts
    assert (out / "final.restart").exists() and (out / rundir.ATOMS).exists()


def test_cli_setup_then_run_under_two_ranks(tmp_path):
    scene = tmp_path / "scene"
    jkrdt = str(BIN / "jkrdt")
    subprocess.run([jkrdt, "setup", "--kind", "bcca", "--dim", "2", "--n-tar", "32", "--n-pro",
                    "32", "--v", "8", "--seed", "3", "--out", str(scene)], check=True, timeout=120)
    subprocess.run([jkrdt, "run", str(scene), "--steps", "2000", "--np", "2"], cwd=ROOT,
                   check=True, timeout=300)
    budget = energy_budget(read_thermo(scene / "log.lammps"))
    assert abs(budget["total"] - budget["total"][0]).max() < 1e-5 * budget["kinetic"][0]
    assert (scene / "final.restart").exists()
