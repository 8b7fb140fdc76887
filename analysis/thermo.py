"""Thermo output of a LAMMPS log as numpy arrays (the energy budget they add up to is
``jkrdt.ledger.energy_budget``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

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
