"""Shared scenes for the tests: real LAMMPS instances with pair jkr/dt."""

import numpy as np
import pytest

from jkrdt import ledger as jkrdt_ledger
from jkrdt.materials import ICE, scales
from jkrdt.session import start_lammps

R_GRAIN = 1.0e-7          # 0.1 micron grains, as in both papers
#: the environment of runs with more ranks than cores: MPICH's ranks sleep while they wait
#: instead of polling (4 polling ranks on 2 cores take several times as long)
SLEEPING_RANKS = dict(MPIR_CVAR_CH4_PROGRESS_THROTTLE="true",
                      MPIR_CVAR_CH4_PROGRESS_THROTTLE_NO_PROGRESS_COUNT="1")
ICE_SCALES = scales(ICE, R_GRAIN)


def jkr_sqrt_radius(d):
    """Reference for eq. (4), independent of the plugin: the largest real root
    y = sqrt(a/a0) of 3 y^4 - 2 y - d = 0."""
    roots = np.roots([3.0, 0.0, 0.0, -2.0, -d])
    return max(r.real for r in roots if abs(r.imag) < 1e-9)


def jkr_force(delta, s):
    """Eq. (5) at compression ``delta`` for scales ``s``."""
    y = jkr_sqrt_radius(delta / s.delta0)
    return 4.0 * s.F_c * y ** 3 * (y ** 3 - 1.0)


def jkr_potential(delta, s):
    """Eq. (6) at compression ``delta`` for scales ``s``."""
    x = jkr_sqrt_radius(delta / s.delta0) ** 2
    return 4.0 * 6 ** (1 / 3) * s.F_c * s.delta_c * (0.8 * x ** 5 - 4 / 3 * x ** 3.5 + x ** 2 / 3)


#: the thermo line of the small scenes: the energies and all of compute pair jkr/dt's values
ENERGY_THERMO = "step ke c_erot pe c_p[*]"


def two_grain_scene(lmp, separation, v_rel=0.0, material=ICE, coeff_extra="frictionless",
                    dt_over_tc=0.01, newton="off", box=2.0e-6, radius=R_GRAIN, skin=None,
                    settings="", atom_style="sphere"):
    """Two grains of ``radius`` (default 0.1 micron ice) on the x axis, ``separation``
    apart (centre to centre), approaching each other at ``v_rel``. The neighbor skin
    is ``skin`` (default 2 delta_c); ``settings`` go on the pair_style line
    (``atom_style="sphere 1"``: radii that may change during a run). Thermo carries the
    energy ledger."""
    r = radius
    s = scales(material, r)
    skin = 2 * s.delta_c if skin is None else skin
    lmp.commands_string(f"""
        units si
        atom_style {atom_style}
        atom_modify map array
        boundary f f f
        newton {newton}
        comm_modify vel yes
        region box block {-box} {box} {-box} {box} {-box} {box}
        create_box 1 box
        create_atoms 1 single 0 0 0
        create_atoms 1 single {separation!r} 0 0
        set type 1 diameter {2 * r!r}
        set type 1 density {material.density!r}
        velocity all set 0 0 0
        set atom 1 vx {0.5 * v_rel!r}
        set atom 2 vx {-0.5 * v_rel!r}
        pair_style jkr/dt {settings}
        pair_coeff * * gamma {material.gamma!r} E {material.E!r} nu {material.nu!r} {coeff_extra}
        neighbor {skin!r} bin
        neigh_modify every 1 delay 0 check yes
        fix integrate all nve/sphere
        compute p all pair jkr/dt
        compute erot all erotate/sphere
        thermo_style custom {ENERGY_THERMO}
        thermo_modify norm no
        timestep {dt_over_tc * s.t_c!r}
    """)
    return s


def ledger(lmp):
    """Energies at the current step: ke, erot, pe, the values of compute pair jkr/dt by
    their names (``jkrdt.ledger.VALUES``: U_n, U_s, ..., events, ..., contacts, made, cut),
    'dissipated' (the channels) and 'total', the conserved sum."""
    p = lmp.numpy.extract_compute("p", 0, 1)
    e = {name: float(p[k]) for k, name in enumerate(jkrdt_ledger.VALUES)}
    e["ke"] = lmp.get_thermo("ke")
    e["pe"] = lmp.get_thermo("pe")
    e["erot"] = float(lmp.extract_compute("erot", 0, 0))
    e["dissipated"] = sum(e[name] for name in jkrdt_ledger.CHANNELS)
    e["total"] = e["ke"] + e["erot"] + e["pe"] + e["dissipated"]
    return e


@pytest.fixture
def lmp():
    instance = start_lammps()
    yield instance
    instance.close()


def atom_force_x(lmp, atom_id):
    ids = lmp.numpy.extract_atom("id")
    f = lmp.numpy.extract_atom("f")
    return float(f[list(ids).index(atom_id), 0])


__all__ = ["R_GRAIN", "ICE_SCALES", "jkr_force", "jkr_potential", "jkr_sqrt_radius",
           "two_grain_scene", "ledger", "atom_force_x"]
