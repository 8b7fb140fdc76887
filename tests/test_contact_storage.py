"""Contact storage grows instead of dropping contacts, and the contact outputs agree."""

import numpy as np
import pytest

from conftest import ENERGY_THERMO, ICE_SCALES as S, R_GRAIN, ledger
from jkrdt.materials import ICE
from jkrdt.scene import pair_coeff

U_EQUILIBRIUM = -0.8 * 6 ** (1 / 3) * S.F_c * S.delta_c      # eq. (6) at a = a0


def icosahedron():
    g = (1 + 5 ** 0.5) / 2
    v = np.array([(0, s1, s2 * g) for s1 in (-1, 1) for s2 in (-1, 1)], float)
    v = np.vstack([v, np.roll(v, 1, axis=1), np.roll(v, 2, axis=1)])
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_twelve_contacts_on_one_grain(lmp):
    # 12 neighbours at the bond length around one grain: more than the initial
    # per-atom capacity (8); shell grains sit 1.05 bond lengths apart, not touching
    shell = icosahedron() * (2 * R_GRAIN - S.delta0)
    lmp.commands_string(f"""
        units si
        atom_style sphere
        atom_modify map array
        boundary f f f
        comm_modify vel yes
        region box block -1e-6 1e-6 -1e-6 1e-6 -1e-6 1e-6
        create_box 1 box
        create_atoms 1 single 0 0 0
    """)
    for x, y, z in shell.tolist():
        lmp.command(f"create_atoms 1 single {x!r} {y!r} {z!r}")
    lmp.commands_string(f"""
        set type 1 diameter {2 * R_GRAIN!r}
        set type 1 density {ICE.density!r}
        pair_style jkr/dt
        pair_coeff * * {pair_coeff(ICE, 'frictionless')}
        neighbor {S.delta_c!r} bin
        compute p all pair jkr/dt
        compute erot all erotate/sphere
        compute coord all jkr/dt/coordination
        compute bonds all jkr/dt/contacts
        fix nve all nve/sphere
        timestep 1e-12
        thermo_style custom {ENERGY_THERMO}
        run 0
    """)
    e = ledger(lmp)
    assert e["contacts"] == 12
    assert e["pe"] == pytest.approx(12 * U_EQUILIBRIUM, rel=1e-9)
    coord = lmp.numpy.extract_compute("coord", 1, 1)
    ids = lmp.numpy.extract_atom("id")
    assert coord[list(ids).index(1)] == 12
    assert sorted(coord[list(ids).index(k)] for k in range(2, 14)) == [1] * 12
    rows = lmp.numpy.extract_compute("bonds", 2, 2)
    assert rows.shape == (12, 8)
    assert set(rows[:, 0]) == {1} and sorted(rows[:, 1]) == list(range(2, 14))
    assert np.allclose(rows[:, 2], S.delta0, rtol=1e-9)
    assert np.allclose(rows[:, 3], S.a0, rtol=1e-9)


def doubles_per_contact(lmp, coeff, dim=3):
    """The contact fix's global scalar after a run 0 of two bonded ice grains."""
    lmp.commands_string(f"""
        units si
        dimension {dim}
        atom_style sphere
        boundary f f {'p' if dim == 2 else 'f'}
        comm_modify vel yes
        region box block -1e-6 1e-6 -1e-6 1e-6 -1e-6 1e-6
        create_box 1 box
        create_atoms 1 single 0 0 0
        create_atoms 1 single {2 * R_GRAIN - S.delta0!r} 0 0
        set type 1 diameter {2 * R_GRAIN!r}
        set type 1 density {ICE.density!r}
        pair_style jkr/dt
        pair_coeff * * gamma 0.1 E 7e9 nu 0.25 {coeff}
        neighbor 1e-8 bin
        fix nve all nve/sphere
        {'fix plane all enforce2d' if dim == 2 else ''}
        timestep 1e-12
        run 0
    """)
    return lmp.extract_fix("JKR_DT_CONTACTS", 0, 0)


@pytest.mark.parametrize("coeff, dim, doubles", [
    ("xi_crit 8e-10", 3, 7),                 # pointers n1, n2 and the twisting angle
    ("xi_crit 8e-10 tvis 6e-12", 3, 8),      # ... and the damping force of eq. (A.5)
    ("frictionless", 3, 0),                  # nothing: the JKR normal force has no history
    ("frictionless tvis 6e-12", 3, 1),
    ("xi_crit 8e-10", 2, 6),                 # 2D: no twist, so no twisting angle
])
def test_a_scene_stores_only_what_its_model_needs(lmp, coeff, dim, doubles):
    assert doubles_per_contact(lmp, coeff, dim) == doubles
