"""Head-on collisions of two grains: the sticking threshold, the losses at
contact formation and separation, and conservation of
ke + erotate + pe + dissipated (compute pair jkr/dt slots 5-9)."""

import math

import pytest

from conftest import ICE_SCALES as S, R_GRAIN, ledger, two_grain_scene
from jkrdt.session import start_lammps

FC_DC = S.F_c * S.delta_c
U_TOUCH = -0.8463 * FC_DC            # U_n(0), section 2.1: -0.847 F_c delta_c
U_BREAK = 0.0893 * FC_DC             # U_n(-delta_c): 0.089 F_c delta_c
# two equal grains (reduced mass m/2) separate again only if m v^2 / 4 + U_n(0) > U_n(-delta_c)
V_STICK = math.sqrt(4.0 * (U_BREAK - U_TOUCH) / S.mass)


def collide(v_rel, dt_over_tc, coeff_extra="frictionless", duration_tc=60.0, samples=400):
    """Run a head-on collision from just outside contact; return the energy
    ledgers along the run (first one at t = 0), and the final relative speed."""
    lmp = start_lammps()
    try:
        two_grain_scene(lmp, 2 * R_GRAIN + 0.3 * S.delta_c, v_rel=v_rel,
                        coeff_extra=coeff_extra, dt_over_tc=dt_over_tc)
        lmp.command("run 0")
        history = [ledger(lmp)]
        nsteps = int(duration_tc / dt_over_tc)
        chunk = max(1, nsteps // samples)
        for _ in range(0, nsteps, chunk):
            lmp.command(f"run {chunk} pre no post no")
            history.append(ledger(lmp))
        v = lmp.numpy.extract_atom("v")
        ids = list(lmp.numpy.extract_atom("id"))
        v_final = abs(v[ids.index(2), 0] - v[ids.index(1), 0])
    finally:
        lmp.close()
    return history, v_final


def max_energy_error(history):
    e_imp = history[0]["ke"]
    return max(abs(h["total"] - history[0]["total"]) for h in history) / e_imp


def test_sticking_threshold_velocity():
    assert V_STICK / S.v0 == pytest.approx(1.9345, rel=1e-3)     # sqrt(3.742) v0
    stuck, _ = collide(0.97 * V_STICK, 0.005)
    assert stuck[-1]["contacts"] == 1
    apart, _ = collide(1.03 * V_STICK, 0.005)
    assert apart[-1]["contacts"] == 0


def test_rebound_speed_follows_the_energy_budget():
    # v_f^2 = v^2 - v_stick^2; at 1.3 v_stick an event error of F_c v dt moves v_f by < 0.5 %
    _, v_final = collide(1.3 * V_STICK, 0.005)
    assert v_final == pytest.approx(math.sqrt(1.3 ** 2 - 1) * V_STICK, rel=0.01)


def test_losses_at_formation_and_separation_are_the_jumps_of_un():
    v = 3.0 * S.v0
    dt_over_tc = 0.005
    history, _ = collide(v, dt_over_tc)
    # a step meets each event up to v dt late: tolerance F_c v dt per event
    tolerance = 2 * S.F_c * v * dt_over_tc * S.t_c
    formed = next(h for h in history if h["contacts"] == 1)
    assert formed["events"] == pytest.approx(-U_TOUCH, abs=tolerance)
    assert history[-1]["contacts"] == 0
    assert history[-1]["events"] == pytest.approx(U_BREAK - U_TOUCH, abs=tolerance)
    assert history[-1]["pe"] == 0.0


@pytest.mark.parametrize("v_over_v0", [1.0, 3.0])
def test_energy_conserved_with_second_order_error(v_over_v0):
    coarse = max_energy_error(collide(v_over_v0 * S.v0, 0.014)[0])
    fine = max_energy_error(collide(v_over_v0 * S.v0, 0.005)[0])
    # measured: 2.7e-4 / 3.5e-5 (v0) and 1.7e-4 / 4.1e-5 (3 v0) of E_imp = m v^2 / 4,
    # which for two grains is only 0.25 (v/v0)^2 F_c delta_c
    assert coarse < 5e-4
    assert fine < 1e-4
    assert coarse / fine > 4.0       # velocity Verlet: (0.014 / 0.005)^2 = 7.8


def test_viscoelastic_damping_conserves_energy_and_makes_grains_stick():
    v = 3.0 * S.v0                   # bounces without damping (above V_STICK)
    history, _ = collide(v, 0.005, coeff_extra="frictionless tvis 6e-12")
    assert history[-1]["contacts"] == 1
    assert history[-1]["damping"] > 0.5 * history[0]["ke"]
    assert max_energy_error(history) < 1e-4
