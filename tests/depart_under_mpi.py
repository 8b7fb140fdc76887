"""Run by tests/test_depart.py as  mpirun -np 2 python depart_under_mpi.py SCENE OUT:
the scene on 2 ranks with departures; prints departed=N still=True|False error=E."""

import sys

import numpy as np
from lammps import LMP_VAR_ATOM
from mpi4py import MPI

from jkrdt.session import Session
from jkrdt.stopping import SettleRule

RULE = SettleRule(check_tc=20, window=5, tolerance=0.01, cap_tc=6000, depart="yes")


def departed(lmp):
    """(ID, x, v) of the departed grains of all ranks, by ID."""
    lmp.command("variable gone atom gmask(jkrdt_departed)")
    n = lmp.extract_global("nlocal")
    gone = lmp.numpy.extract_variable("gone", "all", LMP_VAR_ATOM)[:n] > 0
    mine = np.hstack([lmp.numpy.extract_atom("id")[:n][gone][:, None].astype(float),
                      lmp.numpy.extract_atom("x")[:n][gone], lmp.numpy.extract_atom("v")[:n][gone]])
    rows = np.vstack(MPI.COMM_WORLD.allgather(mine))
    return rows[np.argsort(rows[:, 0])]


with Session(sys.argv[1], sys.argv[2], every=0, settle=RULE) as s:
    s.run(60 * s.check, chunk=s.check, progress=False)
    before = departed(s.lmp)
    s.run(20 * s.check, chunk=s.check, progress=False)
    after = departed(s.lmp)
    kept = np.isin(after[:, 0], before[:, 0])
    still = bool(len(before) and np.array_equal(after[kept], before))
    error = s.energy_error()
    if MPI.COMM_WORLD.rank == 0:
        print(f"departed={len(before)} still={still} error={error:.3e}")
