"""Reading a run's dumps, one frame at a time, plain or compressed (``.gz``, as the scene
deck writes them).

* ``atoms.dump.gz`` (``dump custom ... id type radius x y z vx vy vz c_coord
  d_departed_at``: the last, the time a grain's fragment departed, 0 if it did not) is read
  with MDAnalysis' LAMMPSDUMP reader; the extra per-atom columns (radius, the
  coordination c_coord, ...) come with each frame. MDAnalysis keeps positions in
  float32 and shifts them so that the box starts at 0: distances are good to about
  1e-7 of the box size (1e-13 m for a micron box, far below delta_c).
* ``contacts.dump.gz`` (``dump local ... c_bonds[*]`` of compute jkr/dt/contacts:
  id1 id2 delta a force |zeta| |xi| |phi|) has no MDAnalysis reader; it is read here
  as a stream of snapshots.

Both are generators: a long trajectory is never held in memory at once.
"""

from __future__ import annotations

import dataclasses
import gzip
import tempfile
import warnings
import weakref
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from jkrdt.rundir import ATOMS, BROKEN_STREAM, CONTACTS

#: columns of compute jkr/dt/contacts, in the order of the local dump
CONTACT_COLUMNS = ["id1", "id2", "delta", "a", "force", "zeta", "xi", "phi"]


#: the per-atom column of the time (s) a departed grain left; 0 for the others
DEPARTED_AT = "d_departed_at"


def atoms_universe(path, columns=("radius", "c_coord", DEPARTED_AT)):
    """An MDAnalysis Universe over a ``dump custom`` file with the given extra columns
    (those present in the file) in each frame's ``ts.data``."""
    import MDAnalysis as mda

    path = Path(path)
    with open_text(path) as f:
        header = next((line for line in f if line.startswith("ITEM: ATOMS")), None)
    if header is None:
        raise ValueError(f"{path}: not a LAMMPS dump (no 'ITEM: ATOMS' line)")
    present = header.split()[2:]
    missing = {"id", "x", "y", "z"} - set(present)
    if missing:
        raise ValueError(f"{path}: the dump lacks columns {sorted(missing)}; dump at least "
                         "'id type radius x y z'")
    extra = [c for c in columns if c in present]
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Guessed all Masses")
        warnings.filterwarnings("ignore", message="Reader has no dt information")
        try:
            return mda.Universe(str(path), format="LAMMPSDUMP", topology_format="LAMMPSDUMP",
                                additional_columns=extra, dt=1.0)
        except BROKEN_STREAM:
            readable = _readable_part(path)
            try:
                universe = mda.Universe(str(readable), format="LAMMPSDUMP",
                                        topology_format="LAMMPSDUMP",
                                        additional_columns=extra, dt=1.0)
            except (IndexError, ValueError, EOFError):
                readable.unlink(missing_ok=True)
                raise TruncatedDump(f"{path} holds no whole frame: the run was cut off while "
                                    "it wrote its first; continue it (jkrdt run), then "
                                    "analyse it") from None
            # the copy lives as long as the universe that reads it (or to the exit)
            weakref.finalize(universe, readable.unlink, missing_ok=True)
            return universe


def _readable_part(path: Path) -> Path:
    """A compressed dump that a kill left without its end, as far as it can be read, in a
    plain temporary file (MDAnalysis drops its cut-off last frame)."""
    part = tempfile.NamedTemporaryFile("w", prefix=path.name + ".", suffix=".readable",
                                       delete=False)
    with part, gzip.open(path, "rt") as f:
        try:
            for line in f:
                part.write(line)
        except BROKEN_STREAM:
            pass
    return Path(part.name)


def open_text(path):
    """A dump opened for reading as text, decompressed if its name ends in .gz."""
    path = Path(path)
    return gzip.open(path, "rt") if path.suffix == ".gz" else path.open()


class TruncatedDump(ValueError):
    """A dump whose last snapshot was cut off (the run was killed while writing it)."""


def iter_local(path) -> Iterator[tuple[int, np.ndarray]]:
    """(timestep, rows) of each snapshot of a ``dump local`` file, in file order; a
    snapshot cut off by the end of the file raises ``TruncatedDump``."""
    with open_text(path) as f:
        try:
            yield from _snapshots(f, path)
        except BROKEN_STREAM:     # a compressed stream that a kill left without its end
            raise TruncatedDump(f"{path}: the compressed dump is cut off") from None


def _snapshots(f, path):
    line = f.readline()
    while line:
        if not line.startswith("ITEM: TIMESTEP"):
            raise ValueError(f"{path}: expected 'ITEM: TIMESTEP', found {line.strip()!r}")
        try:
            step = int(f.readline())
            f.readline()                          # ITEM: NUMBER OF ENTRIES
            n = int(f.readline())
        except ValueError:
            raise TruncatedDump(f"{path}: the last snapshot's header is cut off") from None
        line = f.readline()
        while line and not line.startswith("ITEM: ENTRIES"):
            line = f.readline()                  # box bounds
        columns = len(line.split()) - 2              # after "ITEM: ENTRIES"
        rows = [f.readline().split() for _ in range(n)]
        if columns < 1 or any(len(r) != columns for r in rows):
            raise TruncatedDump(f"{path}: the snapshot of step {step} is cut off")
        yield step, np.array(rows, dtype=float).reshape(n, columns)
        line = f.readline()


def last_local_snapshot(path) -> np.ndarray:
    """Rows (id1 id2 delta a force ...) of the last snapshot of a ``dump local`` file."""
    rows = None
    for _, rows in iter_local(path):
        pass
    if rows is None:
        raise ValueError(f"{path}: no snapshot")
    return rows


class ContactSnapshots:
    """The contact list of a ``dump local`` file by timestep, read forward as frames ask
    for increasing steps (read again from the start for an earlier one)."""

    def __init__(self, path):
        self.path = Path(path)
        self._stream, self._pending = None, None

    def pairs(self, step: int) -> np.ndarray:
        """(n_c, 2) atom IDs of the bonded contacts at ``step``."""
        if self._stream is None or (self._pending is not None and self._pending[0] > step):
            self._stream, self._pending = iter_local(self.path), None
        while self._pending is None or self._pending[0] < step:
            self._pending = next(self._stream, None)
            if self._pending is None:
                raise ValueError(f"{self.path} ends before step {step}")
        if self._pending[0] != step:
            raise ValueError(f"{self.path} has no snapshot at step {step}: write both dumps "
                             "at the same interval")
        return self._pending[1][:, :2].astype(np.int64)


@dataclasses.dataclass
class Frame:
    step: int
    ids: np.ndarray          # (N,) atom IDs, ascending
    x: np.ndarray            # (N, 3) positions, m (float64 from MDAnalysis' float32)
    radius: np.ndarray       # (N,) m
    pairs: np.ndarray | None  # (n_c, 2) atom IDs of bonded contacts, None without a contact dump


def frames(run, atoms=ATOMS, contacts=CONTACTS) -> Iterator[Frame]:
    """The frames of a run directory: positions and radii from ``atoms``, joined by
    timestep to the contact list of ``contacts`` when that file exists. They end at the
    last frame both files hold whole (MDAnalysis drops a cut-off last atoms frame; a
    cut-off contact snapshot ends the frames there), which ``jkrdt.rundir.run_status`` then
    reports as a run cut off."""
    run = Path(run)
    u = atoms_universe(run / atoms)
    order = np.argsort(u.atoms.ids)
    ids = u.atoms.ids[order]
    local = ContactSnapshots(run / contacts) if (run / contacts).exists() else None
    for ts in u.trajectory:
        step = int(ts.data["step"])
        try:
            pairs = local.pairs(step) if local is not None else None
        except TruncatedDump:
            return                       # the frames end with the last whole snapshot
        if "radius" not in ts.data:
            raise ValueError(f"{run / atoms}: no radius column; dump 'id type radius x y z'")
        yield Frame(step=step, ids=ids, x=ts.positions[order].astype(np.float64),
                    radius=np.asarray(ts.data["radius"][order], dtype=np.float64), pairs=pairs)
