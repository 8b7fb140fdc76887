"""Thermo output of a LAMMPS log as numpy arrays, and the energy budget of a run."""

from __future__ import annotations

from pathlib import Path

import numpy as np

LEDGER = ["c_p[5]", "c_p[6]", "c_p[7]", "c_p[8]", "c_p[9]"]   # dissipated, by channel
CHANNELS = ["events", "damping", "sliding", "rolling", "twisting"]  # the order of LEDGER
#: the conserved total as a LAMMPS equal-style formula over the deck's computes p, erot
CONSERVED = "ke+c_erot+pe+" + "+".join(LEDGER)


def read_thermo(log) -> dict[str, np.ndarray]:
    """Columns of every thermo block in ``log``, concatenated (repeated steps dropped)."""
    columns, columns_done, rows = None, None, []
    for line in Path(log).read_text().splitlines():
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


def energy_error(budget: dict[str, np.ndarray], e_imp: float) -> float:
    """max |dE| / E_imp over a run, dE the change of the conserved total."""
    total = budget["total"]
    return float(np.abs(total - total[0]).max() / e_imp)


def energy_budget(thermo: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Kinetic (with rotation), potential, dissipated (in all and by channel:
    'events' = contact formation and breaking, 'damping', 'sliding', 'rolling',
    'twisting') and total energy over the run."""
    kinetic = thermo["KinEng"] + thermo["c_erot"]
    dissipated = sum(thermo[c] for c in LEDGER)
    budget = dict(kinetic=kinetic, potential=thermo["PotEng"], dissipated=dissipated,
                  total=kinetic + thermo["PotEng"] + dissipated)
    budget.update({name: thermo[c] for name, c in zip(CHANNELS, LEDGER)})
    return budget
