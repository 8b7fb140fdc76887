"""When a collision run ends, and how accurate it was.

The settle rule is ``fix jkr/dt/settle`` of the plugin (its line is in
``inputs/collision.lmp``): every ``check`` steps it finds the fragments (the
connected components of the bonded contacts); the collision has settled when,
over the last ``window`` checks,

* the largest fragment N_lar and the number of fragments have each varied by at
  most ``counts`` of all grains, rounded down (unchanged below 1/counts grains;
  at 10^5 grains thousands of fragments still fly when the outcome is fixed),
* the number of bonded contacts has varied by at most ``tolerance`` of its value,
* the energy dissipated over the window is at most ``tolerance`` of all the
  energy dissipated so far (restructuring has stopped),
* and the largest fragment, where it holds at least ``stretch`` of all grains, has not
  grown in r_g by more than ``tolerance`` over the window: a body held by a neck without
  rolling or sliding resistance stretches at constant N_lar and contacts, dissipating
  nothing, and may part long after (at 2 x 50000 the frictionless 1/12 collision at
  39.8 m/s settled at f_gro +0.81 without this and parted twice, to -0.27, by 2.7 us).
  Replayed on the twelve runs continued to a fixed end of 16000 t_c, the rule with shape
  watched ends each with the fixed end's f_gro within 0.001, the 2 x 50000 ones at
  2.75 us instead of 4.4 (``validation/end_rule.py``). ``stretch`` 0 does not watch shape:
  the rule of the runs made before it (and of the plugin's fix without the keyword).

A run that has not settled by ``cap_tc`` (simulated time, in t_c) stops there with
reason "cap".

At each check, fragments that have left the collision for good depart (``depart``
"yes"; the rule is in the plugin's ``fix_jkr_dt_settle_depart.cpp`` and the manual's
"Fragments that fly apart"): they keep their velocities, spins and contacts but stop
and meet nothing more, so the box, the neighbor bins and the cost per step stop growing
with them. "no" lets every fragment fly; "shadow" lets them fly and logs, once per
fragment, when the rule would have let it depart (to measure the rule).

The defaults below check every 50 t_c over 5 checks (250 t_c, about
70 ns for 0.1 micron ice), which is longer than a grain's contact time and shorter
than a collision of a few hundred grains.

The energy watch: max |dE| / E_imp over a run, with dE the change of the conserved
ke + erot + pe + dissipated; above ``ENERGY_WARN`` a run is flagged.
"""

from __future__ import annotations

import dataclasses
import math

#: max |dE| / E_imp above which a run's energy budget is reported as inaccurate
ENERGY_WARN = 1.0e-3

#: stop reasons written in outcome.json: settled and fixed-length ("steps") runs are
#: complete; a run that hit its cap or an error did not end its collision
COMPLETE = ("settled", "steps")
#: how the summaries and jkrdt run say each stop reason
STOP_WORDS = {"settled": "settled", "cap": "hit the cap before settling",
              "steps": "ran its fixed number of steps (no settle rule)",
              "error": "FAILED", "cut off": "was CUT OFF", "in progress": "is in progress"}


#: what fix jkr/dt/settle's depart keyword takes
DEPART = ("yes", "no", "shadow")
#: the share of all grains from which the rule watches the largest fragment's shape, the
#: analysis's warning's own (``analysis.outcome.STRETCH_SHARE``: f_gro >= -0.5)
STRETCH = 0.25
#: the rule's fields that came after runs were made with it, with the value that gives
#: the rule of those runs: a campaign recorded without one resumes with that value
#: (``jkrdt.campaign.own``)
BEFORE = dict(stretch=0.0)


@dataclasses.dataclass(frozen=True)
class SettleRule:
    """The settle rule's parameters (see the module docstring)."""

    check_tc: float = 50.0        # simulated time between checks, t_c
    window: int = 5               # checks that must agree
    tolerance: float = 0.01       # relative change of contacts and dissipation allowed
    counts: float = 1e-4          # change of N_lar and of the fragment count, of all grains
    cap_tc: float = 40000.0       # simulated time at which an unsettled run stops, t_c
    depart: str = "yes"           # fragments that have left for good stop: yes, no, shadow
    stretch: float = STRETCH      # share of all grains above which shape is watched; 0: not

    def __post_init__(self):
        if not self.check_tc > 0:
            raise ValueError(f"settle check interval must be > 0 t_c (got {self.check_tc})")
        if not (isinstance(self.window, int) and self.window >= 1):
            raise ValueError(f"settle window must be a whole number of checks >= 1 "
                             f"(got {self.window})")
        if not 0 <= self.tolerance < 1:
            raise ValueError(f"settle tolerance is a fraction in [0, 1) (got {self.tolerance})")
        if not 0 <= self.counts < 1:
            raise ValueError(f"settle counts is a fraction of all grains in [0, 1) "
                             f"(got {self.counts}; 0: N_lar and fragments unchanged)")
        if not 0 <= self.stretch <= 1:
            raise ValueError(f"settle stretch is a fraction of all grains in [0, 1] (got "
                             f"{self.stretch}; 0 does not watch shape, {STRETCH} watches a "
                             "largest fragment of a quarter of the grains or more)")
        if self.depart not in DEPART:
            raise ValueError(f"settle depart must be one of {DEPART} (got {self.depart!r})")
        if not self.cap_tc > self.check_tc:
            raise ValueError(f"settle cap ({self.cap_tc} t_c) must exceed the check interval "
                             f"({self.check_tc} t_c)")

    def check_steps(self, dt_over_tc: float) -> int:
        """Steps between checks (and dumps) at a time step of ``dt_over_tc`` t_c."""
        return max(1, round(self.check_tc / dt_over_tc))

    def cap_steps(self, dt_over_tc: float) -> int:
        """The cap in steps, a whole number of checks."""
        every = self.check_steps(dt_over_tc)
        return every * max(1, math.ceil(self.cap_tc / dt_over_tc / every))

    def deck_variables(self, dt_over_tc: float) -> dict:
        """Variables of ``inputs/collision.lmp`` that switch the rule on."""
        return dict(settle="yes", every=self.check_steps(dt_over_tc), window=self.window,
                    settle_tol=self.tolerance, settle_counts=self.counts,
                    steps=self.cap_steps(dt_over_tc),
                    depart=self.depart, settle_stretch=self.stretch)


#: the rule of ``jkrdt run``, ``jkrdt demo``, campaigns and ``Session.run_until_settled``
DEFAULT_RULE = SettleRule()
