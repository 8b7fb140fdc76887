"""Where a kept run's outcome is read: the end that decides its f_gro (issue 46).

At 2 x 50000 the settle rule as it was (shape not watched, ``stretch 0``) ended runs while
a neck still held their largest body, which parted later (``fixed_end``). A run's record
therefore gives its f_gro where it ended, and that is its outcome only if its body was
not stretching there. Each kept record is read, in this order, at:

  fixed end   its continuation (``fixed_end``'s record) reached the fixed end
  shape end   its continuation settled with shape watched (``fixed_end --shape``)
  cap         it ended at its stage's cap, and is counted there (``paper_protocol``)
  settle end  it settled with its largest body not stretching over the rule's last window
              (``analysis.outcome.stretching``): the rule with shape watched ends it at the
              same check, so it reads the same f_gro whether or not it watched shape
  open        it settled while its largest body was stretching and was not continued:
              its outcome is not known, and it is left out of every reading's average

The f_gro of each is (N_lar - N_tar) / N_pro at that check of the run's settle checks.

A continuation may be of a run made anew that is not the recorded one (``paper_protocol
--again`` on another build: chaos parts the two within thousands of steps). Its record
then holds that run's own small record (ANEW/), and the continuation is read on from that
run's checks, not the recorded run's: another run of the same collision.
"""

from __future__ import annotations

from pathlib import Path

from jkrdt import rundir
from jkrdt.analysis.outcome import from_checks, stretching
from jkrdt.analysis.tables import read_csv
from jkrdt.stopping import SettleRule

#: the settle rule's window and tolerance, over which a largest body's stretching is judged
RULE = SettleRule()

#: how a record can be read, in the order above; OPEN is not a reading
FIXED_END, SHAPE_END, CAP, SETTLE_END, OPEN = ("fixed end", "shape end", "cap",
                                               "settle end", "open")
#: in a continuation's record: the small record of the run made anew that it continued,
#: where that run is not the recorded one
ANEW = "anew"


def checks_through(record: Path, continued: Path | None, n_tar: int, n_pro: int) -> list[dict]:
    """The settle checks of the run of ``record`` (rows of ``from_checks``), with those of
    its continuation's record ``continued`` after its end appended where one is kept; the
    continuation's alone, whole, where it continued a run made anew (``anew``)."""
    rows = from_checks(read_csv(continued_run(record, continued) / rundir.CHECKS), n_tar,
                       n_pro)
    return rows + continued_after(rows, continued, n_tar, n_pro)


def anew(continued: Path | None) -> bool:
    """Whether the continuation's record ``continued`` is of a run made anew that is not
    the recorded one (its own record then lies in ANEW/)."""
    return continued is not None and (continued / ANEW / rundir.OUTCOME).exists() and \
        (continued / rundir.CHECKS).exists()


def continued_run(record: Path, continued: Path | None) -> Path:
    """The record of the run that the continuation ``continued`` goes on from: the run
    made anew in it (``anew``), else ``record``'s own."""
    return continued / ANEW if anew(continued) else record


def continued_after(rows: list[dict], continued: Path | None, n_tar: int,
                    n_pro: int) -> list[dict]:
    """The checks of the continuation's record ``continued`` after the last of ``rows``
    (none where no continuation is kept)."""
    more = continued / rundir.CHECKS if continued is not None else None
    if more is None or not more.exists():
        return []
    return [r for r in from_checks(read_csv(more), n_tar, n_pro) if r["step"] > rows[-1]["step"]]


def fixed_end_us(record: Path, cap_tc: float) -> float:
    """The fixed end ``cap_tc`` (in t_c) of the run of ``record``, in microseconds."""
    return cap_tc * rundir.read(record).scales.t_c * 1e6


def first_at(rows: list[dict], time_us: float) -> int | None:
    """The first of ``rows`` at or after ``time_us``, as a cap ends a run (None: none)."""
    return next((k for k, r in enumerate(rows) if r["time"] * 1e6 >= time_us * (1 - 1e-9)),
                None)


def read(outcome: dict, record: Path, continued: Path | None, cap_tc: float) -> dict:
    """How the run of ``record`` (its ``outcome``) is read: ``read_at`` (one of the five
    above), ``f_gro`` there (None where open) and the time there, ``time_us``. Its
    continuation's record is ``continued`` (None or absent: not continued); ``cap_tc``
    is the fixed end it was continued to."""
    end = dict(f_gro=outcome["growth_efficiency"], time_us=outcome["time_end"] * 1e6)
    if continued is not None and (continued / rundir.CHECKS).exists():
        rows = checks_through(record, continued, outcome["N_tar"], outcome["N_pro"])
        at = first_at(rows, fixed_end_us(record, cap_tc))
        last = rows[-1 if at is None else at]
        return dict(read_at=SHAPE_END if at is None else FIXED_END,
                    f_gro=last["growth_efficiency"], time_us=last["time"] * 1e6,
                    **(dict(anew=True) if anew(continued) else {}))
    if outcome.get("stop_reason") == "cap":
        return dict(end, read_at=CAP)
    rows = checks_through(record, None, outcome["N_tar"], outcome["N_pro"])
    shape = stretching(rows, RULE.window, RULE.tolerance)
    if shape and shape["stretching"]:
        return dict(read_at=OPEN, f_gro=None, time_us=end["time_us"])
    return dict(end, read_at=SETTLE_END)
