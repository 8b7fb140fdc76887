"""Why a run stopped, read from its LAMMPS log: settled, cap, steps, error or cut off.

* ``settled`` / ``cap``: the last ``jkr/dt/settle: stop_reason ...`` line that fix
  jkr/dt/settle writes when it ends a run (``jkrdt.stopping`` has the rule);
* ``steps``: a run of a fixed number of steps (no settle rule) that completed;
* ``error``: the log holds a LAMMPS ERROR line;
* ``cut off``: the log ends inside a run (the process was killed), or between two of its
  run commands (a campaign or session that runs in chunks, killed between two), or the
  dumps end before the run did.

A run has ended by its own rule only when its log holds the deck's last line,
``jkr/dt: run finished step S`` (``FINISH_LINE``), which the deck's end part (``label
finish``, also what a Session runs when it closes) prints after writing the last frames
and final.restart.

A run that failed or was cut off is not a collision outcome: ``problem`` says why,
and the analysis refuses it unless asked to analyse what is there.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from jkrdt.scene import LOG

SETTLE_LINE = "jkr/dt/settle: stop_reason"
FINISH_LINE = "jkr/dt: run finished step"


@dataclasses.dataclass
class RunStatus:
    stop_reason: str            # settled, cap, steps, error, cut off
    stop_step: int | None       # the step the run ended at (None if unknown)
    problem: str | None         # why the run is not a complete outcome, or None
    error: str | None = None    # the LAMMPS error line, if any


def _settle_fields(line: str) -> dict:
    words = line.split()[1:]                 # after "jkr/dt/settle:"
    return dict(zip(words[::2], words[1::2]))


def run_status(run, last_dump_step: int | None = None) -> RunStatus:
    """The status of run directory ``run`` from its ``log.lammps``; with
    ``last_dump_step``, also whether the dumps reach the end of the run."""
    log = Path(run) / LOG
    if not log.exists():
        return RunStatus("cut off", None, f"{log} does not exist: no way to tell how the run "
                         "ended")
    lines = log.read_text(errors="replace").splitlines()
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
    if header and (not loops or loops[-1] < header[-1]):
        return RunStatus("cut off", last_step, f"{log} ends inside a run at step {last_step}: "
                         "the run was cut off")
    if not any(line.startswith(FINISH_LINE) for line in lines):
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
