"""The JKR normal interaction against eqs. (4)-(6) and (45) of Wada et al. (2007)."""

import numpy as np
import pytest

from conftest import ICE_SCALES as S, R_GRAIN, atom_force_x, jkr_force, jkr_potential, \
    ledger, two_grain_scene

U_EQUILIBRIUM = -0.8 * 6 ** (1 / 3)        # U_n(delta0) / (F_c delta_c), eq. (6) at a = a0
E_BREAK = 4 / 45 + 0.8 * 6 ** (1 / 3)      # eq. (45) / (A.7), ~1.5426


def place(lmp, delta):
    """Move grain 2 to compression ``delta`` and evaluate forces (run 0)."""
    lmp.command(f"set atom 2 x {float(2 * R_GRAIN - delta)!r}")
    lmp.command("run 0")


def test_rest_at_equilibrium_has_no_force_and_energy_u_delta0(lmp):
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0)
    lmp.command("run 0")
    e = ledger(lmp)
    # round-off of delta: |x| ~ 2e-7 m carries ~3e-23 m error against delta0 ~ 1e-9 m
    assert abs(atom_force_x(lmp, 1)) < 1e-11 * S.F_c
    assert e["pe"] / (S.F_c * S.delta_c) == pytest.approx(U_EQUILIBRIUM, rel=1e-10)
    assert e["contacts"] == 1


def test_force_follows_eq5_over_compression_and_tensile_branch(lmp):
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0)
    lmp.command("run 0")                                   # the contact forms at delta0
    deltas = np.concatenate([np.linspace(-0.9999, 0, 40) * S.delta_c,
                             np.linspace(0, 5, 40) * S.delta0,
                             [20 * S.delta0, 50 * S.delta0]])    # large: 50 delta0 is half a radius
    for delta in deltas:
        place(lmp, delta)
        expected = jkr_force(delta, S)
        # atom 1 sits at smaller x: a repulsive force pushes it to -x
        assert -atom_force_x(lmp, 1) == pytest.approx(expected, rel=1e-9, abs=1e-10 * S.F_c), delta
        assert ledger(lmp)["pe"] == pytest.approx(jkr_potential(delta, S), rel=1e-9,
                                                      abs=1e-10 * S.F_c * S.delta_c)


def test_tensile_force_at_break_point_and_break_beyond(lmp):
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0)
    lmp.command("run 0")
    place(lmp, -(1 - 1e-9) * S.delta_c)
    # at a/a0 = 6^(-2/3): F = 4 (1/36 - 1/6) F_c = -5/9 F_c
    assert -atom_force_x(lmp, 1) == pytest.approx(-5 / 9 * S.F_c, rel=1e-4)
    assert ledger(lmp)["contacts"] == 1
    place(lmp, -(1 + 1e-9) * S.delta_c)
    assert atom_force_x(lmp, 1) == 0.0
    assert ledger(lmp)["contacts"] == 0
    assert ledger(lmp)["pe"] == 0.0
    place(lmp, -0.5 * S.delta_c)                           # no re-forming while apart
    assert atom_force_x(lmp, 1) == 0.0 and ledger(lmp)["contacts"] == 0


def test_no_contact_before_touching(lmp):
    two_grain_scene(lmp, 2 * R_GRAIN + 0.5 * S.delta_c)
    lmp.command("run 0")
    assert atom_force_x(lmp, 1) == 0.0 and ledger(lmp)["contacts"] == 0


def test_breaking_energy_from_plugin_energies_is_eq45(lmp):
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0)
    lmp.command("run 0")
    u_eq = ledger(lmp)["pe"]
    place(lmp, -(1 - 1e-12) * S.delta_c)
    u_break = ledger(lmp)["pe"]
    # the last bonded position is 1e-12 delta_c short of the break: dU = 5/9 F_c * 1e-12 delta_c
    assert (u_break - u_eq) / (S.F_c * S.delta_c) == pytest.approx(E_BREAK, rel=1e-9)
    assert E_BREAK == pytest.approx(1.5426, abs=1e-4)


def test_unequal_radii_use_the_reduced_radius(lmp):
    # r1 = 0.1 micron, r2 = 0.05 micron: R = r1 r2 / (r1 + r2), eq. (2)
    from jkrdt.materials import ICE
    r1, r2 = R_GRAIN, 0.5 * R_GRAIN
    R = r1 * r2 / (r1 + r2)
    Estar = ICE.E / (2 * (1 - ICE.nu ** 2))
    a0 = (9 * np.pi * ICE.gamma * R ** 2 / Estar) ** (1 / 3)
    delta0 = a0 ** 2 / (3 * R)
    F_c, delta_c = 3 * np.pi * ICE.gamma * R, (9 / 16) ** (1 / 3) * delta0
    two_grain_scene(lmp, r1 + r2 - delta0)
    lmp.command(f"set atom 2 diameter {2 * r2!r}")
    lmp.command("run 0")
    assert abs(atom_force_x(lmp, 1)) < 1e-10 * F_c
    assert ledger(lmp)["pe"] / (F_c * delta_c) == pytest.approx(U_EQUILIBRIUM, rel=1e-9)
    lmp.command(f"set atom 2 x {float(r1 + r2 + 0.5 * delta_c)!r}")     # tensile, -delta_c/2
    lmp.command("run 0")
    s = type("Scales", (), dict(F_c=F_c, delta0=delta0, delta_c=delta_c))
    assert -atom_force_x(lmp, 1) == pytest.approx(jkr_force(-0.5 * delta_c, s), rel=1e-9)


def test_radii_changed_during_a_run_by_fix_adapt_follow_eq5(lmp):
    # fix adapt grows both grains by 1 % during a run with the positions frozen. The pair
    # looks its contact constants up once per scene while the radii are those of the types,
    # so it must see the new radii at every step while a fix adapt is defined: the force is
    # eq. (5) for the new R and delta, not for the radii the run started with
    from jkrdt.materials import ICE, scales
    separation = 2 * R_GRAIN - S.delta0
    two_grain_scene(lmp, separation, atom_style="sphere 1")
    lmp.command("unfix integrate")
    lmp.command("run 0")
    assert abs(atom_force_x(lmp, 1)) < 1e-10 * S.F_c
    grown = 1.01 * R_GRAIN
    lmp.command(f"variable diameter equal {2 * grown!r}")
    lmp.command("fix grow all adapt 1 atom diameter v_diameter")
    lmp.command("run 2")
    s = scales(ICE, grown)
    want = jkr_force(2 * grown - separation, s)
    assert want > S.F_c               # the old radii, at their equilibrium, give none
    assert -atom_force_x(lmp, 1) == pytest.approx(want, rel=1e-9)


def contact_radius_ratio(delta, s):
    """a / a0 of eq. (4) on the stable branch (a / a0 >= 6^(-2/3)), by bisection."""
    lo, hi = 6 ** (-1 / 3), 2.0                  # y = (a / a0)^(1/2): delta / delta0 = 3 y^4 - 2 y
    for _ in range(200):
        y = 0.5 * (lo + hi)
        lo, hi = (y, hi) if 3 * y ** 4 - 2 * y < delta / s.delta0 else (lo, y)
    return lo * lo


@pytest.mark.parametrize("damp_tension", ["on", "off"])
@pytest.mark.parametrize("delta_over_delta0", [-0.4, 0.5])
def test_damping_force_is_eq_A5_and_off_under_tension_with_damp_tension_off(lmp, damp_tension,
                                                                           delta_over_delta0):
    # a bonded contact held at delta, its grains moving apart at v_n = 1 m/s with nothing
    # integrated: the force is eq. (5) minus F_D = 2 T_vis E* / nu^2 a v_n of eq. (A.5),
    # which pulls against the separation. damp_tension off drops F_D while the contact is
    # stretched (delta < 0) and keeps it while compressed
    from jkrdt.materials import ICE
    tvis, v_n = 6e-12, 1.0
    extra = f"frictionless tvis {tvis!r} damp_tension {damp_tension}"
    two_grain_scene(lmp, 2 * R_GRAIN - S.delta0, coeff_extra=extra)
    lmp.command("run 0")                                   # the contact forms at delta0
    lmp.command("unfix integrate")
    delta = delta_over_delta0 * S.delta0
    lmp.command(f"set atom 2 x {float(2 * R_GRAIN - delta)!r}")
    lmp.command(f"set atom 1 vx {-0.5 * v_n!r}")
    lmp.command(f"set atom 2 vx {0.5 * v_n!r}")
    lmp.command("run 1")
    Estar = ICE.E / (2 * (1 - ICE.nu ** 2))
    f_d = 2 * tvis * Estar / ICE.nu ** 2 * contact_radius_ratio(delta, S) * S.a0 * v_n
    if damp_tension == "off" and delta < 0:
        f_d = 0.0
    assert f_d == 0.0 or f_d > 0.05 * S.F_c                # a force the comparison resolves
    assert -atom_force_x(lmp, 1) == pytest.approx(jkr_force(delta, S) - f_d, rel=1e-9,
                                                  abs=1e-10 * S.F_c)
    assert ledger(lmp)["contacts"] == 1
