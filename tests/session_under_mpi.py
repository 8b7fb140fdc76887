"""Run by tests/test_session.py as  mpirun -np 2 python session_under_mpi.py SCENE OUT:
a Session over all ranks; rank 0 saves the energies and whether every rank got them."""

import sys

import numpy as np
from mpi4py import MPI

from jkrdt.session import Session

scene, out = sys.argv[1], sys.argv[2]
comm = MPI.COMM_WORLD
with Session(scene, out, every=500) as session:
    session.run(2000, chunk=250, progress=False)
    energies = session.energies()
    ranks = session.lmp.extract_setting("world_size")
same = comm.gather(energies["total"], root=0)
if comm.rank == 0:
    np.savez(f"{out}/energies.npz", ranks=ranks, same_on_all_ranks=all(
        np.array_equal(same[0], other) for other in same), **energies)
