"""Files written whole or not at all: to a temporary name, then renamed, so that a reader
never sees half a file and an interrupted write never replaces a finished one. Every
record jkr/dt writes (``jkrdt.rundir``'s files, data files, tables, campaign records)
goes through here."""

from __future__ import annotations

import json
from pathlib import Path


def write_atomic(path, text: str) -> Path:
    """``text`` into ``path`` through a temporary name and a rename."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)
    return path


def write_json(path, data) -> Path:
    return write_atomic(path, json.dumps(data, indent=2, default=float) + "\n")
