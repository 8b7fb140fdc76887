"""A resumed run is the run (issue 48): a scene above UNSORTED_MAX grains, continued from
any of its restart files, ends bit for bit where the uninterrupted run ends, serially and
on two ranks. The deck sorts its atoms at the restart steps (``sort``, default ``every``):
LAMMPS sorts at every run's set-up, so a continuation starts in the order the
uninterrupted run had just sorted into at that step, and every force sum keeps its order.
Sorting at other steps (LAMMPS's default every 1000 steps) is shown to lose the bits, so
the test can tell the two apart."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from jkrdt import rundir
from jkrdt.materials import ICE
from jkrdt.scene import Scene

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
    subprocess.run(cmd, check=True, timeout=600, capture_output=True)
    return dict(np.load(out / "ends.npz"))


def test_a_run_continued_from_any_restart_point_is_the_run_bit_for_bit(scene, tmp_path):
    ends = resume(scene, tmp_path / "aligned")
    straight = ends.pop("straight")
    assert sorted(ends) == [f"from{k * EVERY}" for k in (1, 2, 3)]
    for name, end in ends.items():
        assert np.array_equal(end, straight), (name, np.abs(end - straight).max())
    # sorting between restart points: the continuations part from the run in the last bits
    ends = resume(scene, tmp_path / "between", sort=1000)
    straight = ends.pop("straight")
    assert any(not np.array_equal(end, straight) for end in ends.values())


@pytest.mark.mpi
def test_on_two_ranks_too(scene, tmp_path):
    ends = resume(scene, tmp_path / "two", ranks=2)
    straight = ends.pop("straight")
    for name, end in ends.items():
        assert np.array_equal(end, straight), (name, np.abs(end - straight).max())
