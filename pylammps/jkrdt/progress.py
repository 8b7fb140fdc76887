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
                 start_step: int = 0, stream=None, bar: bool | None = None,
                 prefix: str = "", every_s: float = 0.0):
        self.out, self.t_c, self.E_imp = Path(out), t_c, E_imp
        self.cap_step, self.start_step = cap_step, start_step
        # a campaign's runs side by side: each line named, and at most one per every_s
        # (the first after every_s: a run of seconds shows none)
        self.prefix, self.every_s = prefix, every_s
        self.last_shown = time.monotonic() if every_s > 0 else None
        self.stream = stream or sys.stdout
        self.seen = start_step if start_step > 0 else -1    # a new run shows its step 0
        self.first_step, self.first_wall = None, 0.0
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

    def line(self, row: dict, wall: float | None, error: float | None) -> str:
        step = int(row["step"])
        words = [f"step {step}", f"t {row['time'] / self.t_c:.0f} t_c",
                 f"N_lar {int(row['n_largest'])}", f"fragments {int(row['n_fragments'])}",
                 f"contacts {int(row['contacts'])}"]
        if error is not None:
            words.append(f"|dE|/E_imp {error:.1e}")
        if wall is not None:
            words.append(f"{wall:.1f} s/check")
        if self.cap_step and step > self.first_step and "wall" in row:
            rate = (row["wall"] - self.first_wall) / (step - self.first_step)
            left = (self.cap_step - step) * rate
            words.append(f"cap in {format_seconds(left)} at most")
        return "  ".join(words)

    def poll(self) -> None:
        """Print the checks that have appeared since the last poll. The wall times are the
        table's own (its ``wall`` column, the run's seconds at each check)."""
        table = complete_rows(self.out / rundir.CHECKS)
        new = [k for k, r in enumerate(table) if r["step"] > self.seen]
        error, read = None, False      # the log: read once per poll, and only for a line shown
        for k in new:
            row = table[k]
            if self.first_step is None:
                self.first_step, self.first_wall = int(row["step"]), row.get("wall", 0.0)
            wall = row["wall"] - table[k - 1]["wall"] if k and "wall" in row else None
            if wall is not None and wall < 0:      # a table of an older build: its clock
                wall = None                        # started again at a resume
                self.first_step, self.first_wall = int(row["step"]), row["wall"]
            due = self.last_shown is None or time.monotonic() - self.last_shown >= self.every_s
            if self.bar is not None or due:
                if not read:
                    error, read = self.energy_error(), True
                text = self.prefix + self.line(row, wall, error)
            if self.bar is not None:
                self.bar.write(text)
                self.bar.update(int(row["step"]) - self.seen)
            elif due:
                print(text, file=self.stream, flush=True)
                self.last_shown = time.monotonic()
            self.seen = int(row["step"])

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
