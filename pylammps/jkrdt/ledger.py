"""The energy ledger: the layout of ``compute pair jkr/dt``'s vector, the thermo line that
carries it, and the energy budget a run conserves.

The plugin's compute gives these values (``VALUES``; its manual page, "Output"):

    1-4   U_n, U_s, U_r, U_t: the normal, sliding, rolling and twisting potentials
    5-9   energy dissipated by contact formation and breaking ('events'), damping,
          sliding, rolling and twisting: the channels of the ledger
    10    the number of bonded contacts
    11-12 the contacts made and cut since the run's first step (N_con and N_cut of the
          3D BPCA paper, App. C.2); contacts present at the first step count as neither,
          so value 10 = its first value + N_con - N_cut, exactly

ke + erotate/sphere + pe + the channels is conserved. The channels are declared once, in
the kernel (plugin/jkr_dt_contact.h and jkr_dt_tangential.h); this module gives their
names to Python, and a test holds the two lists equal. The deck's computes kedep and erotdep
are the part of ke and erotate that fragments which have departed (``jkrdt.stopping``)
carry away: constant once they are gone, like their contacts' share of pe.

This module is the one place that layout is written down: the deck's thermo line
(``inputs/collision.lmp``, tested to match ``THERMO_STYLE``), ``Session``'s samples and
the analysis of a log read it from here.
"""

from __future__ import annotations

import numpy as np

#: the dissipation channels: the kernel's ledger columns (plugin/jkr_dt_contact.h: its
#: JKRDT_NORMAL_CHANNELS, then its JKRDT_TANGENTIAL_CHANNELS), which tests/test_kernel.py
#: compares with these
CHANNELS = ["events", "damping", "sliding", "rolling", "twisting"]
#: the contact potentials: U_n, then one per tangential channel
POTENTIALS = ["U_n", "U_s", "U_r", "U_t"]
#: compute pair jkr/dt's values in order (the kernel's VALUE_NAME): the potentials, the
#: channels, the bonded contacts, the contacts made and cut
VALUES = [*POTENTIALS, *CHANNELS, "contacts", "made", "cut"]
#: 0-based index of the first channel, of the contact count and of N_con, N_cut in the
#: compute's vector
FIRST_CHANNEL, CONTACT_COUNT = VALUES.index(CHANNELS[0]), VALUES.index("contacts")
EVENT_COUNTS = (VALUES.index("made"), VALUES.index("cut"))
#: the compute's values as thermo names (the deck's compute is called p)
LEDGER = [f"c_p[{FIRST_CHANNEL + 1 + k}]" for k in range(len(CHANNELS))]
CONTACTS = f"c_p[{CONTACT_COUNT + 1}]"
#: N_con, N_cut as thermo names; a log written before they were counted lacks them
MADE, CUT = (f"c_p[{k + 1}]" for k in EVENT_COUNTS)
#: the kinetic and rotational energy of the departed fragments (included in ke, c_erot)
DEPARTED = ["c_kedep", "c_erotdep"]
#: the deck's thermo keywords (all the compute's values, c_p[*]) and the names LAMMPS gives
#: their columns in a log. Logs of decks before 2026-12-07 hold c_p[5]-c_p[12] alone, in
#: another order: they are read by these names, never by position
THERMO_KEYWORDS = ["step", "time", "ke", "c_erot", "pe", "c_p[*]", *DEPARTED]
THERMO = ["Step", "Time", "KinEng", "c_erot", "PotEng",
          *(f"c_p[{k + 1}]" for k in range(len(VALUES))), *DEPARTED]
THERMO_STYLE = "thermo_style    custom " + " ".join(THERMO_KEYWORDS)
#: the conserved total as a LAMMPS equal-style formula over the deck's computes p, erot
CONSERVED = "ke+c_erot+pe+" + "+".join(LEDGER)


def sample(lmp) -> list[float]:
    """The thermo columns (``THERMO``) at the current step of a LAMMPS instance running
    the deck (a collective call under MPI)."""
    p = lmp.numpy.extract_compute("p", 0, 1)
    return [lmp.get_thermo("step"), lmp.get_thermo("time"), lmp.get_thermo("ke"),
            float(lmp.extract_compute("erot", 0, 0)), lmp.get_thermo("pe"),
            *(float(p[k]) for k in range(len(VALUES))),
            *(float(lmp.extract_compute(name[2:], 0, 0)) for name in DEPARTED)]


def energy_budget(thermo: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Kinetic (with rotation), potential, dissipated (in all and by channel) and total
    energy over a run, from thermo columns named as in ``THERMO``, and ``departed``: the
    part of the kinetic energy that departed fragments carry (0 for a log without it)."""
    kinetic = thermo["KinEng"] + thermo["c_erot"]
    dissipated = sum(thermo[c] for c in LEDGER)
    departed = sum(thermo.get(c, np.zeros_like(kinetic)) for c in DEPARTED)
    budget = dict(kinetic=kinetic, potential=thermo["PotEng"], dissipated=dissipated,
                  total=kinetic + thermo["PotEng"] + dissipated, departed=departed)
    budget.update({name: thermo[c] for name, c in zip(CHANNELS, LEDGER)})
    return budget


def energy_error(budget: dict[str, np.ndarray], e_imp: float) -> float:
    """max |dE| / E_imp over a run, dE the change of the conserved total."""
    total = budget["total"]
    return float(np.abs(total - total[0]).max() / e_imp)


def contact_events(thermo: dict[str, np.ndarray], at: int = -1) -> dict[str, float] | None:
    """N_con and N_cut at row ``at`` of thermo columns named as in ``THERMO`` (whole
    numbers: the plugin books half an event to each atom), with the bonded contacts at the
    first row and at that one, whose difference they equal; None for a log written before
    the plugin counted them."""
    if MADE not in thermo or CUT not in thermo:
        return None
    return dict(N_con=float(thermo[MADE][at]), N_cut=float(thermo[CUT][at]),
                contacts_start=float(thermo[CONTACTS][0]),
                contacts_end=float(thermo[CONTACTS][at]))
