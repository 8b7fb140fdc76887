"""Grain materials and the contact scales they imply.

All quantities are SI. The presets are Table 2 of Wada et al. (2007) with the
critical rolling displacements used in the two papers: 2 or 30 Angstrom in
Wada et al. (2007), 8 Angstrom for ice in the 3D BPCA paper.

Derived scales for two equal grains of radius r (Wada et al. 2007, sec. 2 and 4):

=========  ============================================  ===========
a0         (9 pi gamma R^2 / E*)^(1/3)                    eq. (1)
delta0     a0^2 / (3 R)                                   below (4)
delta_c    (9/16)^(1/3) delta0                            below (5)
F_c        3 pi gamma R                                   below (5)
v0, t_c    sqrt(F_c delta_c / m), delta_c / v0            eqs. (48)-(49)
E_roll     12 pi^2 gamma R xi_crit                        eq. (44), (A.9)
E_break    (4/45 + 4/5 6^(1/3)) F_c delta_c ~ 1.54 F_c delta_c   eq. (45), (A.7)
k_s        8 a0 G*,  G* = G / (2 (2 - nu))                eqs. (12)-(13)
zeta_crit  (2 - nu) a0 / (16 pi)                          eq. (36)
F_fric     k_s zeta_crit = (G/2) a0^2 / (2 pi)            eq. (35)
k_r        4 F_c / R                                      eq. (22)
k_t        16/3 (G/2) a0^3                                eq. (26)
M_fric     k_t / (16 pi) = (G/2) a0^3 / (3 pi)            eqs. (37)-(38)
E_slide    k_s zeta_crit pi R = G a0^2 R / 4              (A.11)
E_twist    k_t phi_crit pi/2 = G a0^3 / 12                (A.13)
=========  ============================================  ===========
with R = r/2, E* = E / (2 (1 - nu^2)) and G the shear modulus.
"""

from __future__ import annotations

import dataclasses
import math

ANGSTROM = 1.0e-10


@dataclasses.dataclass(frozen=True)
class Material:
    """A grain material. SI units: J/m^2, Pa, kg/m^3, m, s."""

    name: str
    gamma: float            # surface energy
    E: float                # Young's modulus
    nu: float               # Poisson ratio
    density: float
    xi_crit: float | None   # critical rolling displacement; None = rolling off
    G: float | None = None  # shear modulus; None = E / (2 (1 + nu))
    tvis: float = 0.0       # viscoelastic time scale of eq. (A.5); 0 = no damping
    # F_D of eq. (A.5) also while a contact is stretched (delta < 0), as printed; False: only
    # while compressed (the model variant of validation/damped_tension)
    damp_tension: bool = True

    def __post_init__(self):
        for field in ("gamma", "E", "density"):
            if not getattr(self, field) > 0:
                raise ValueError(f"Material {self.name!r}: {field} must be > 0")
        if not -1.0 < self.nu < 0.5:
            raise ValueError(f"Material {self.name!r}: nu must lie in (-1, 0.5)")
        if self.xi_crit is not None and not self.xi_crit > 0:
            raise ValueError(f"Material {self.name!r}: xi_crit must be > 0 or None")
        if self.tvis < 0:
            raise ValueError(f"Material {self.name!r}: tvis must be >= 0")

    @property
    def shear_modulus(self) -> float:
        return self.G if self.G is not None else self.E / (2.0 * (1.0 + self.nu))


ICE = Material("ice", gamma=0.100, E=7.0e9, nu=0.25, density=1000.0, xi_crit=8 * ANGSTROM)
QUARTZ = Material("quartz", gamma=0.025, E=54.0e9, nu=0.17, density=2600.0, xi_crit=2 * ANGSTROM)
PRESETS = {m.name: m for m in (ICE, QUARTZ)}


def material(name: str, **overrides) -> Material:
    """A preset by name ('ice', 'quartz'), with any field overridden."""
    try:
        base = PRESETS[name]
    except KeyError:
        raise ValueError(f"unknown material {name!r}; presets: {', '.join(PRESETS)}") from None
    return dataclasses.replace(base, **overrides)


def from_dict(fields: dict) -> Material:
    """The material stored in a scene's metadata (``dataclasses.asdict`` of a Material)."""
    return Material(**fields)


@dataclasses.dataclass(frozen=True)
class Scales:
    """Contact scales of two equal grains of radius ``r`` (SI)."""

    r: float
    R: float
    Estar: float
    a0: float
    delta0: float
    delta_c: float
    F_c: float
    mass: float
    v0: float
    t_c: float
    E_roll: float | None
    E_break: float
    k_s: float
    zeta_crit: float
    F_fric: float
    k_r: float
    k_t: float
    M_fric: float
    E_slide: float
    E_twist: float


E_BREAK_RATIO = 4.0 / 45.0 + 0.8 * 6.0 ** (1.0 / 3.0)   # E_break / (F_c delta_c), eq. (A.7)


def scales(mat: Material, r: float) -> Scales:
    """Derived contact scales for two grains of radius ``r`` of ``mat``."""
    if not r > 0:
        raise ValueError("grain radius must be > 0")
    R = r / 2.0
    Estar = mat.E / (2.0 * (1.0 - mat.nu ** 2))
    a0 = (9.0 * math.pi * mat.gamma * R ** 2 / Estar) ** (1.0 / 3.0)
    delta0 = a0 ** 2 / (3.0 * R)
    delta_c = (9.0 / 16.0) ** (1.0 / 3.0) * delta0
    F_c = 3.0 * math.pi * mat.gamma * R
    mass = 4.0 / 3.0 * math.pi * r ** 3 * mat.density
    v0 = math.sqrt(F_c * delta_c / mass)
    E_roll = None if mat.xi_crit is None else 12.0 * math.pi ** 2 * mat.gamma * R * mat.xi_crit
    G = mat.shear_modulus
    k_s = 8.0 * a0 * G / (2.0 * (2.0 - mat.nu))
    zeta_crit = (2.0 - mat.nu) * a0 / (16.0 * math.pi)
    k_t = 16.0 / 3.0 * (G / 2.0) * a0 ** 3
    return Scales(r=r, R=R, Estar=Estar, a0=a0, delta0=delta0, delta_c=delta_c, F_c=F_c,
                  mass=mass, v0=v0, t_c=delta_c / v0, E_roll=E_roll,
                  E_break=E_BREAK_RATIO * F_c * delta_c,
                  k_s=k_s, zeta_crit=zeta_crit, F_fric=k_s * zeta_crit, k_r=4.0 * F_c / R,
                  k_t=k_t, M_fric=k_t / (16.0 * math.pi),
                  E_slide=k_s * zeta_crit * math.pi * R, E_twist=k_t / (16.0 * math.pi) * math.pi / 2)
