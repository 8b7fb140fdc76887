"""The Python session runs a scene in chunks, returns the energy budget as arrays
that conserve ke + erotate + pe + dissipated, continues from its restarts, and runs
the same collision under mpirun -np 2 with mpi4py."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jkrdt import rundir
from jkrdt.analysis.dumps import open_text
from jkrdt.session import Session

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
SCENE = ROOT / "inputs" / "data" / "bcca_2d_head_on"     # 64 + 64 grains, 2D, 10 m/s
E_IMP = json.loads((SCENE / "collision.json").read_text())["E_imp"]


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("session")
    with Session(SCENE, out, every=500) as session:
        session.run(1000, chunk=250, progress=False)
        session.write_restart(out / "half.restart")
        session.run(1000, chunk=250, progress=False)
        return out, session.thermo(), session.energies()


def test_chunks_sample_the_energy_budget(serial):
    out, thermo, energies = serial
    assert np.array_equal(thermo["Step"], np.arange(0, 2001, 250))
    # the scene starts in the centre-of-mass frame with E_imp = mu v^2 / 2, no spin
    assert energies["kinetic"][0] == pytest.approx(E_IMP, rel=1e-12)
    # velocity Verlet at dt = 0.014 t_c: drift well below 1e-5 E_imp (tests/test_decks.py)
    assert np.abs(energies["total"] - energies["total"][0]).max() < 1e-5 * E_IMP
    assert energies["dissipated"][-1] > 0.0 and energies["kinetic"][-1] < E_IMP


def test_dumps_and_restarts_on_request(serial):
    out, _, _ = serial
    with open_text(out / rundir.ATOMS) as f:
        steps = [int(block.split()[0]) for block in f.read().split("ITEM: TIMESTEP\n")[1:]]
    assert steps == [0, 500, 1000, 1500, 2000]
    # a session that closes after no error ends its record as the deck does: final.restart
    # replaces the rolling restart files
    assert (out / "final.restart").exists() and not (out / "restart.a").exists()
    assert (out / rundir.CONTACTS).exists()


def test_no_outputs_unless_asked(tmp_path):
    with Session(SCENE, tmp_path) as session:
        session.run(10, progress=False)
    assert not (tmp_path / rundir.ATOMS).exists() and not (tmp_path / "restart.a").exists()


def test_continuing_from_a_restart_repeats_the_run(serial, tmp_path):
    _, _, energies = serial
    with Session(SCENE, tmp_path, restart=serial[0] / "half.restart") as session:
        session.run(1000, chunk=250, progress=False)
        resumed = session.energies()
    # same contacts, same state: the second half again, to round-off
    assert np.abs(resumed["total"] - energies["total"][4:]).max() < 1e-12 * E_IMP
    assert np.abs(resumed["dissipated"] - energies["dissipated"][4:]).max() < 1e-12 * E_IMP


def test_a_session_keeps_a_finished_record(serial):
    # a session may not start a new record over a finished run's, nor continue from a
    # restart file over any record without appending to it
    out = serial[0]
    log = (out / rundir.LOG).read_text()
    with pytest.raises(ValueError, match="holds a finished run .* force=True"):
        Session(SCENE, out, every=500)
    with pytest.raises(ValueError, match="would replace it; give append=True"):
        Session(SCENE, out, restart=out / "half.restart")
    assert (out / rundir.LOG).read_text() == log


def test_a_new_record_leaves_no_stale_analysis(serial, tmp_path):
    shutil.copytree(serial[0], tmp_path / "copy")
    out = tmp_path / "copy"
    (out / rundir.OUTCOME).write_text('{"stop_reason": "settled"}')
    with Session(SCENE, out, force=True) as session:
        session.run(10, progress=False)
    assert not (out / rundir.OUTCOME).exists()


@pytest.mark.mpi
def test_session_under_mpirun_two_ranks(serial, tmp_path):
    _, _, energies = serial
    subprocess.run([str(BIN / "mpirun"), "-np", "2", sys.executable,
                    str(Path(__file__).with_name("session_under_mpi.py")), str(SCENE),
                    str(tmp_path)], check=True, timeout=300)
    parallel = np.load(tmp_path / "energies.npz")
    assert int(parallel["ranks"]) == 2 and bool(parallel["same_on_all_ranks"])
    # domain decomposition changes only the summation order
    assert np.abs(parallel["total"] - energies["total"]).max() < 1e-9 * E_IMP
    assert np.abs(parallel["kinetic"] - energies["kinetic"]).max() < 1e-9 * E_IMP
