"""The contact state across LAMMPS commands between runs: what is carried through, and
what is refused with the way that works named."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import ENERGY_THERMO, ICE_SCALES as S, R_GRAIN, ledger, two_grain_scene
from jkrdt import rundir
from jkrdt import scene as scene_module
from jkrdt.materials import ICE
from jkrdt.session import start_lammps

BIN = Path(sys.executable).parent
READ_BACK = """units si
atom_style sphere
comm_modify vel yes
pair_style jkr/dt
read_data {data}
neighbor 1e-8 bin
fix integrate all nve/sphere
timestep 3.8e-12
"""


def write_data_after_a_run(tmp_path):
    log, data = tmp_path / "write.log", tmp_path / "stuck.data"
    lmp = start_lammps(log=log)
    try:
        two_grain_scene(lmp, 2 * R_GRAIN - S.delta0)     # one bonded contact at equilibrium
        lmp.command("run 10")
        lmp.command(f"write_data {data}")
    finally:
        lmp.close()
    return log, data


# decks give their own coefficients after read_data: the file's mark must outlive them
@pytest.mark.parametrize("then", ["", "pair_coeff * * gamma 0.1 E 7e9 nu 0.25 frictionless"],
                         ids=["coefficients from the file", "the deck's own pair_coeff"])
def test_a_run_from_write_data_with_contacts_is_refused(tmp_path, then):
    log, data = write_data_after_a_run(tmp_path)
    assert "WARNING: pair jkr/dt: write_data does not carry the 1 bonded contacts" in \
        log.read_text()
    lmp = start_lammps()
    try:
        lmp.commands_string(READ_BACK.format(data=data) + then)
        with pytest.raises(Exception, match="written by write_data from a state with 1 bonded "
                                            "contacts.*write_restart / read_restart.*"
                                            "'pair_style jkr/dt' again after read_data"):
            lmp.command("run 10")
    finally:
        lmp.close()


def test_pair_style_given_again_starts_from_the_positions(tmp_path):
    _, data = write_data_after_a_run(tmp_path)
    lmp = start_lammps()
    try:
        lmp.commands_string(READ_BACK.format(data=data))
        lmp.command("pair_style jkr/dt")                # the fresh start the error names
        lmp.command("pair_coeff * * gamma 0.1 E 7e9 nu 0.25 frictionless")
        lmp.command("compute p all pair jkr/dt")
        lmp.command("run 10")
        assert lmp.numpy.extract_compute("p", 0, 1)[9] == 1    # the contact formed anew
    finally:
        lmp.close()


def test_restart_files_written_before_owner_ids_continue():
    # tests/data: a spinning, sliding stuck pair written by the plugin before the contact
    # fix stored each atom's own ID, and where that plugin's own continuation ended. The
    # kernel's arithmetic has changed since (issue 13: another start of the Newton solve
    # for eq. 4, constants folded): the continuation agrees to round-off, not bit for bit
    data = Path(__file__).parent / "data"
    expected = json.loads((data / "before_owner_ids.json").read_text())["after_300_more_steps"]
    lmp = start_lammps()
    try:
        lmp.commands_string(f"""
            read_restart {data / "before_owner_ids.restart"}
            comm_modify vel yes
            pair_style jkr/dt
            pair_coeff * * gamma {ICE.gamma!r} E {ICE.E!r} nu {ICE.nu!r} xi_crit 8e-10
            neighbor {2 * S.delta_c!r} bin
            fix integrate all nve/sphere
            run 150
            run 150
        """)                      # the second run checks each atom's stored ID
        order = np.argsort(lmp.numpy.extract_atom("id")[:2])
        x = lmp.numpy.extract_atom("x")[:2][order]
        omega = lmp.numpy.extract_atom("omega")[:2][order]
        assert np.abs(x - expected["x"]).max() < 1e-9 * S.delta_c
        assert np.abs(omega - expected["omega"]).max() < 1e-9 * np.abs(expected["omega"]).max()
    finally:
        lmp.close()


def test_scene_deck_continues_a_restart_with_the_scenes_model_and_dt(tmp_path):
    # the README's restart route: the scene's own deck, which carries its model and dt
    scene = rundir.write(tmp_path / "scene", scene_module.Scene(
        ICE, 40, 40, v_col=30.0, b_off=0.2, seed=21, model="frictionless", dt_over_tc=0.02,
        dt_reason="dt = 0.02 t_c given for the test"))
    runs = {}
    for name in ("straight", "first", "second"):
        runs[name] = tmp_path / name
        shutil.copytree(scene, runs[name])

    def lmp_in(where, *extra):
        subprocess.run([str(BIN / "lmp"), "-in", "in.collision.lmp", "-screen", "none",
                        "-var", "settle", "no", "-var", "every", "1000", *extra], cwd=where,
                       check=True, timeout=300)
        final = np.loadtxt(where / rundir.FINAL_DUMP, skiprows=9)
        return final[np.argsort(final[:, 0])]

    straight = lmp_in(runs["straight"], "-var", "steps", "4000")
    lmp_in(runs["first"], "-var", "steps", "2000")
    second = lmp_in(runs["second"], "-var", "steps", "2000", "-var", "read", "read_restart",
                    "-var", "file", str(runs["first"] / "final.restart"))
    assert np.array_equal(straight, second)         # bit for bit
    log = (runs["second"] / "log.lammps").read_text()
    assert "timestep 5.472" in log and "= 0.02 t_c" in log and "frictionless" in log


def stuck_pair(lmp):
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0)
    lmp.command("run 10")
    return lmp


def bonded(lmp):
    return lmp.numpy.extract_compute("p", 0, 1)[9]


def test_a_run_under_another_pair_style_is_refused(lmp):
    stuck_pair(lmp)
    lmp.command("pair_style zero 1e-7")
    lmp.command("pair_coeff * *")
    lmp.command("uncompute p")                     # compute pair jkr/dt would stop it first
    with pytest.raises(Exception, match=r"pair style is now zero, but 1 bonded contacts of "
                                        r"jkr/dt are stored.*hybrid/overlay.*unfix"):
        lmp.command("run 10")


def test_pair_style_jkr_dt_given_again_takes_its_contacts_back(lmp):
    stuck_pair(lmp)
    lmp.command("pair_style zero 1e-7")
    lmp.command("pair_style jkr/dt")
    lmp.command("pair_coeff * * gamma 0.1 E 7e9 nu 0.25 frictionless")
    lmp.command("run 10")
    assert bonded(lmp) == 1


def test_unfix_of_the_contact_fix_is_refused(lmp):
    stuck_pair(lmp)
    lmp.command("unfix JKR_DT_CONTACTS")
    with pytest.raises(Exception, match=r"contact fix JKR_DT_CONTACTS was removed \(unfix\) "
                                        r"with the 1 bonded contacts"):
        lmp.command("run 10")
    # the way out the error names: the pair style and its coefficients anew
    lmp.command("pair_style jkr/dt")
    lmp.command("pair_coeff * * gamma 0.1 E 7e9 nu 0.25 frictionless")
    lmp.command("run 10")
    assert bonded(lmp) == 1      # formed again from the positions


@pytest.mark.parametrize("switch", ["frictionless", "xi_crit 8e-10 sliding off",
                                    "xi_crit 8e-10 twisting off rolling off"])
def test_switching_a_channel_off_books_its_springs_energy(lmp, switch):
    # two stuck grains, one spinning about a tilted axis: rolling and twisting springs
    # load up; switching channels off moves their energy from pe to their ledger
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0, coeff_extra="xi_crit 8e-10")
    lmp.command("set atom 1 omega 2e6 1e6 3e6")
    lmp.command("run 300 post no")
    before = ledger(lmp)
    assert before["U_r"] > 0 and before["U_t"] > 0            # U_r, U_t held
    lmp.command(f"pair_coeff * * gamma 0.1 E 7e9 nu 0.25 {switch}")
    lmp.command("run 0 post no")
    after = ledger(lmp)
    assert after["total"] == pytest.approx(before["total"], rel=1e-12, abs=1e-12 * abs(before["pe"]))
    for slot, ledger_slot in (("U_s", "sliding"), ("U_r", "rolling"), ("U_t", "twisting")):
        dropped = before[slot] - after[slot]                    # U_s, U_r, U_t that left pe
        assert after[ledger_slot] - before[ledger_slot] == pytest.approx(dropped, rel=1e-12,
                                                                         abs=1e-30)


def test_a_limit_lowered_between_runs_is_clamped_and_booked_by_the_next_step(lmp):
    # a run's set-up takes the stored state as it is: a rolling displacement left beyond a
    # xi_crit lowered by pair_coeff keeps its spring energy through the set-up, and the
    # first step clamps it and books the release in the rolling channel
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0, coeff_extra="xi_crit 8e-10")
    lmp.command("set atom 1 omega 0 0 3e6")
    lmp.command("run 300 post no")
    before = ledger(lmp)
    xi = np.sqrt(2.0 * before["U_r"] / S.k_r)                  # U_r = k_r xi^2 / 2, eq. (21)
    assert before["rolling"] == 0 and xi > 1e-10                    # held, never clamped
    lmp.command(f"pair_coeff * * gamma 0.1 E 7e9 nu 0.25 xi_crit {xi / 4}")
    lmp.command("run 0 post no")
    setup = ledger(lmp)
    assert setup["U_r"] == before["U_r"] and setup["rolling"] == 0    # the set-up moved nothing
    lmp.command("run 1 pre no post no")
    after = ledger(lmp)
    # one step on, xi sits at the new limit: U_r = k_r (xi / 4)^2 / 2, and the rest of the
    # spring's energy is in the rolling channel (a step's rotation changes xi by 1e-4)
    assert after["U_r"] == pytest.approx(0.5 * S.k_r * (xi / 4) ** 2, rel=1e-3)
    assert after["rolling"] == pytest.approx(before["U_r"] - after["U_r"], rel=1e-2)
    assert after["total"] == pytest.approx(before["total"], rel=1e-9)


def lone_grain_and_stuck_pair(lmp):
    """Atoms 1 and 2 bonded at equilibrium, atom 3 alone far off; one run done."""
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0)              # atoms 1, 2
    lmp.command("create_atoms 1 single -1e-6 1e-6 1e-6")          # atom 3, alone
    lmp.command("set atom 3 diameter 2e-7 density 1000")
    lmp.command("run 10 post no")
    assert bonded(lmp) == 1


def sliding_spinning_pair_and_a_lone_grain(lmp, renumber=None):
    """Atoms 1 and 2 stuck, 2 at lower x than 1, sliding and spinning (pointers and twist
    loaded); atom 3 alone far off at the lowest x. 300 steps, ``renumber``, 300 steps;
    returns ids, positions and spins ordered by x, and the ledger. LAMMPS's own bins
    (bins box): reset_atoms sorts by them, and the IDs asserted below follow that order."""
    two_grain_scene(lmp, -(2 * R_GRAIN - S.delta0), coeff_extra="xi_crit 8e-10",
                    settings="bins box")
    lmp.command("create_atoms 1 single -1e-6 0 0")
    lmp.command("set atom 3 diameter 2e-7 density 1000")
    lmp.command("set atom 1 omega 2e6 1e6 3e6")
    lmp.command("set atom 2 vy 0.05")
    lmp.command("run 300 post no")
    if renumber:
        lmp.commands_string(renumber)
    lmp.command("run 300 post no")
    n = lmp.get_natoms()
    x = lmp.numpy.extract_atom("x")[:n]
    order = np.argsort(x[:, 0])
    return (lmp.numpy.extract_atom("id")[:n][order].tolist(), x[order].copy(),
            lmp.numpy.extract_atom("omega")[:n][order].copy(), ledger(lmp))


@pytest.mark.parametrize("renumber, ids_after", [
    # spatial sort: the lone grain becomes 1, the pair 2 and 3 in flipped order (n1 <-> n2)
    ("reset_atoms id sort yes", [1, 2, 3]),
    # ... and then the lone grain is deleted with compress yes: 2, 3 become 2, 1
    ("reset_atoms id sort yes\ngroup lone id 1\ndelete_atoms group lone compress yes", [2, 1]),
])
def test_renumbered_atoms_keep_their_contacts(renumber, ids_after):
    straight = start_lammps()
    renumbered = start_lammps()
    try:
        ids0, x0, w0, e0 = sliding_spinning_pair_and_a_lone_grain(straight)
        ids1, x1, w1, e1 = sliding_spinning_pair_and_a_lone_grain(renumbered, renumber)
    finally:
        straight.close()
        renumbered.close()
    assert ids0 == [3, 2, 1] and ids1 == ids_after       # ordered by x
    # the pair continues exactly as without the renumbering: same grains, same state
    assert np.array_equal(x1[-2:], x0[-2:]) and np.array_equal(w1[-2:], w0[-2:])
    assert e1["contacts"] == e0["contacts"] == 1


def test_delete_atoms_compress_yes_carries_the_survivors_contacts(lmp):
    # delete atom 2 of the pair: its partner loses the contact; no wrong atom is blamed
    lone_grain_and_stuck_pair(lmp)
    lmp.command("group gone id 2")
    lmp.command("delete_atoms group gone compress yes")     # 3 becomes 2
    lmp.command("run 10 post no")
    assert bonded(lmp) == 0 and lmp.get_natoms() == 2


def test_deleting_a_bonded_atom_removes_its_contacts(tmp_path):
    log = tmp_path / "log.lammps"
    lmp = start_lammps(log=log)
    try:
        lone_grain_and_stuck_pair(lmp)
        lmp.command("group gone id 2")
        lmp.command("delete_atoms group gone compress no")
        lmp.command("run 10 post no")
        assert bonded(lmp) == 0 and lmp.get_natoms() == 2
    finally:
        lmp.close()
    assert "pair jkr/dt: 1 contacts with deleted atoms removed" in log.read_text()


def test_a_channel_switched_off_across_a_pair_style_swap_is_booked(lmp):
    # the constants the springs were made with live in the contact fix, so a pair style
    # that takes the contacts over books them with the last run's values
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0, coeff_extra="xi_crit 8e-10")
    lmp.command("set atom 1 omega 2e6 1e6 3e6")
    lmp.command("run 300 post no")
    before = ledger(lmp)
    lmp.command("pair_style zero 1e-7")
    lmp.command("pair_coeff * *")
    lmp.command("pair_style jkr/dt")
    lmp.command("pair_coeff * * gamma 0.1 E 7e9 nu 0.25 frictionless")
    lmp.command("run 0 post no")
    after = ledger(lmp)
    held = before["U_s"] + before["U_r"] + before["U_t"]
    assert held > 0 and after["U_s"] == after["U_r"] == after["U_t"] == 0
    assert after["total"] == pytest.approx(before["total"], rel=1e-12)
    booked = sum(after[k] - before[k] for k in ("sliding", "rolling", "twisting"))
    assert booked == pytest.approx(held, rel=1e-12)


def read_and_switch(restart: Path, switch: str) -> dict:
    """The ledger after reading ``restart`` and running 0 steps with ``switch``'s channels."""
    again = start_lammps()
    try:
        again.commands_string(f"""
            read_restart {restart}
            comm_modify vel yes
            pair_coeff * * gamma 0.1 E 7e9 nu 0.25 {switch}
            neighbor {2 * S.delta_c!r} bin
            fix integrate all nve/sphere
            compute p all pair jkr/dt
            compute erot all erotate/sphere
            thermo_style custom {ENERGY_THERMO}
            thermo_modify norm no
            run 0 post no
        """)
        return ledger(again)
    finally:
        again.close()


@pytest.mark.parametrize("switch", ["frictionless", "xi_crit 8e-10 sliding off",
                                    "xi_crit 8e-10 twisting off rolling off"])
def test_a_channel_switched_off_across_a_restart_is_booked(tmp_path, switch):
    # the constants the springs were made with go into the restart file with the contacts,
    # so a deck that reads it and switches a channel off books the springs' energy as the
    # same switch between two runs does: the conserved total holds to round-off
    first = start_lammps()
    try:
        two_grain_scene(first, 2 * R_GRAIN - S.delta0, coeff_extra="xi_crit 8e-10")
        first.command("set atom 1 omega 2e6 1e6 3e6")
        first.command("run 300 post no")
        before = ledger(first)
        first.command(f"write_restart {tmp_path}/loaded.restart")
    finally:
        first.close()
    assert before["U_s"] > 0 and before["U_r"] > 0 and before["U_t"] > 0
    after = read_and_switch(tmp_path / "loaded.restart", switch)
    assert after["total"] == pytest.approx(before["total"], rel=1e-12,
                                           abs=1e-12 * abs(before["pe"]))
    for slot, ledger_slot in (("U_s", "sliding"), ("U_r", "rolling"), ("U_t", "twisting")):
        dropped = before[slot] - after[slot]                    # U_s, U_r, U_t that left pe
        assert after[ledger_slot] - before[ledger_slot] == pytest.approx(dropped, rel=1e-12,
                                                                         abs=1e-30)


@pytest.mark.parametrize("switch", ["frictionless", "xi_crit 8e-10 sliding off"])
def test_a_restart_file_with_made_with_as_bytes_still_books_a_channel_switched_off(switch):
    # tests/data/made_with_as_bytes.restart: the scene above, written by the build before
    # made_with named its fields (each Param's bytes); read by this build, a channel
    # switched off still books the energy its springs held, and the total holds
    data = Path(__file__).parent / "data"
    before = json.loads((data / "made_with_as_bytes.json").read_text())["ledger"]
    after = read_and_switch(data / "made_with_as_bytes.restart", switch)
    assert after["total"] == pytest.approx(before["total"], rel=1e-12,
                                           abs=1e-12 * abs(before["pe"]))
    booked = sum(after[k] - before[k] for k in ("sliding", "rolling", "twisting"))
    held = sum(before[k] - after[k] for k in ("U_s", "U_r", "U_t"))
    assert held > 0 and booked == pytest.approx(held, rel=1e-12)


def test_replicate_works_before_the_first_run_and_is_refused_after(lmp):
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0, box=2e-6)
    lmp.command("change_box all boundary p f f")
    lmp.command("replicate 2 1 1")                    # no contacts stored yet
    lmp.command("run 10 post no")
    assert bonded(lmp) == 2 and lmp.get_natoms() == 4
    with pytest.raises(Exception, match="Cannot replicate with fixes that store per-atom"):
        lmp.command("replicate 2 1 1")


def test_change_box_that_stretches_a_contact_is_named(lmp):
    stuck_pair(lmp)
    lmp.command("change_box all boundary f f f")          # changes nothing for the pair
    lmp.command("run 10 post no")
    assert bonded(lmp) == 1
    lmp.command("change_box all x final -3e-6 3e-6 remap")   # pulls the pair 1.5x apart
    with pytest.raises(Exception, match="moved by something other than the integration.*"
                                        "change_box"):
        lmp.command("run 10")


def test_a_contact_found_deeper_than_a_step_travel_is_named(lmp):
    # the late neighbor check, by the one route the refusals leave open: positions
    # changed from Python between chunks that skip their set-up
    two_grain_scene(lmp, 2 * R_GRAIN + 0.5 * S.delta_c, skin=4 * S.delta_c)   # apart, at rest
    lmp.command("run 10 post no")
    lmp.numpy.extract_atom("x")[1, 0] = 2 * R_GRAIN - 0.5 * S.delta0
    with pytest.raises(Exception, match=r"atoms 1 and 2 is first seen at step 11 already "
                                        r"overlapped by .*it was missed when it formed.*"
                                        r"'run N pre no' chunks"):
        lmp.command("run 10 pre no")


def test_a_restart_written_during_a_run_holds_that_steps_contacts(tmp_path):
    # 'restart N' with no dump at that step: the contact state, kept in list order, must
    # reach the file as of the step written, not as of the last reneighboring
    def spinning_pair(lmp):
        two_grain_scene(lmp, 2 * R_GRAIN - S.delta0, coeff_extra="xi_crit 8e-10")
        lmp.command("set atom 1 omega 2e6 1e6 3e6")
        lmp.command("set atom 2 vy 0.05")

    def state(lmp):
        order = np.argsort(lmp.numpy.extract_atom("id")[:2])
        return (lmp.numpy.extract_atom("x")[:2][order].copy(),
                lmp.numpy.extract_atom("omega")[:2][order].copy())

    straight = start_lammps()
    try:
        spinning_pair(straight)
        straight.command(f"restart 60 {tmp_path}/mid.*")
        straight.command("run 100")
        x0, w0 = state(straight)
    finally:
        straight.close()
    again = start_lammps()
    try:
        again.commands_string(f"""
            read_restart {tmp_path}/mid.60
            comm_modify vel yes
            neighbor {2 * S.delta_c!r} bin
            fix integrate all nve/sphere
            run 40
        """)
        x1, w1 = state(again)
    finally:
        again.close()
    assert np.array_equal(x1, x0) and np.array_equal(w1, w0)


# the three pair_coeff lines of tests/data/coeffs_by_position.restart, as the plugin that
# wrote it (one that stored the coefficients by position, 9 doubles and 3 ints) wrote them
# with write_coeff after its run (less the mark of that run's contact, " data_contacts 1")
COEFFS_BY_POSITION = [
    "pair_coeff 1 1 gamma 0.10000000000000001 E 7000000000 nu 0.25 "
    "xi_crit 8.0000000000000003e-10 tvis 2e-12",
    "pair_coeff 1 2 gamma 0.14999999999999999 ks_scale 2 twisting off",
    "pair_coeff 2 2 gamma 0.25 E 54000000000 nu 0.17000000000000001 G 20000000000 "
    "xi_crit 2.0000000000000001e-10 kr_scale 0.5 rolling off",
]


def coeff_lines(lmp, path):
    lmp.command(f"write_coeff {path}")
    return [line.split(" data_contacts")[0] for line in Path(path).read_text().splitlines()
            if line.startswith("pair_coeff")]


def test_restart_files_name_their_coefficients_and_old_ones_read_back(tmp_path):
    # a file of the first builds holds its coefficients by position; this build writes them
    # by name, so that a file written before a keyword was added reads back without it.
    # Both give back every keyword of every line given, unset ones unset
    lmp = start_lammps()
    try:
        lmp.command(f"read_restart {Path(__file__).parent / 'data' / 'coeffs_by_position.restart'}")
        assert coeff_lines(lmp, tmp_path / "old.coeff") == COEFFS_BY_POSITION
        lmp.command(f"write_restart {tmp_path / 'named.restart'}")
    finally:
        lmp.close()
    named = (tmp_path / "named.restart").read_bytes()
    for word in (b"gamma", b"xi_crit", b"kt_scale", b"twisting"):
        assert word in named
    lmp = start_lammps()
    try:
        lmp.command(f"read_restart {tmp_path / 'named.restart'}")
        assert coeff_lines(lmp, tmp_path / "named.coeff") == COEFFS_BY_POSITION
    finally:
        lmp.close()


def test_a_restart_file_keeps_damp_tension_off(tmp_path):
    # a keyword added after the restart records were named: written by name, it reads back
    lmp = start_lammps()
    try:
        two_grain_scene(lmp, 2 * R_GRAIN - S.delta0,
                        coeff_extra="frictionless tvis 6e-12 damp_tension off")
        lmp.command("run 0")
        lmp.command(f"write_restart {tmp_path / 'off.restart'}")
    finally:
        lmp.close()
    assert b"damp_tension" in (tmp_path / "off.restart").read_bytes()
    lmp = start_lammps()
    try:
        lmp.command(f"read_restart {tmp_path / 'off.restart'}")
        assert coeff_lines(lmp, tmp_path / "off.coeff") == [
            "pair_coeff 1 1 gamma 0.10000000000000001 E 7000000000 nu 0.25 "
            "tvis 6.0000000000000003e-12 sliding off rolling off twisting off damp_tension off"]
    finally:
        lmp.close()
