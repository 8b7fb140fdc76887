"""Run by tests/test_resume_exact.py, serially or as  mpirun -np K python resume_exact.py
SCENE OUT EVERY CHUNKS [DECK VARIABLES as name=value ...]: the scene's own deck run for
CHUNKS x EVERY steps with its restart files every EVERY steps (a copy kept of each), then
continued from each restart point but the last to the same end; rank 0 writes OUT/ends.npz
with the final positions, velocities and spins by atom ID of the straight run ("straight")
and of each continuation ("from<step>")."""

import shutil
import sys
from pathlib import Path

import numpy as np
from mpi4py import MPI

from jkrdt import rundir
from jkrdt.session import read_deck, start_lammps

scene, out, every, chunks = Path(sys.argv[1]), Path(sys.argv[2]), int(sys.argv[3]), \
    int(sys.argv[4])
extra = dict(word.split("=", 1) for word in sys.argv[5:])
comm = MPI.COMM_WORLD
words = dict(file=str(scene / rundir.DATA), out=str(out), outputs="yes", every=str(every),
             frames="1000", **extra)


def state(lmp):
    """x, v, omega of every grain by ID (on rank 0; None elsewhere)."""
    n = lmp.extract_global("nlocal")
    mine = [lmp.numpy.extract_atom(name)[:n].copy() for name in ("id", "x", "v", "omega")]
    got = comm.gather(mine, root=0)
    if comm.rank:
        return None
    ids = np.concatenate([g[0] for g in got])
    order = np.argsort(ids)
    return np.hstack([np.vstack([g[k] for g in got])[order] for k in (1, 2, 3)])


ends = {}
straight = start_lammps(comm)
read_deck(straight, words, deck=scene / rundir.DECK)
for k in range(1, chunks + 1):
    # one run command, as the deck runs; the restart file of its last step kept
    straight.command(f"run {every} {'pre no ' if k > 1 else ''}post no")
    comm.Barrier()
    if comm.rank == 0:
        newest = max((out / name for name in rundir.ROLLING_RESTARTS
                      if (out / name).exists()), key=lambda p: p.stat().st_mtime)
        shutil.copy(newest, out / f"step{k * every}.restart")
    comm.Barrier()
ends["straight"] = state(straight)
straight.close()
for k in range(1, chunks):
    if comm.rank == 0:
        (out / f"from{k * every}").mkdir(exist_ok=True)
    comm.Barrier()
    again = start_lammps(comm)
    read_deck(again, dict(words, out=str(out / f"from{k * every}"), read="read_restart",
                          file=str(out / f"step{k * every}.restart")),
              deck=scene / rundir.DECK)
    again.command(f"run {(chunks - k) * every} post no")
    ends[f"from{k * every}"] = state(again)
    again.close()
if comm.rank == 0:
    np.savez(out / "ends.npz", **ends)
