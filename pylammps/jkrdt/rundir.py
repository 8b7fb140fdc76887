"""The run directory: the one place that knows what a collision's directory holds, how
each file is named, read and written, and what the deck is told. ``jkrdt setup`` and
``run``, campaigns, ``Session`` and the analysis all go through it; ``jkrdt.scene`` is the
scene itself, a value that knows no files.

    collision.data     the grains (target type 1, projectile type 2), LAMMPS data file
    collision.json     the scene's fields and its set-up (E_imp, b, gap, ...): ``write``/``read``
    in.collision.lmp   the scene's deck variables, then ``inputs/collision.lmp``: the deck
                       every route runs (``cd DIR && lmp -in in.collision.lmp -log none``)
    log.lammps         the run's log: thermo (the energy ledger) at every check, the settle
                       fix's stop line, the deck's last line (``run_status``)
    atoms.dump.gz, contacts.dump.gz   frames of the grains and of the bonded contacts
    checks.csv         the settle rule's table of the fragments at every check
    restart.a, restart.b               restart files of a run under way, alternately
    final.restart, final.dump.gz       the end state, written when the run ends
    frames.csv, outcome.json, outcome/energy/timeline .png/.pdf   the analysis
    .claim             the lock of the process that runs it (jkrdt run, a Session, a
                       campaign): ``claim``, ``hold``, ``running``

The columns and fields of each record are described in ``docs/records.md``.

A run is finished when ``outcome.json`` exists (written last, atomically) and holds no
``stop_reason`` "error"; a run that failed has one of the same schema (``parameters``)
with the error as its ``problem``. A run that was cut off has none (or that of a partial
analysis, stop_reason "cut off" or "in progress", which does not count): it is continued from
its newer whole restart file, its record cut back to that step (``resume_point``,
``cut_back``, ``continuation``).
"""

from __future__ import annotations

import dataclasses
import fcntl
import gzip
import zlib
import json
import os
import re
import socket
import time
from pathlib import Path

from .atomic import write_atomic, write_json
from .datafile import write_sphere_data
from .materials import from_dict
from .scene import Scene

# ---- the file names ------------------------------------------------------------------
DATA, META, DECK = "collision.data", "collision.json", "in.collision.lmp"
#: a run's record (inputs/collision.lmp writes them): the frames of atoms and of contacts
#: (compressed, every ``frames`` checks and at the end), the settle rule's table of the
#: fragments at every check, and the log with the energies at every check
ATOMS, CONTACTS, CHECKS, LOG = "atoms.dump.gz", "contacts.dump.gz", "checks.csv", "log.lammps"
#: the outputs a new run of a scene replaces
RUN_OUTPUTS = (ATOMS, CONTACTS, CHECKS, LOG)
#: the end state (the restart file, and the grains with their spins, compressed) and the
#: restart files of a run under way, written alternately at every check
FINAL_RESTART, FINAL_DUMP = "final.restart", "final.dump.gz"
ROLLING_RESTARTS = ("restart.a", "restart.b")
#: what jkrdt analyse writes
FRAMES, OUTCOME = "frames.csv", "outcome.json"
ANALYSIS_OUTPUTS = (FRAMES, OUTCOME, "outcome.png", "outcome.pdf", "energy.png",
                    "energy.pdf", "timeline.png", "timeline.pdf")
#: a finished run's small record, what a study commits of each run (under 1 MB at 2 x 5000):
#: its scene's metadata, the settle rule's table, the timeline with the energy ledger and
#: N_con, N_cut at every check, the outcome and its two pictures; the re-analysis of a
#: study needs nothing else
RECORD = (META, CHECKS, FRAMES, OUTCOME, "outcome.png", "timeline.png")
#: a campaign's lock on a run (``claim``)
CLAIM = ".claim"
#: what a scene directory holds once set up, run and analysed (all that a fresh scene clears)
SCENE_FILES = (DATA, META, DECK, *RUN_OUTPUTS, *ANALYSIS_OUTPUTS, *ROLLING_RESTARTS,
               FINAL_RESTART, FINAL_DUMP)

#: up to this many grains a scene does not sort its atoms (``atom_modify sort 0``): at this
#: size sorting gains nothing (2 x 1000: bins 2.1x faster than nsq either way); at 2 x 25000
#: it makes the loop 1.7-2x faster. Larger scenes sort at the restart steps (the deck's
#: ``sort``, default ``every``): LAMMPS sorts at every run's set-up, and a continued run
#: then starts from the order the uninterrupted one had just sorted into, so the force sums
#: keep their order and the continuation is the same run bit for bit (issue 48)
UNSORTED_MAX = 2000

#: the deck's last line, printed after the last frames and final.restart
FINISH_LINE = "jkr/dt: run finished step"
#: the line fix jkr/dt/settle writes when it ends a run
SETTLE_LINE = "jkr/dt/settle: stop_reason"
# ... and the line it writes when it ends a part of the run for wider neighbor bins
PART_LINE = "jkr/dt/settle: new run for wider bins step"


# ---- clearing ----------------------------------------------------------------------
def clear(directory, names=SCENE_FILES) -> None:
    """Remove the files ``names`` (default: everything a scene and its run wrote) from
    ``directory``, and nothing else."""
    for name in names:
        (Path(directory) / name).unlink(missing_ok=True)


def clear_run(directory) -> None:
    """Remove a run's record, end state and analysis, keeping the scene."""
    clear(directory, [n for n in SCENE_FILES if n not in (DATA, META, DECK)])


# ---- collision.json <-> Scene --------------------------------------------------------
def metadata(scene: Scene) -> dict:
    """``collision.json`` of ``scene``, without the set-up's geometry."""
    meta = dict(N_tar=scene.n_tar, N_pro=scene.n_pro, v_col=scene.v_col, B_off=scene.b_off,
                seed=scene.seed, material=dataclasses.asdict(scene.material),
                radius=scene.radius, dimension=scene.dim, E_imp=scene.E_imp, kind=scene.kind,
                model=scene.model)
    if scene.dt_over_tc is not None:
        meta.update(dt_over_tc=scene.dt_over_tc, dt_reason=scene.dt_reason)
    meta.update(skin=scene.skin_for(scene.time_step()[0]), skin_given=scene.skin is not None)
    if scene.bond != "equilibrium":
        meta.update(bond=scene.bond)
    if scene.gap is not None:
        meta.update(gap_given=scene.gap)
    return meta


def from_metadata(meta: dict) -> Scene:
    """The scene of a ``collision.json``."""
    return Scene(material=from_dict(meta["material"]), n_tar=meta["N_tar"],
                 n_pro=meta["N_pro"], v_col=meta["v_col"], b_off=meta["B_off"],
                 seed=meta.get("seed"), kind=meta.get("kind") or "bpca",
                 dim=meta["dimension"], radius=meta["radius"],
                 model=meta.get("model") or "frictional", dt_over_tc=meta.get("dt_over_tc"),
                 dt_reason=meta.get("dt_reason"),
                 skin=meta["skin"] if meta.get("skin_given") else None,
                 bond=meta.get("bond", "equilibrium"), gap=meta.get("gap_given"))


def read_metadata(directory) -> dict:
    path = Path(directory) / META
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: {directory} is not a scene; write one "
                                "with 'jkrdt setup' (or jkrdt.rundir.write)")
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as err:
        raise ValueError(f"{path} is not valid JSON ({err}): write the scene again with "
                         "'jkrdt setup --force'") from None


def read(directory) -> Scene:
    """The scene written into ``directory``."""
    return from_metadata(read_metadata(directory))


def write(directory, scene: Scene, placed=None, **extra) -> Path:
    """Write ``scene`` into ``directory``: its grains (``placed``, a
    ``jkrdt.collision.Collision``, default ``scene.collide()``), ``collision.json`` (with
    ``extra`` fields) and its deck. Returns the directory."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    placed = scene.collide() if placed is None else placed
    write_sphere_data(directory / DATA, placed.x, scene.radius, scene.material.density,
                      v=placed.v, types=placed.body, margin=20 * scene.radius)
    write_json(directory / META, dict(metadata(scene), **placed.meta, **extra))
    write_deck(directory, scene)
    return directory


# ---- the deck and its variables ------------------------------------------------------
def time_variables(scene: Scene, dt_over_tc: float | None = None) -> dict:
    """The deck's dt (s), dt_over_tc, dt_note and skin for ``dt_over_tc`` (default the
    scene's; see ``Scene.time_step``)."""
    ratio, why = scene.time_step(dt_over_tc)
    return dict(dt=ratio * scene.scales.t_c, dt_over_tc=ratio, dt_note=why.replace('"', "'"),
                skin=scene.skin_for(ratio))


def deck_variables(scene: Scene) -> dict:
    """The variables of ``inputs/collision.lmp`` that make it run ``scene``."""
    few = scene.n_tar + scene.n_pro <= UNSORTED_MAX
    return dict(file=DATA, dim=scene.dim, coeffs=scene.pair_coeff, **time_variables(scene),
                **(dict(sort="0") if few else {}))


def fixed_steps(steps: int, every: int) -> dict:
    """The deck variables of a run of ``steps`` steps without the settle rule, its frames
    every ``every`` steps."""
    return dict(settle="no", steps=steps, every=every)


def continuation(restart, steps_left: int | None = None) -> dict:
    """The deck variables that continue a cut-off run from ``restart``, appending to its
    record (cut back first: ``cut_back``), for the ``steps_left`` of its cap or steps."""
    words = dict(read="read_restart", file=str(restart), append="yes")
    if steps_left is not None:
        words["steps"] = steps_left
    return words


def find_template(name: str = "collision.lmp") -> Path:
    """A deck of ``inputs/``: the copy installed in the package, else the checkout's."""
    here = Path(__file__).resolve().parent
    for base in [here, Path.cwd(), *here.parents]:
        path = base / "inputs" / name
        if path.exists():
            return path
    raise FileNotFoundError(f"inputs/{name} not found: reinstall with 'pip install .' "
                            "or run from the repository root")


def deck(directory) -> Path:
    """The scene's own deck in ``directory``; raises with the fix if it is missing."""
    path = Path(directory) / DECK
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: write the scene with 'jkrdt setup', "
                                f"or its deck with jkrdt.rundir.write_deck('{directory}')")
    return path


def write_deck(directory, scene: Scene | None = None) -> Path:
    """``in.collision.lmp``: the scene's variables, then ``inputs/collision.lmp`` verbatim
    (a variable's first definition wins, so ``-var NAME VALUE`` still overrides)."""
    directory = Path(directory)
    scene = read(directory) if scene is None else scene
    lines = ["# jkr/dt: the scene in this directory (written by jkrdt.rundir.write_deck); run",
             "#   lmp -in in.collision.lmp     or     mpirun -np 2 lmp -in in.collision.lmp",
             "# here. Any variable below can be overridden with -var NAME VALUE.", ""]
    lines += [f'variable {name:<10} index "{value}"'
              for name, value in deck_variables(scene).items()]
    return write_atomic(directory / DECK,
                        "\n".join(lines) + "\n\n" + find_template().read_text())


# ---- the log: thermo, status ---------------------------------------------------------
def read_thermo(log, text: str | None = None) -> dict:
    """Columns of every thermo block in ``log`` (numpy arrays), concatenated (repeated steps
    dropped); the energy budget they add up to is ``jkrdt.ledger.energy_budget``. ``text``:
    the log's text, when the caller has read it already."""
    import numpy as np

    columns, columns_done, rows = None, None, []
    text = Path(log).read_text() if text is None else text
    for line in text.splitlines():
        words = line.split()
        if words and words[0] == "Step":
            columns = words
            continue
        if columns and words and words[0] == "Loop":
            columns_done = columns
            columns = None
            continue
        if columns and len(words) == len(columns):
            try:
                rows.append([float(w) for w in words])
            except ValueError:
                pass
    if not rows:
        raise ValueError(f"{log}: no thermo output found")
    names = columns or columns_done
    data = np.array(rows)
    _, keep = np.unique(data[:, 0], return_index=True)
    data = data[np.sort(keep)]
    return {name: data[:, k] for k, name in enumerate(names)}


#: the stop reason of a run that a live process is running now (its claim is held)
IN_PROGRESS = "in progress"


@dataclasses.dataclass
class RunStatus:
    """Why a run stopped: settled, cap, steps (its fixed steps), error or cut off; or that
    it has not stopped yet (``IN_PROGRESS``)."""

    stop_reason: str
    stop_step: int | None       # the step the run ended at (None if unknown)
    problem: str | None         # why the run is not a complete outcome, or None
    error: str | None = None    # the LAMMPS error line, if any


def settle_window(text: str) -> tuple[int, float] | None:
    """The settle rule's window (checks) and tolerance as the run's log defined them (its
    ``fix ... jkr/dt/settle N window K tolerance f`` line, the variables substituted);
    None for a run without the rule."""
    found = None
    for m in re.finditer(r"jkr/dt/settle \d+ window (\d+) tolerance ([0-9.eE+-]+)\s", text):
        found = (int(m.group(1)), float(m.group(2)))
    return found


def _settle_fields(line: str) -> dict:
    words = line.split()[1:]                 # after "jkr/dt/settle:"
    return dict(zip(words[::2], words[1::2]))


def run_status(run, last_dump_step: int | None = None, text: str | None = None) -> RunStatus:
    """The status of run directory ``run`` from its log (``text``: the log's text, when the
    caller has read it already); with ``last_dump_step``, also whether the dumps reach the
    end of the run.

    * settled / cap: the last line the settle fix writes when it ends a run;
    * steps: a run of a fixed number of steps (no settle rule) that completed;
    * error: the log holds a LAMMPS ERROR line;
    * cut off: the log ends inside a run (the process was killed), or between two of its
      run commands (a campaign or session that runs in chunks, killed between two), or
      the dumps end before the run did.

    A run has ended by its own rule only when its log holds the deck's last line
    (``FINISH_LINE``), which the deck's end part (``label finish``, also what a Session
    runs when it closes) prints after writing the last frames and final.restart."""
    log = Path(run) / LOG
    holder = running(run)
    if not log.exists():
        if holder:
            return RunStatus(IN_PROGRESS, None, f"the run is starting ({holder})")
        return RunStatus("cut off", None, f"{log} does not exist: no way to tell how the run "
                         "ended")
    lines = (log.read_text(errors="replace") if text is None else text).splitlines()
    errors = [line.strip() for line in lines if line.startswith("ERROR")]
    settle = [_settle_fields(line) for line in lines if line.startswith(SETTLE_LINE)]
    header = [k for k, line in enumerate(lines) if line.split()[:1] == ["Step"]]
    loops = [k for k, line in enumerate(lines) if line.startswith("Loop time of")]
    last_step = None
    if header:
        for line in lines[header[-1] + 1:]:
            words = line.split()
            if not words or not words[0].isdigit():
                break
            last_step = int(words[0])
    if errors:
        return RunStatus("error", last_step, f"the run failed: {errors[-1]}", errors[-1])
    whole = any(line.startswith(FINISH_LINE) for line in lines)
    if holder and not whole:
        return RunStatus(IN_PROGRESS, last_step, f"in progress at step {last_step} ({holder})")
    if header and (not loops or loops[-1] < header[-1]):
        return RunStatus("cut off", last_step, f"{log} ends inside a run at step {last_step}: "
                         "the run was cut off")
    parts = [k for k, line in enumerate(lines) if line.startswith(PART_LINE)]
    if parts and not any(k > parts[-1] for k in header):
        return RunStatus("cut off", last_step, f"{log}: the settle rule ended a part of the "
                         f"run at step {last_step} for wider neighbor bins, and the deck did "
                         "not run the next part (a deck written before runs in parts): write "
                         "the scene anew (jkrdt setup ... --force) and run it again")
    if not whole:
        return RunStatus("cut off", last_step, f"{log} stops at step {last_step} without its "
                         f"last line ('{FINISH_LINE} ...'): the run was cut off between two "
                         "of its run commands; run it again (jkrdt run), let jkrdt campaign "
                         "resume it, or analyse what is there with --partial")
    if settle:
        reason, stop = settle[-1]["stop_reason"], int(settle[-1]["step"])
        # a later run without the rule (e.g. 'run 1000' after settling) ends elsewhere
        if last_step is not None and last_step > stop:
            reason, stop = "steps", last_step
    else:
        reason, stop = "steps", last_step
    if last_dump_step is not None and stop is not None and last_dump_step < stop:
        return RunStatus("cut off", stop, f"the dumps end at step {last_dump_step}, before the "
                         f"run's end at step {stop}")
    return RunStatus(reason, stop, None)


# ---- outcome.json --------------------------------------------------------------------
#: the fields of ``outcome.json``, in the order it holds them; docs/records.md says what
#: each is (a test holds the page to these lists). The run's parameters open it, for a
#: failed run too (``parameters``) ...
PARAMETER_FIELDS = ("run", "N_tar", "N_pro", "v_col", "B_off", "seed", "model", "kind",
                    "dimension", "material", "xi_crit", "tvis", "radius")
#: ... then what ``jkrdt analyse`` (``analysis/run.py``) adds: the energy scales, the
#: outcome (the measures of ``analysis.outcome.Outcome``) and its fragments, how the run
#: ended, the energy partition, the contact counts, the pictures and the paper's diagnostics
ANALYSIS_FIELDS = ("E_imp", "n_k", "E_roll", "E_break", "E_imp_over_nk_Eroll",
                   "E_imp_over_nk_Ebreak", "step", "n_total", "n_largest", "n_second",
                   "n_fragments", "growth_efficiency", "gyration_radius_largest",
                   "contacts_per_particle", "fragment_sizes", "N_cum", "contacts_source",
                   "stop_reason", "stop_step", "last_step", "last_frame_step", "outcome_from",
                   "settled", "problem", "shape_at_end", "time_end", "time_end_over_tc",
                   "kinetic_start", "kinetic_left", "kinetic_departed", "potential_change",
                   "energy_drift", "energy_error", "energy_warning", "dissipated_fraction",
                   "dissipated_by_channel", "N_con", "N_cut", "contacts_start",
                   "contacts_end", "pictures", "diagnostics")
OUTCOME_FIELDS = PARAMETER_FIELDS + ANALYSIS_FIELDS


def parameters(directory, meta: dict | None = None) -> dict:
    """The fields that open every ``outcome.json``, of a finished run or a failed one: the
    run and the parameters of its scene."""
    meta = read_metadata(directory) if meta is None else meta
    mat = meta["material"]
    values = dict(run=str(directory), N_tar=meta["N_tar"], N_pro=meta["N_pro"],
                  v_col=meta["v_col"], B_off=meta["B_off"], seed=meta.get("seed"),
                  model=meta.get("model") or "frictional", kind=meta.get("kind") or "bpca",
                  dimension=meta["dimension"], material=mat["name"],
                  xi_crit=mat.get("xi_crit"), tvis=mat.get("tvis", 0.0), radius=meta["radius"])
    return {name: values[name] for name in PARAMETER_FIELDS}


def read_outcome(directory) -> dict | None:
    """The run's ``outcome.json``, or None if it has none."""
    path = Path(directory) / OUTCOME
    return json.loads(path.read_text()) if path.exists() else None


def finished(directory) -> bool:
    """Whether the run has its outcome (complete, or recorded as failed); the outcome of a
    partial analysis (``jkrdt analyse --partial`` of a run cut off or in progress) is not
    one."""
    if not (Path(directory) / OUTCOME).exists():
        return False
    outcome = read_outcome(directory)
    return outcome is None or outcome.get("stop_reason") not in ("cut off", IN_PROGRESS)


def failed(directory) -> bool:
    """Whether the run's outcome records a failure."""
    outcome = read_outcome(directory)
    return outcome is not None and outcome.get("stop_reason") == "error"


def write_outcome(directory, outcome: dict) -> Path:
    """``outcome.json``, its fields in the order of ``OUTCOME_FIELDS``; a field not
    declared there is refused (declare it there and in docs/records.md)."""
    unknown = sorted(set(outcome) - set(OUTCOME_FIELDS))
    if unknown:
        raise ValueError(f"outcome.json has no field {unknown}: declare it in "
                         "jkrdt.rundir.OUTCOME_FIELDS and docs/records.md")
    return write_json(Path(directory) / OUTCOME,
                      {name: outcome[name] for name in OUTCOME_FIELDS if name in outcome})


def record_failure(directory, error: str) -> Path:
    """``outcome.json`` of a run that failed: its parameters and the error, no outcome."""
    return write_outcome(directory, dict(parameters(directory), stop_reason="error",
                                         settled=False, problem=error))


# ---- a campaign's claim, and continuing a cut-off run ----------------------------------
def claim(directory, even_finished: bool = False):
    """An open, locked ``directory/.claim``, or None if another process holds the run or
    it has finished (unless ``even_finished``: a run started again from the start).
    Closing the file (or the holder's death) releases the claim: a stale claim of a dead
    process is taken over. One claim per process and directory (POSIX locks are the
    process's: closing a second handle would release the first)."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    f = open(directory / CLAIM, "a+")
    try:
        fcntl.lockf(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        f.close()
        return None
    if not even_finished and finished(directory):        # finished while we looked
        f.close()
        return None
    f.truncate(0)
    f.write(f"{socket.gethostname()} pid {os.getpid()} since {time.ctime()}\n")
    f.flush()
    _HELD[directory.resolve()] = f
    return f


#: the claims this process holds, by directory: ``running`` must not probe those (a probe's
#: close would release the process's lock)
_HELD: dict = {}


def running(directory) -> str | None:
    """Who runs ``directory`` now (its claim's line: host, pid, since when), or None when
    no other live process holds its claim (this process's own run is told by its log)."""
    path = Path(directory) / CLAIM
    mine = _HELD.get(Path(directory).resolve())
    if (mine is not None and not mine.closed) or not path.exists():
        return None
    with open(path, "a+") as f:
        try:
            fcntl.lockf(f, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except OSError:
            f.seek(0)
            return f.read().strip() or "another process"
    return None


class RunHeld(RuntimeError):
    """Another process is running this directory's run."""


def hold(directory):
    """The claim on ``directory`` for a run that is started or continued by hand (jkrdt
    run, a Session), finished or not; raises RunHeld naming the holder if another
    process runs it. Close the returned file to release it."""
    held = claim(directory, even_finished=True)
    if held is None:
        try:
            holder = (Path(directory) / CLAIM).read_text().strip() or "another process"
        except OSError:
            holder = "another process"
        raise RunHeld(f"{directory} is being run by {holder}: wait for it to end, or stop "
                      "it (jkrdt run continues a run that was stopped)")
    return held


def resume_point(directory, end_step: int | None = None):
    """(restart file, its step) to continue a cut-off run from, or None: the newer restart
    file that LAMMPS reads whole (a file cut off while being written is passed over). One
    written where the run ended (``end_step``, its cap, or the step the settle rule
    stopped it at, as the log says: a run killed while it wrote its end) is passed over
    for the one before, so the continuation runs the last check interval again and ends
    where the uninterrupted run ended, with the same lines and files."""
    from mpi4py import MPI

    from .instance import start_lammps

    directory = Path(directory)
    if not (directory / META).exists():
        return None
    if (directory / LOG).exists():
        stops = [int(_settle_fields(line).get("step", -1)) for line in
                 (directory / LOG).read_text(errors="replace").splitlines()
                 if line.startswith(SETTLE_LINE)]
        if stops and stops[-1] >= 0:
            end_step = stops[-1] if end_step is None else min(end_step, stops[-1])
    rolling = (directory / name for name in ROLLING_RESTARTS)
    found = sorted((p for p in rolling if p.exists()), key=lambda p: p.stat().st_mtime,
                   reverse=True)
    for path in found:
        lmp = start_lammps(MPI.COMM_SELF)
        try:
            lmp.command(f"read_restart {path}")
            step = int(lmp.extract_global("ntimestep"))
        except Exception:
            continue
        finally:
            lmp.close()
        if end_step is None or step < end_step:
            return path, step
    return None


#: what reading a compressed dump raises where a kill cut it off: the stream ends inside a
#: member (EOFError), or a later write follows a member cut short (zlib.error, a bad header)
BROKEN_STREAM = (EOFError, zlib.error, gzip.BadGzipFile)


def cut_dump(path: Path, step: int) -> None:
    """Keep the snapshots of a dump (plain or compressed) before ``step`` (the resumed run
    writes ``step`` again); a compressed stream cut off by a kill ends where it was cut."""
    if not path.exists():
        return
    opener = gzip.open if path.suffix == ".gz" else open
    kept = path.with_name(path.name + ".cut")
    with opener(path, "rb") as src, opener(kept, "wb") as dst:
        try:
            for line in src:
                if line.startswith(b"ITEM: TIMESTEP"):
                    at = src.readline()
                    if int(at) >= step:
                        break
                    line += at
                dst.write(line)
        except BROKEN_STREAM:
            pass
    kept.replace(path)


def cut_table(path: Path, step: int) -> None:
    """Keep the rows of the settle rule's table up to ``step`` (its check at ``step`` came
    before the restart file; the resumed run writes the checks after it)."""
    if not path.exists():
        return
    lines = path.read_text(errors="replace").splitlines(keepends=True)
    keep = [line for line in lines[1:] if line.split(",")[0].isdigit()
            and int(line.split(",")[0]) <= step and line.endswith("\n")]
    write_atomic(path, "".join(lines[:1] + keep))


def cut_log(path: Path, step: int) -> None:
    """Keep a log up to its thermo row of ``step`` (the resumed run appends from there)."""
    if not path.exists():
        return
    lines = path.read_text(errors="replace").splitlines(keepends=True)
    last = 0
    for k, line in enumerate(lines):
        words = line.split()
        if words and words[0].isdigit() and int(words[0]) <= step and len(words) > 3:
            last = k + 1
    write_atomic(path, "".join(lines[:last]))


def cut_back(directory, step: int) -> None:
    """A cut-off run's record cut back to ``step`` (its restart file's), to be appended
    to; an analysis of it (``--partial``) goes, so that none sits beside the longer run."""
    directory = Path(directory)
    for name in (ATOMS, CONTACTS):
        cut_dump(directory / name, step)
    cut_table(directory / CHECKS, step)
    cut_log(directory / LOG, step)
    clear(directory, ANALYSIS_OUTPUTS)
