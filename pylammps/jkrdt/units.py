"""Values a user can't get wrong by a unit: a scene's numbers are SI (m, s, m/s, Pa, J/m^2),
and one given in the unit it is usually quoted in (micron, ps, Angstrom, GPa, mJ/m^2)
lands decades away from grain scales. Such a value is refused at set-up in one line that
names its SI unit and the value the user probably meant; the bounds are wide (a few
decades around the presets and the papers' values), so no real grain is refused."""

from __future__ import annotations

#: grain radii, m: 1 nm to 1 mm
RADIUS = (1e-9, 1e-3)
#: collision speeds, m/s: up to 10 km/s
V_COL_MAX = 1e4
#: Young's modulus, Pa, and surface energy, J/m^2: about three decades around the presets
#: (ice 7 GPa and 0.1 J/m^2, quartz 54 GPa and 0.025 J/m^2)
E_RANGE = (1e6, 1e13)
GAMMA_RANGE = (1e-5, 10.0)


def check(scene) -> None:
    """Raise ValueError for a value of ``scene`` (a jkrdt.scene.Scene) outside grain
    scales, naming its unit and what was probably meant."""
    r, mat = scene.radius, scene.material
    if not RADIUS[0] <= r <= RADIUS[1]:
        raise ValueError(f"the grain radius {r:g} m lies outside grain scales (1 nm to 1 mm): "
                         f"radii are in metres; {r * 1e-6:g} if you meant {r:g} micron")
    if scene.v_col > V_COL_MAX:
        raise ValueError(f"v_col {scene.v_col:g} m/s exceeds 10 km/s: speeds are in m/s")
    if not E_RANGE[0] <= mat.E <= E_RANGE[1]:
        raise ValueError(f"E = {mat.E:g} Pa lies decades from the presets (ice 7e9, quartz "
                         f"5.4e10): moduli are in Pa; {mat.E * 1e9:g} if you meant "
                         f"{mat.E:g} GPa")
    if not GAMMA_RANGE[0] <= mat.gamma <= GAMMA_RANGE[1]:
        raise ValueError(f"gamma = {mat.gamma:g} J/m^2 lies decades from the presets (ice "
                         f"0.1, quartz 0.025): surface energies are in J/m^2; "
                         f"{mat.gamma * 1e-3:g} if you meant {mat.gamma:g} mJ/m^2")
    if mat.xi_crit is not None and mat.xi_crit > r:
        raise ValueError(f"xi_crit = {mat.xi_crit:g} m exceeds the grain radius ({r:g} m): "
                         f"it is in metres (the papers' 8 Angstrom is 8e-10); "
                         f"{mat.xi_crit * 1e-10:g} if you meant {mat.xi_crit:g} Angstrom")
    t_c = scene.scales.t_c
    if mat.tvis > t_c:
        raise ValueError(f"tvis = {mat.tvis:g} s exceeds the contact time t_c = {t_c:.3g} s: "
                         f"it is in seconds (the paper's 6 ps is 6e-12); "
                         f"{mat.tvis * 1e-12:g} if you meant {mat.tvis:g} ps")
