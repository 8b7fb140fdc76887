"""N_con and N_cut, the contacts made and cut during a collision (3D BPCA paper, App. C.2):
values 11 and 12 of compute pair jkr/dt, booked half to each atom of the contact in the
contact fix's ledger, so that they are counted exactly on any number of ranks and carried
through restart files (tests/test_records.py continues a cut-off run to the same counts)."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import ICE_SCALES as S, R_GRAIN, ledger, two_grain_scene
from jkrdt import rundir
from jkrdt.ledger import CONTACTS, CUT, MADE

BIN = Path(sys.executable).parent
JKRDT = str(BIN / "jkrdt")


@pytest.mark.parametrize("v_rel, made, cut", [(4.0, 1, 0), (6.5, 1, 1)])
def test_two_grains_make_one_contact_and_cut_it_only_above_the_sticking_speed(lmp, v_rel, made,
                                                                              cut):
    """Two 0.1 micron ice grains head-on stick below v_stick = 5.95 m/s (eq. 6's energy
    balance, validation/two_grain_sticking) and bounce above it: one contact made, and cut
    only when they bounce. The contacts present are value 10 = N_con - N_cut."""
    two_grain_scene(lmp, 2 * R_GRAIN + 0.5 * S.delta_c, v_rel=v_rel)
    lmp.command("run 30000")
    e = ledger(lmp)
    assert (e["made"], e["cut"]) == (made, cut)
    assert e["contacts"] == made - cut


def test_a_contact_made_at_the_first_step_is_given_not_made(lmp):
    """Contacts present when a run starts (its set-up) are taken as given, as the energy
    ledger takes them: the aggregates' own contacts are not collision events."""
    two_grain_scene(lmp, 2 * R_GRAIN)
    lmp.command("run 1000")
    e = ledger(lmp)
    assert (e["contacts"], e["made"], e["cut"]) == (1, 0, 0)


@pytest.mark.parametrize("ranks", [1, 2])
def test_contacts_made_less_cut_are_the_change_in_bonded_contacts_at_every_check(tmp_path, ranks):
    """A shattering collision (2 x 200 frictionless ice at 39.8 m/s, as the paper's Fig. 1)
    makes and cuts contacts many times over (the paper: both above N_tot for this model);
    whatever the rank count, the bonded contacts at each check less those at the start are
    N_con - N_cut exactly, and the ledger's per-atom halves add up to whole events."""
    d = tmp_path / "run"
    subprocess.run([JKRDT, "setup", "--n-tar", "200", "--n-pro", "200", "--v", "39.8",
                    "--model", "frictionless", "--dt", "0.03", "--out", str(d)], check=True,
                   capture_output=True, timeout=300)
    subprocess.run([JKRDT, "run", str(d), "--np", str(ranks)], check=True, capture_output=True,
                   timeout=600)
    thermo = rundir.read_thermo(d / rundir.LOG)
    made, cut, bonded = thermo[MADE], thermo[CUT], thermo[CONTACTS]
    assert np.array_equal(bonded - bonded[0], made - cut)
    assert np.array_equal(made, np.round(made)) and np.array_equal(cut, np.round(cut))
    assert np.all(np.diff(made) >= 0) and np.all(np.diff(cut) >= 0)
    assert made[-1] > 400 and cut[-1] > 400
    subprocess.run([JKRDT, "analyse", str(d), "--no-plots"], check=True, capture_output=True,
                   timeout=300)
    out = json.loads((d / rundir.OUTCOME).read_text())
    assert (out["N_con"], out["N_cut"]) == (made[-1], cut[-1])
    assert out["diagnostics"]["E_dis_c"] == out["dissipated_by_channel"]["events"]
    assert out["diagnostics"]["N_cum_1000"] == out["n_total"]
