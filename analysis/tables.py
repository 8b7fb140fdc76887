"""Results tables: CSV, one row per frame or per run, written atomically
(``jkrdt.atomic``: a reader never sees half a file)."""

from __future__ import annotations

import csv
import io
from pathlib import Path

from jkrdt.atomic import write_atomic


def write_csv(path, rows: list[dict]) -> Path:
    """Rows of dicts; the columns are the union of their keys, in first-seen order."""
    columns: list[str] = []
    for row in rows:
        columns += [k for k in row if k not in columns]
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return write_atomic(path, buffer.getvalue())


def read_csv(path) -> list[dict]:
    """Rows of a CSV written by ``write_csv`` (or by fix jkr/dt/settle as a run goes),
    numbers as floats where they parse. A last row without its end (a table being
    written, or cut off by a kill) is left out."""
    def value(text):
        try:
            return float(text)
        except ValueError:
            return text
    text = Path(path).read_text(errors="replace")
    if text and not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    return [{k: value(v) for k, v in row.items()} for row in csv.DictReader(io.StringIO(text))
            if None not in row and None not in row.values()]
