"""Reading the plugin's local contact dumps (dump local of compute jkr/dt/contacts)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def last_local_snapshot(path) -> np.ndarray:
    """Rows (id1 id2 delta a force) of the last snapshot of a ``dump local`` file."""
    text = Path(path).read_text().split("ITEM: TIMESTEP")[-1]
    body = text.split("ITEM: ENTRIES")[-1].splitlines()[1:]
    rows = [[float(w) for w in line.split()] for line in body if line.strip()]
    return np.array(rows, dtype=float).reshape(len(rows), -1)
