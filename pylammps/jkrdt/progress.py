"""What a run shows while it runs: one line per settle check, read from the run's own
table (``checks.csv``, written by fix jkr/dt/settle at each check) and log, so that a
run of LAMMPS in another process (``jkrdt run``, ``jkrdt demo``) can be watched.

A line holds the check's time in t_c, N_lar, the fragments, the bonded contacts, the
largest energy error so far (|dE| / E_imp), the wall time of the check and, with the cap
as the end, an estimate of the wall time left (the settle rule may end the run sooner).
On a terminal the lines scroll above a tqdm bar over the cap's steps; in a log file or
under Slurm they are plain lines, flushed as they come."""

from __future__ import annotations

import sys
import time
from pathlib import Path

from . import ledger, rundir


def complete_rows(path: Path) -> list[dict]:
    """The rows of a table being written: whole lines only (the last may be half written)."""
    from jkrdt.analysis.tables import read_csv

    return read_csv(path) if Path(path).exists() else []


class CheckLines:
    """Follows ``out``'s checks.csv; ``poll()`` prints a line for each new check.

    ``t_c`` (s) and ``E_imp`` (J) scale the line; ``cap_step`` (the run's last step at
    the latest) gives the estimate; ``start_step`` skips the checks of a run continued
    from a restart file that were shown before."""

    def __init__(self, out: Path, t_c: float, E_imp: float, cap_step: int | None = None,
                 start_step: int = 0, stream=None, bar: bool | None = None):
        self.out, self.t_c, self.E_imp = Path(out), t_c, E_imp
        self.cap_step, self.start_step = cap_step, start_step
        self.stream = stream or sys.stdout
        self.seen = start_step if start_step > 0 else -1    # a new run shows its step 0
        self.last_wall = time.time()
        self.started = self.last_wall
        use_bar = self.stream.isatty() if bar is None else bar
        self.bar = None
        if use_bar and cap_step:
            from tqdm import tqdm
            self.bar = tqdm(total=cap_step, initial=start_step, unit="step",
                            file=self.stream, dynamic_ncols=True, leave=False)

    def energy_error(self) -> float | None:
        log = self.out / rundir.LOG
        try:
            budget = ledger.energy_budget(rundir.read_thermo(log))
            return ledger.energy_error(budget, self.E_imp)
        except (OSError, KeyError, ValueError, IndexError):
            return None

    def line(self, row: dict, wall: float) -> str:
        step = int(row["step"])
        words = [f"step {step}", f"t {row['time'] / self.t_c:.0f} t_c",
                 f"N_lar {int(row['n_largest'])}", f"fragments {int(row['n_fragments'])}",
                 f"contacts {int(row['contacts'])}"]
        error = self.energy_error()
        if error is not None:
            words.append(f"|dE|/E_imp {error:.1e}")
        words.append(f"{wall:.1f} s/check")
        if self.cap_step and step > self.start_step:
            rate = (time.time() - self.started) / (step - self.start_step)
            left = (self.cap_step - step) * rate
            words.append(f"cap in {format_seconds(left)} at most")
        return "  ".join(words)

    def poll(self) -> None:
        """Print the checks that have appeared since the last poll."""
        rows = [r for r in complete_rows(self.out / rundir.CHECKS) if r["step"] > self.seen]
        now = time.time()
        for k, row in enumerate(rows):
            wall = (now - self.last_wall) / len(rows)
            text = self.line(row, wall)
            if self.bar is not None:
                self.bar.write(text)
                self.bar.update(int(row["step"]) - self.seen)
            else:
                print(text, file=self.stream, flush=True)
            self.seen = int(row["step"])
        if rows:
            self.last_wall = now

    def close(self) -> None:
        self.poll()
        if self.bar is not None:
            self.bar.close()


def format_seconds(seconds: float) -> str:
    seconds = max(0.0, seconds)
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
