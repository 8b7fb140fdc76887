"""Every misuse of the input stops with a LAMMPS error that names the problem and the fix."""

import pytest

from jkrdt.session import start_lammps

BASE = """
units si
atom_style {style}
atom_modify map array
boundary {boundary}
newton off
{comm}
region box block -1e-6 1e-6 -1e-6 1e-6 -1e-6 1e-6
create_box 1 box
create_atoms 1 single 0 0 0
create_atoms 1 single 1.99e-7 0 0
{diameter}
pair_style jkr/dt
{coeff}
neighbor 1e-9 bin
"""
GOOD_COEFF = "pair_coeff * * gamma 0.1 E 7e9 nu 0.25 frictionless"


def run_deck(style="sphere", comm="comm_modify vel yes", coeff=GOOD_COEFF,
             diameter="set type 1 diameter 2e-7", boundary="f f f", tail="run 0", check=None):
    """Run the two-grain deck with ``tail``; ``check(lmp)`` inspects the result."""
    lmp = start_lammps()
    try:
        lmp.commands_string(BASE.format(style=style, comm=comm, coeff=coeff,
                                        diameter=diameter, boundary=boundary))
        lmp.commands_string(tail)
        if check:
            check(lmp)
    finally:
        lmp.close()


def expect_error(match, **kwargs):
    with pytest.raises(Exception, match=match):
        run_deck(**kwargs)


def test_good_deck_runs():
    run_deck()


def test_atom_style_without_radius():
    expect_error("requires atom_style sphere", style="atomic", diameter="mass 1 1e-17")


def test_ghost_velocities_missing():
    expect_error("comm_modify vel yes", comm="")


def test_type_material_incomplete():
    expect_error("must give its material; missing: E and nu",
                 coeff="pair_coeff * * gamma 0.1 frictionless")
    expect_error(r"missing: gamma \(", coeff="pair_coeff * * E 7e9 nu 0.25 frictionless")


def test_e_without_nu():
    expect_error("E and nu go together", coeff="pair_coeff * * gamma 0.1 E 7e9 frictionless")


def test_unknown_keyword():
    expect_error("unknown keyword 'gama'", coeff="pair_coeff * * gama 0.1 E 7e9 nu 0.25")


@pytest.mark.parametrize("word,value,message", [
    ("gamma", "-1", "gamma must be > 0"), ("E", "0", "E must be > 0"),
    ("nu", "0.7", "nu must lie in"), ("tvis", "-1e-12", "tvis must be >= 0"),
    ("xi_crit", "0", "xi_crit must be > 0"), ("kr_scale", "0", "kr_scale must be > 0"),
    ("ks_scale", "-2", "ks_scale must be > 0"), ("kt_scale", "0", "kt_scale must be > 0")])
def test_out_of_range_values(word, value, message):
    words = {"gamma": "0.1", "E": "7e9", "nu": "0.25"}
    words[word] = value
    coeff = "pair_coeff * * " + " ".join(f"{k} {v}" for k, v in words.items())
    expect_error(message, coeff=coeff + " rolling off")


def test_keyword_without_value():
    expect_error("needs a value", coeff="pair_coeff * * gamma 0.1 E 7e9 nu 0.25 tvis")


def test_rolling_needs_xi_crit():
    expect_error("xi_crit is not set", coeff="pair_coeff * * gamma 0.1 E 7e9 nu 0.25")


def test_damping_with_zero_poisson_ratio():
    expect_error("divides by nu", coeff="pair_coeff * * gamma 0.1 E 7e9 nu 0 tvis 6e-12 frictionless")


def test_zero_radius():
    expect_error("finite radius > 0", diameter="set atom 1 diameter 0")


def test_periodic_box_too_small():
    expect_error("two images of one contact partner", boundary="p p p",
                 diameter="set type 1 diameter 1.5e-6")


def test_pair_style_arguments():
    lmp = start_lammps()
    try:
        with pytest.raises(Exception, match="unknown setting '1.0'; the settings are 'dt_check"):
            lmp.command("pair_style jkr/dt 1.0")
        with pytest.raises(Exception, match="dt_check takes error, warn or off"):
            lmp.command("pair_style jkr/dt dt_check maybe")
    finally:
        lmp.close()


def test_contact_escaping_the_neighbor_list():
    # a bonded pair pulled out of neighbor range in one jump, between two runs
    expect_error("left the neighbor list before it could break.*moved by something other "
                 "than the integration", tail="run 0\nset atom 2 x 9e-7\nrun 0")


def test_minimize_is_refused():
    expect_error("cannot be minimized", tail="minimize 0 0 10 10")


def test_switching_friction_on_mid_run_starts_the_pointers_at_the_contact():
    # contacts formed while the frictionless model stored no pointers get
    # n1 = -n_c, n2 = n_c when friction comes on: zero displacement, no jump
    def zero_displacements(lmp):
        rows = lmp.numpy.extract_compute("bonds", 2, 2)
        assert rows.shape == (1, 8)
        assert rows[0, 5] == rows[0, 6] == rows[0, 7] == 0.0

    run_deck(tail="""
        fix integrate all nve/sphere
        compute bonds all jkr/dt/contacts
        timestep 1e-12
        run 10
        pair_coeff * * gamma 0.1 E 7e9 nu 0.25 xi_crit 8e-10
        run 0
    """, check=zero_displacements)


@pytest.mark.parametrize("coeff, match", [
    ("pair_coeff * * gamma E 7e9 nu 0.25 frictionless",
     r"keyword 'gamma' needs a value \(next is the keyword 'E'\)"),
    ("pair_coeff * * gamma 0.1 E 7e9 nu 0.25 xi_crit 8e-10 sliding maybe",
     "sliding takes on or off \\(got 'maybe'\\)"),
])
def test_coefficient_errors_name_the_keyword(coeff, match):
    expect_error(match, coeff=coeff)


def test_respa_is_refused_with_the_supported_style_named():
    expect_error("does not support run_style respa.*'run_style verlet' with 'fix nve/sphere'",
                 tail="run_style respa 2 2\nfix nve all nve/sphere\nrun 1")


def test_integration_without_rotation_warns(tmp_path):
    log = tmp_path / "log.lammps"
    lmp = start_lammps(log=log)
    try:
        lmp.commands_string(BASE.format(style="sphere", comm="comm_modify vel yes",
                                        coeff=GOOD_COEFF, diameter="set type 1 diameter 2e-7",
                                        boundary="f f f"))
        lmp.commands_string("fix move all nve\ntimestep 1e-12\nrun 10")
    finally:
        lmp.close()
    assert "WARNING: pair jkr/dt: no time-integration fix turns the grains" in log.read_text()
