"""Sliding, rolling and twisting of one bonded contact (Wada et al. 2007,
section 2.2): the critical loads of eqs. (35)-(37), E_roll of eq. (44), and
energy conservation in the elastic regime.

Grain 2 is held still (not integrated); grain 1 is launched so that one
channel alone is driven, and its kinetic energy pays for the work:
  rolling   v = 2 r Omega around grain 2 with spin 2 Omega (rolling without slip)
  sliding   tangential v, grain 1 not allowed to turn (fix nve), so n1 and n2 stay put
  twisting  spin about n_c only
Reference values are computed here from the papers' formulas."""

import math

import numpy as np
import pytest

from conftest import ICE_SCALES as S, R_GRAIN, ledger, two_grain_scene
from jkrdt.materials import ICE, QUARTZ, scales
from jkrdt.session import start_lammps

XI_CRIT = ICE.xi_crit
D0 = 2 * R_GRAIN - S.delta0              # equilibrium distance of a bonded pair
G = ICE.E / (2 * (1 + ICE.nu))           # shear modulus
G_RED = G / 2                            # reduced shear modulus of two equal grains, eq. (26)
G_STAR = G / (2 * (2 - ICE.nu))          # eq. (13)
K_S = 8 * S.a0 * G_STAR                  # eq. (12)
ZETA_CRIT = (2 - ICE.nu) / (16 * math.pi) * S.a0          # eq. (36)
F_FRIC = G_RED * S.a0 ** 2 / (2 * math.pi)                # eq. (35)
K_R = 4 * S.F_c / S.R                                     # eq. (22)
E_ROLL = 12 * math.pi ** 2 * ICE.gamma * S.R * XI_CRIT    # eq. (44)
K_T = 16 / 3 * G_RED * S.a0 ** 3                          # eq. (26)
M_FRIC = G_RED * S.a0 ** 3 / (3 * math.pi)                # eq. (37)
PHI_CRIT = 1 / (16 * math.pi)                             # eq. (38)


def held_pair(lmp, integrate="nve/sphere", dt_over_tc=0.014, extra=""):
    """A bonded pair at rest at delta0, all channels on; only grain 1 moves."""
    two_grain_scene(lmp, D0, coeff_extra=f"xi_crit {XI_CRIT!r} {extra}", dt_over_tc=dt_over_tc)
    lmp.commands_string(f"""
        unfix integrate
        group mobile id 1
        fix integrate mobile {integrate}
        compute bonds all jkr/dt/contacts
    """)


def atom_row(lmp, name, atom_id):
    ids = list(lmp.numpy.extract_atom("id"))
    return np.array(lmp.numpy.extract_atom(name)[ids.index(atom_id)])


def normal(lmp):
    d = atom_row(lmp, "x", 1) - atom_row(lmp, "x", 2)
    return d / np.linalg.norm(d)


def test_constants_match_table3_and_the_3d_paper():
    # Table 3: E_roll = 2.98 F_c delta_c for ice at xi_crit = 2 Angstrom
    assert E_ROLL / 4 / (S.F_c * S.delta_c) == pytest.approx(2.98, rel=0.01)
    # k_s zeta_crit pi R = G a0^2 R / 4 and k_t phi_crit pi/2 = G a0^3 / 12, eqs. (A.11), (A.13)
    assert K_S * ZETA_CRIT == pytest.approx(F_FRIC, rel=1e-12)
    assert K_S * ZETA_CRIT * math.pi * S.R == pytest.approx(G * S.a0 ** 2 * S.R / 4, rel=1e-12)
    assert K_T * PHI_CRIT * math.pi / 2 == pytest.approx(G * S.a0 ** 3 / 12, rel=1e-12)
    # Table 3, quartz at xi_crit = 2 Angstrom: E_roll = 28.7 F_c delta_c; the Python scales agree
    q = scales(QUARTZ, R_GRAIN)
    assert q.E_roll / (q.F_c * q.delta_c) == pytest.approx(28.7, rel=0.01)
    for name, value in [("k_s", K_S), ("zeta_crit", ZETA_CRIT), ("F_fric", F_FRIC), ("k_r", K_R),
                        ("k_t", K_T), ("M_fric", M_FRIC)]:
        assert getattr(S, name) == pytest.approx(value, rel=1e-12), name


@pytest.mark.parametrize("kr_scale", [1.0, 0.5])
def test_rolling_a_quarter_turn_dissipates_E_roll(lmp, kr_scale):
    # kr_scale multiplies k_r and keeps xi_crit: the critical torque and E_roll scale with it
    held_pair(lmp, extra=f"kr_scale {kr_scale}")
    k_r, e_roll = kr_scale * K_R, kr_scale * E_ROLL
    omega = 1.2e8                        # enough kinetic energy for ~1.2 E_roll of rolling
    lmp.command(f"set atom 1 vy {-omega * D0!r} omega 0 0 {2 * omega!r}")
    lmp.command("run 0")
    start = ledger(lmp)
    n0 = normal(lmp)
    angle, e, u_r_plateau = 0.0, start, []
    while angle < math.pi / 2:
        lmp.command("run 10 pre no post no")
        e = ledger(lmp)
        angle = math.acos(np.clip(np.dot(n0, normal(lmp)), -1, 1))
        if angle > 0.2:
            u_r_plateau.append(e["U_r"])
    # rolling without slip turns n1 by 2 angle: the xi path is 2 R angle, of which
    # the first xi_crit is elastic (eqs. 40, 44)
    expected = k_r * XI_CRIT * (2 * S.R * angle - XI_CRIT)
    print(f"rolled {math.degrees(angle):.2f} deg: E_dis,r = {e['rolling'] / e_roll:.4f} E_roll")
    assert e["rolling"] == pytest.approx(expected, rel=2e-3)
    assert e["rolling"] == pytest.approx(e_roll, rel=0.02)
    # the rolling spring sits at its limit, U_r = k_r xi_crit^2 / 2; sliding stays elastic
    assert np.allclose(u_r_plateau, 0.5 * k_r * XI_CRIT ** 2, rtol=2e-3)
    assert abs(e["sliding"]) < 1e-6 * e["rolling"] and e["twisting"] == 0.0
    assert abs(e["total"] - start["total"]) < 1e-6 * start["ke"]


def test_sliding_force_saturates_at_eq35(lmp):
    held_pair(lmp, integrate="nve")      # translation only: grain 1 never turns
    lmp.command("set atom 1 vy 20.0")
    lmp.command("run 0")
    start = ledger(lmp)
    loads, u_s, zeta = [], [], []
    for _ in range(100):
        lmp.command("run 20 pre no post no")
        f2 = atom_row(lmp, "f", 2)
        n = normal(lmp)
        loads.append(np.linalg.norm(f2 - np.dot(f2, n) * n))
        u_s.append(ledger(lmp)["U_s"])
        zeta.append(lmp.numpy.extract_compute("bonds", 2, 2)[0, 5])
    e = ledger(lmp)
    # eq. (14): k_s zeta_crit times (r1 + r2 - zeta0.n_c) / |x1 - x2| = 2 r / (2 r - delta0)
    plateau = F_FRIC * 2 * R_GRAIN / D0
    assert max(loads) == pytest.approx(plateau, rel=1e-3)
    assert max(zeta) == pytest.approx(ZETA_CRIT, rel=1e-6)           # clamped by eq. (42)
    assert max(u_s) == pytest.approx(0.5 * K_S * ZETA_CRIT ** 2, rel=1e-6)
    # the kinetic energy went into sliding, none into rolling or twisting
    assert e["sliding"] > 0.95 * start["ke"]
    assert e["rolling"] == 0.0 and e["twisting"] == 0.0
    assert abs(e["total"] - start["total"]) < 1e-5 * start["ke"]


def test_twisting_torque_saturates_at_eq37(lmp):
    held_pair(lmp)
    lmp.command("set atom 1 omega 3e8 0 0")     # about n_c (the x axis)
    lmp.command("run 0")
    start = ledger(lmp)
    torques = []
    for _ in range(300):                         # spins down in about 4700 steps
        lmp.command("run 20 pre no post no")
        torques.append(abs(np.dot(atom_row(lmp, "torque", 2), normal(lmp))))
    e = ledger(lmp)
    assert max(torques) == pytest.approx(M_FRIC, rel=1e-9)
    phi = lmp.numpy.extract_compute("bonds", 2, 2)[0, 7]
    assert abs(phi) <= PHI_CRIT * (1 + 1e-12)
    assert e["twisting"] > 0.95 * (start["erot"])
    assert e["sliding"] == 0.0 and e["rolling"] == 0.0
    assert abs(e["total"] - start["total"]) < 1e-6 * start["erot"]


def oscillate(dt_over_tc, duration_tc=60.0):
    """A bonded pair, both grains free, set spinning and sliding well inside
    the elastic limits. Returns the peak U_s, U_r, U_t, the final ledger and the
    largest |dE|, all over the energy put in."""
    lmp = start_lammps()
    try:
        two_grain_scene(lmp, D0, coeff_extra=f"xi_crit {XI_CRIT!r}", dt_over_tc=dt_over_tc)
        w = 2e6 * np.random.default_rng(3).normal(size=3)
        lmp.command(f"set atom 1 omega {' '.join(repr(float(c)) for c in w)} vy 0.02")
        lmp.command("set atom 2 vy -0.02")
        lmp.command("run 0")
        start = ledger(lmp)
        peak, drift = np.zeros(3), 0.0
        steps = int(duration_tc / dt_over_tc)
        for _ in range(200):
            lmp.command(f"run {steps // 200} pre no post no")
            e = ledger(lmp)
            peak = np.maximum(peak, [e["U_s"], e["U_r"], e["U_t"]])
            drift = max(drift, abs(e["total"] - start["total"]))
    finally:
        lmp.close()
    energy_in = start["ke"] + start["erot"]
    return peak / energy_in, e, drift / energy_in


def test_small_oscillations_are_elastic_and_conserve_energy():
    peak, e, coarse = oscillate(0.014)
    _, _, fine = oscillate(0.005)
    print(f"peak U_s, U_r, U_t / E_in = {peak}; max |dE| / E_in = {coarse:.2e} (0.014 t_c), "
          f"{fine:.2e} (0.005 t_c)")
    assert np.all(peak > 0.05)                        # all three springs take part
    assert e["sliding"] == e["rolling"] == e["twisting"] == 0.0       # no clamp, no dissipation
    # the stiffest mode (sliding against spin) has omega dt = 0.037 at 0.014 t_c, so
    # velocity Verlet's energy wobbles by ~(omega dt)^2 / 8 = 1.7e-4; it is second order
    assert coarse < 3e-4
    assert coarse / fine > 6.0                        # (0.014 / 0.005)^2 = 7.8
