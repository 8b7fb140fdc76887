"""Contact state survives reneighboring, MPI decomposition, newton settings and
restarts: the same aggregate collision gives the same trajectory to round-off.
Every test runs with the frictionless model and with the frictional one, whose
contacts also carry the pointers n1, n2 and the twisting angle."""

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import SLEEPING_RANKS
from jkrdt import ledger, rundir

from jkrdt import scene as scene_module
from jkrdt.analysis.dumps import last_local_snapshot
from jkrdt.materials import ICE, scales

DECK = Path(__file__).resolve().parents[1] / "inputs" / "collision.lmp"
BIN = Path(sys.executable).parent
R = 1.0e-7
S = scales(ICE, R)
STEPS = 4000      # long enough for ~1000 contacts to form, several to break, atoms to migrate


MODELS = {"frictionless": "frictionless", "frictional": "frictional"}


@pytest.fixture(scope="module", params=list(MODELS))
def model(request):
    return MODELS[request.param]


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    d = tmp_path_factory.mktemp("scene")
    rundir.write(d, scene_module.Scene(ICE, 150, 150, v_col=20.0, b_off=0.3, seed=7))
    return d / rundir.DATA


def run_deck(workdir, data, model, nproc=1, steps=STEPS, restart=None, extra=(), threads=1,
             tvis=0.0):
    workdir.mkdir(parents=True, exist_ok=True)
    cmd = [str(BIN / "lmp"), "-in", str(DECK), "-log", str(workdir / "log.lammps"),
           "-screen", "none",
           "-var", "file", str(restart or data), "-var", "out", str(workdir),
           "-var", "coeffs", scene_module.pair_coeff(dataclasses.replace(ICE, tvis=tvis), model),
           "-var", "dt", repr(0.014 * S.t_c),
           "-var", "steps", str(steps), "-var", "every", "500", *extra]
    if restart:
        cmd += ["-var", "read", "read_restart"]
    if nproc > 1:
        cmd = [str(BIN / "mpirun"), "-np", str(nproc)] + cmd
    # threads and ranks that sleep while they wait: more of them than cores (2 ranks x 2
    # threads, or 4 ranks, on 2 cores) would otherwise spin against each other
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), OMP_WAIT_POLICY="PASSIVE",
               **SLEEPING_RANKS)
    subprocess.run(cmd, check=True, cwd=workdir, timeout=600, env=env)
    final = np.loadtxt(workdir / rundir.FINAL_DUMP, skiprows=9)
    return final[np.argsort(final[:, 0])]


def last_local_dump(workdir):
    """Rows of the last snapshot of the deck's contact dump (dump local)."""
    return last_local_snapshot(workdir / rundir.CONTACTS)


def scale_error(a, b):
    """Largest position difference in units of delta_c, and velocity in m/s."""
    assert np.array_equal(a[:, 0], b[:, 0])
    return np.abs(a[:, 1:4] - b[:, 1:4]).max() / S.delta_c, np.abs(a[:, 4:7] - b[:, 4:7]).max()


@pytest.fixture(scope="module")
def serial_dir(scene, model, tmp_path_factory):
    d = tmp_path_factory.mktemp("serial")
    run_deck(d, scene, model, extra=("-var", "keep_restarts", "yes"))   # for the mid-run restart
    return d


@pytest.fixture(scope="module")
def serial(serial_dir):
    final = np.loadtxt(serial_dir / rundir.FINAL_DUMP, skiprows=9)
    return final[np.argsort(final[:, 0])]


def test_collision_forms_contacts_that_obey_eq5(serial_dir):
    from conftest import jkr_force
    rows = last_local_dump(serial_dir)
    ids, delta, force = rows[:, :2], rows[:, 2], rows[:, 4]
    across = (ids[:, 0] <= 150) & (ids[:, 1] > 150)
    assert across.sum() >= 1                          # target and projectile are bonded
    assert np.all(ids[:, 0] < ids[:, 1])
    assert len({tuple(p) for p in ids}) == len(ids)   # each contact listed once
    assert np.all(delta >= -S.delta_c)
    expected = np.array([jkr_force(d, S) for d in delta])
    assert np.allclose(force, expected, rtol=1e-8, atol=1e-9 * S.F_c)


@pytest.mark.mpi
@pytest.mark.parametrize("nproc", [2, 4])
def test_ranks_match_serial(serial, scene, model, tmp_path, nproc):
    parallel = run_deck(tmp_path, scene, model, nproc=nproc)
    dx, dv = scale_error(serial, parallel)
    print(f"{model}, {nproc} ranks vs 1: max |dx| = {dx:.2e} delta_c, max |dv| = {dv:.2e} m/s")
    # forces sum in another order across ranks; that round-off grows over 4000 steps
    # of a colliding aggregate but stays far below delta_c (the scale of any event)
    assert dx < 1e-6 and dv < 1e-6


def test_newton_on_matches_off(serial, scene, model, tmp_path):
    on = run_deck(tmp_path, scene, model, extra=("-var", "newton", "on"))
    dx, dv = scale_error(serial, on)
    print(f"newton on vs off: max |dx| = {dx:.2e} delta_c, max |dv| = {dv:.2e} m/s")
    assert dx < 1e-6 and dv < 1e-6


@pytest.mark.parametrize("tvis", [0.0, 6e-12])
def test_restart_continues_exactly(scene, model, tmp_path, tvis):
    straight = run_deck(tmp_path / "straight", scene, model, tvis=tvis)
    first = tmp_path / "first"
    run_deck(first, scene, model, steps=STEPS // 2, tvis=tvis)
    cont = run_deck(tmp_path / "second", scene, model, steps=STEPS // 2,
                    restart=first / "final.restart", tvis=tvis)
    dx, dv = scale_error(straight, cont)
    assert dx == 0.0 and dv == 0.0     # same arithmetic in the same order: bitwise equal
    # the dissipation ledger continues too: compare the contacts' forces at the end
    a = last_local_dump(tmp_path / "straight")
    b = last_local_dump(tmp_path / "second")
    assert np.array_equal(a, b)


@pytest.mark.parametrize("how", [(), ("-sf", "omp", "-pk", "omp", "2")],
                         ids=["OMP_NUM_THREADS", "sf omp"])
def test_threads_match_serial(serial, scene, model, tmp_path, how):
    first = run_deck(tmp_path / "a", scene, model, threads=2, extra=how)
    again = run_deck(tmp_path / "b", scene, model, threads=2, extra=how)
    assert np.array_equal(first, again)          # the same partition sums in the same order
    dx, dv = scale_error(serial, first)
    print(f"{model}, 2 threads vs 1: max |dx| = {dx:.2e} delta_c, max |dv| = {dv:.2e} m/s")
    assert dx < 1e-6 and dv < 1e-6               # round-off, grown as across ranks
    assert "2 OpenMP threads" in (tmp_path / "a" / "log.lammps").read_text()


@pytest.mark.mpi
def test_ranks_with_threads_match_serial(serial, scene, model, tmp_path):
    hybrid = run_deck(tmp_path, scene, model, nproc=2, threads=2)
    dx, dv = scale_error(serial, hybrid)
    print(f"{model}, 2 ranks x 2 threads vs 1: max |dx| = {dx:.2e} delta_c, |dv| = {dv:.2e}")
    assert dx < 1e-6 and dv < 1e-6


def test_restart_written_during_a_run_continues_exactly(serial_dir, serial, scene, model,
                                                        tmp_path):
    # the deck's 'restart 500 restart.a restart.b': restart.a holds step 3500 of the serial
    # run. The contact state in list order must reach the file as of that step, not as of
    # the last reneighboring
    cont = run_deck(tmp_path, scene, model, steps=STEPS - 3500,
                    restart=serial_dir / "restart.a")
    dx, dv = scale_error(serial, cont)
    assert dx == 0.0 and dv == 0.0


def test_every_restart_point_continues_exactly(scene, tmp_path):
    # the clamps of eqs. (42), (A8) leave a contact on its plateau to second order, so a
    # contact that slides and rolls at once sits a hair beyond zeta_crit after its step. A
    # run's set-up must take that state as it is: read back from a restart file at any
    # step, the forces, torques, potential energy and ledger are the uninterrupted run's,
    # bit for bit (clamping again at set-up moved 8 of 59 restart points of a 2 x 64 run by
    # 1e-9 E_imp in the ledger, and a resumed campaign run away from the uninterrupted one)
    from jkrdt.session import read_deck, start_lammps

    deck = scene.parent / rundir.DECK
    words = dict(run="no", outputs="no", settle="no", every="100", file=str(scene))

    def state(lmp):
        order = np.argsort(lmp.numpy.extract_atom("id"))
        ledger = lmp.numpy.extract_compute("p", 0, 1)[4:9].copy()
        return (np.hstack([lmp.numpy.extract_atom(name)[order] for name in ("f", "torque")]),
                lmp.get_thermo("pe"), ledger)

    straight = start_lammps()
    read_deck(straight, words, deck=deck)
    straight.command("run 0 post no")
    moved = []
    for k in range(1, 31):
        straight.command("run 100 pre no post no")
        path = tmp_path / f"step{100 * k}.restart"
        straight.command(f"write_restart {path}")
        again = start_lammps()
        read_deck(again, dict(words, read="read_restart", file=str(path)), deck=deck)
        again.command("run 0 post no")
        a, b = state(straight), state(again)
        again.close()
        if not (np.array_equal(a[0], b[0]) and a[1] == b[1] and np.array_equal(a[2], b[2])):
            moved.append(100 * k)
    p = dict(zip(ledger.VALUES, straight.numpy.extract_compute("p", 0, 1)))
    assert p["contacts"] > 100 and p["sliding"] > 0 and p["rolling"] > 0    # clamped
    straight.close()
    assert moved == [], f"restart points that did not continue exactly: {moved}"


BALANCED = """variable run index no
include {deck}
comm_style tiled
fix balanced all balance 100 1.0 {style}
run {half}
balance 1.0 {style}
run {half}
write_dump all custom {out}/final.dump id x y z vx vy vz omegax omegay omegaz modify sort id format float %.17g
"""


@pytest.mark.mpi
@pytest.mark.parametrize("nproc,style", [(2, "rcb"), (4, "rcb"), (2, "shift xyz 10 1.0"),
                                         (4, "shift xyz 10 1.0")])
def test_load_balancing_keeps_every_contact(serial, scene, model, tmp_path, nproc, style):
    # fix balance every 100 steps (always: threshold 1.0) and balance between two runs move
    # atoms between ranks through LAMMPS's irregular communication, before this plugin's
    # own pre_exchange: every contact and its state must travel with them. rcb used to
    # lose the rows of atoms that arrived on a rank that sent none ("contact ... stored
    # with only one of its atoms"); the run must equal 1 rank to round-off
    if style.startswith("shift"):
        tiled = BALANCED.replace("comm_style tiled\n", "")
    else:
        tiled = BALANCED
    deck = tmp_path / "in.balanced"
    deck.write_text(tiled.format(deck=DECK, style=style, half=STEPS // 2, out=tmp_path))
    cmd = [str(BIN / "mpirun"), "-np", str(nproc), str(BIN / "lmp"), "-in", str(deck),
           "-log", str(tmp_path / "log.lammps"), "-screen", "none",
           "-var", "file", str(scene), "-var", "out", str(tmp_path),
           "-var", "coeffs", scene_module.pair_coeff(ICE, model),
           "-var", "dt", repr(0.014 * S.t_c), "-var", "every", "500", "-var", "outputs", "no"]
    subprocess.run(cmd, check=True, cwd=tmp_path, timeout=600,
                   env=dict(os.environ, OMP_NUM_THREADS="1", **SLEEPING_RANKS))
    final = np.loadtxt(tmp_path / "final.dump", skiprows=9)
    dx, dv = scale_error(serial, final[np.argsort(final[:, 0])])
    log = (tmp_path / "log.lammps").read_text()
    assert "Loop time" in log and log.count("Loop time") == 2
    assert dx < 1e-6 and dv < 1e-6
