"""A resumed run is the run (issue 48): a scene above UNSORTED_MAX grains, continued from
any of its restart files, ends bit for bit where the uninterrupted run ends, serially and
on two ranks. The deck sorts its atoms at the restart steps (``sort``, default ``every``):
LAMMPS sorts at every run's set-up, so a continuation starts in the order the
uninterrupted run had just sorted into at that step, and every force sum keeps its order.
Sorting at other steps (LAMMPS's default every 1000 steps) is shown to lose the bits, so
the test can tell the two apart."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jkrdt import rundir
from jkrdt.materials import ICE
from jkrdt.scene import Scene

from conftest import SLEEPING_RANKS

BIN = Path(sys.executable).parent
HERE = Path(__file__).resolve().parent
EVERY, CHUNKS = 300, 4


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    # 2 x 2500 grains (above UNSORTED_MAX, so the deck sorts), frictional (the most state
    # a contact carries), 39.8 m/s at B_off 0.3: contacts made, cut and sliding from the
    # first steps on
    where = tmp_path_factory.mktemp("scene")
    rundir.write(where, Scene(ICE, 2500, 2500, v_col=39.8, b_off=0.3, seed=3,
                              model="frictional"))
    assert 5000 > rundir.UNSORTED_MAX
    return where


def resume(scene, out, ranks=1, **variables):
    cmd = [sys.executable, str(HERE / "resume_exact.py"), str(scene), str(out), str(EVERY),
           str(CHUNKS), *(f"{k}={v}" for k, v in variables.items())]
    if ranks > 1:
        cmd = [str(BIN / "mpirun"), "-np", str(ranks)] + cmd
    out.mkdir()
    subprocess.run(cmd, check=True, timeout=600, capture_output=True,
                   env=dict(os.environ, **SLEEPING_RANKS))
    return dict(np.load(out / "ends.npz"))


def assert_each_continuation_is_the_run(ends: dict) -> None:
    """Every continuation (from each restart point but the last) ends bit for bit where
    the uninterrupted run ends."""
    straight = ends.pop("straight")
    assert sorted(ends) == [f"from{k * EVERY}" for k in range(1, CHUNKS)]
    for name, end in ends.items():
        assert np.array_equal(end, straight), (name, np.abs(end - straight).max())


def test_a_run_continued_from_any_restart_point_is_the_run_bit_for_bit(scene, tmp_path):
    assert_each_continuation_is_the_run(resume(scene, tmp_path / "aligned"))
    # sorting between restart points: the continuations part from the run in the last bits
    ends = resume(scene, tmp_path / "between", sort=1000)
    straight = ends.pop("straight")
    assert any(not np.array_equal(end, straight) for end in ends.values())


@pytest.mark.mpi
def test_on_two_ranks_too(scene, tmp_path):
    assert_each_continuation_is_the_run(resume(scene, tmp_path / "two", ranks=2))


@pytest.mark.mpi
def test_on_four_ranks_with_fix_balance(scene, tmp_path):
    # the deck's default balance (rcb, comm_style tiled): each continuation reads its
    # restart file into LAMMPS's regular grid of sub-domains and cuts them afresh
    assert_each_continuation_is_the_run(resume(scene, tmp_path / "four", ranks=4))


def test_a_campaign_killed_three_times_publishes_the_uninterrupted_numbers(tmp_path):
    # 4 collisions of 2 x 2500 grains (two offsets x two seeds), each to a cap of 60 t_c
    # with a check (and restart files) every 5 t_c, run once straight and once killed
    # with SIGKILL at three moments (drawn from a fixed seed) and started again each time:
    # every outcome.json and every checks.csv are the same but for where the run lies and
    # the timing columns
    import json
    import os
    import random
    import signal
    import time

    from jkrdt.analysis.tables import read_csv
    from jkrdt.campaign import run_campaign

    spec = dict(kind="bpca", dim=3, n_tar=2500, n_pro=2500, material="ice",
                model="frictionless", v_col=[39.8], b_off2=[0.0, 0.25], seeds=[1, 2],
                settle=dict(check_tc=5, cap_tc=60))
    path = tmp_path / "spec.json"
    path.write_text(json.dumps(spec))
    t0 = time.time()
    run_campaign(path, tmp_path / "straight", progress=False)
    whole = time.time() - t0
    moments = random.Random(48)
    for _ in range(3):
        started = time.time()
        proc = subprocess.Popen([str(BIN / "jkrdt"), "campaign", str(path),
                                 str(tmp_path / "killed"), "--quiet"], start_new_session=True)
        # a kill inside a run: once the campaign has written a restart file, a moment
        # later drawn from a fixed seed (a fixed delay fell between runs on a loaded host)
        while proc.poll() is None and not any(
                p.stat().st_mtime > started for name in rundir.ROLLING_RESTARTS
                for p in (tmp_path / "killed").rglob(name)):
            time.sleep(0.05)
        time.sleep(moments.uniform(0.0, 0.3) * whole / 4)
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    assert run_campaign(path, tmp_path / "killed", progress=False)["runs"] == 4
    continued = sum(p.read_text().count("Reading restart file")
                    for p in (tmp_path / "killed").rglob("log.lammps"))
    assert continued >= 1, "no kill fell inside a run"
    timing = {"wall", "memory_mb", "peak_rss_mb"}
    outcomes = sorted((tmp_path / "straight").rglob("outcome.json"))
    assert len(outcomes) == 4
    for straight in outcomes:
        again = tmp_path / "killed" / straight.parent.relative_to(tmp_path / "straight")
        a, b = (json.loads(p.read_text()) for p in (straight, again / "outcome.json"))
        for o in (a, b):
            o.pop("run"), o.pop("pictures", None)
        assert a == b, straight.parent
        rows = [[{k: v for k, v in r.items() if k not in timing}
                 for r in {r["step"]: r for r in read_csv(d / "checks.csv")}.values()]
                for d in (straight.parent, again)]
        assert rows[0] == rows[1], straight.parent
