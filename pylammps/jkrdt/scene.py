"""A collision scene: what it is, and the ``pair_coeff`` line of its material and model.

A scene is the material and grain radius, the dimension, the model ('frictional':
Wada et al. 2007 with the material's xi_crit; 'frictionless': the 3D BPCA paper's
model without sliding, rolling and twisting), the aggregates' kind and sizes, v_col,
B_off, the seed, the time step and the neighbor skin, and two choices of the set-up that
the papers leave open (``bond``: the aggregates' bonds at the JKR equilibrium delta_0, as
built by default, or touching; ``gap``: how far apart the aggregates start). It is a
value: how it is written into a directory, read back and run (``collision.json``, the
deck and its variables) is ``jkrdt.rundir``'s.

E_imp = mu v_col^2 / 2 with mu = m N_tar N_pro / (N_tar + N_pro), equal grains of mass m.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from . import collision
from . import timestep, units
from .aggregates import BUILDERS, check_fits
from .materials import Material, scales
from .timestep import PAPER_DT

MODELS = ("frictional", "frictionless")
#: the 3D BPCA paper's four models, as it names them, and how to ask for each
PAPER_MODELS = ("frictional (model 'frictional'), frictional with normal dissipation "
                "(model 'frictional', tvis 6e-12 s), frictionless ('frictionless'), "
                "frictionless with normal dissipation ('frictionless', tvis 6e-12 s)")
#: where the aggregates' bonds sit, as a fraction of delta_0: at the JKR equilibrium (at
#: rest, the default), or touching (delta 1e-3 delta_0, just inside contact: each bond then
#: pulls with about 0.9 F_c and the aggregates start with the energy of settling into it)
BONDS = {"equilibrium": 1.0, "touching": 1.0e-3}


def pair_coeff(mat: Material, model: str = "frictional") -> str:
    """The words of ``pair_coeff * *`` for ``mat`` under ``model`` (SI units)."""
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}: use 'frictional' or 'frictionless'; "
                         f"the 3D paper's four models are {PAPER_MODELS}")
    words = [f"gamma {mat.gamma!r}", f"E {mat.E!r}", f"nu {mat.nu!r}"]
    if mat.G is not None:
        words.append(f"G {mat.G!r}")
    if mat.tvis > 0:
        words.append(f"tvis {mat.tvis!r}")
        if not mat.damp_tension:
            words.append("damp_tension off")
    if model == "frictionless":
        words.append("frictionless")
    elif mat.xi_crit is None:
        raise ValueError(f"material {mat.name!r} has no xi_crit: give one, or use the "
                         "'frictionless' model")
    else:
        words.append(f"xi_crit {mat.xi_crit!r}")
    return " ".join(words)


#: the neighbor skin (m) of a scene whose grains are slow enough for it: ~10 delta_c of
#: 0.1 micron ice. Faster steps get SKIN_STEPS times the step of a pair at 2 v_col
SKIN_MIN = 1.0e-8
#: the plugin stops a pair that closes more than half the skin in one step; a pair of the
#: collision closes at most ~v_col per step (2 v_col for a grain thrown back), so 4 steps of
#: 2 v_col keep it at a quarter of the skin
SKIN_STEPS = 4.0


@dataclasses.dataclass(frozen=True)
class Scene:
    """What one collision is. ``dt_over_tc`` None means the papers' 0.014 t_c."""

    material: Material
    n_tar: int
    n_pro: int
    v_col: float                    # m/s
    b_off: float = 0.0              # B_off, in [0, 1]
    seed: int | None = 1
    kind: str = "bpca"
    dim: int = 3
    radius: float = 1.0e-7          # m
    model: str = "frictional"
    dt_over_tc: float | None = None
    dt_reason: str | None = None
    skin: float | None = None       # m; None: from the speed and dt (skin_for)
    bond: str = "equilibrium"       # one of BONDS
    gap: float | None = None        # m between the nearest grains at start; None: delta_c/2

    def __post_init__(self):
        if not self.v_col > 0:
            raise ValueError(f"v_col is the collision speed and must be > 0 m/s "
                             f"(got {self.v_col})")
        if not 0 <= self.b_off <= 1:
            raise ValueError(f"B_off must lie in [0, 1] (got {self.b_off})")
        if self.kind not in BUILDERS:
            raise ValueError(f"unknown aggregate kind {self.kind!r}: one of {sorted(BUILDERS)}")
        if self.dim not in (2, 3):
            raise ValueError(f"dimension must be 2 or 3 (got {self.dim})")
        if self.skin is not None and not self.skin > 0:
            raise ValueError(f"the neighbor skin must be > 0 m (got {self.skin:g})")
        if not self.radius > 0:
            raise ValueError(f"the grain radius must be > 0 m (got {self.radius:g})")
        if min(self.n_tar, self.n_pro) < 1:
            raise ValueError("each aggregate needs at least one grain")
        check_fits(self.n_tar + self.n_pro)
        if self.dt_over_tc is not None:
            timestep.check(self.dt_over_tc)
        if self.bond not in BONDS:
            raise ValueError(f"unknown bond {self.bond!r}: one of {sorted(BONDS)}")
        if self.gap is not None and not self.gap >= 0:
            raise ValueError(f"the initial gap must be >= 0 m (got {self.gap:g})")
        pair_coeff(self.material, self.model)          # the model fits the material
        units.check(self)                              # SI values near grain scales

    @functools.cached_property
    def scales(self):
        return scales(self.material, self.radius)

    @property
    def pair_coeff(self) -> str:
        return pair_coeff(self.material, self.model)

    @property
    def E_imp(self) -> float:
        n = self.n_tar + self.n_pro
        return 0.5 * self.scales.mass * self.n_tar * self.n_pro / n * self.v_col ** 2

    def time_step(self, dt_over_tc: float | None = None) -> tuple[float, str]:
        """(dt / t_c, why): ``dt_over_tc`` if given, else the scene's, else the papers'."""
        if dt_over_tc is not None:
            if not dt_over_tc > 0:
                raise ValueError(f"dt must be > 0 (in units of t_c; got {dt_over_tc})")
            return dt_over_tc, f"dt = {dt_over_tc:g} t_c given for this run"
        if self.dt_over_tc is not None:
            return self.dt_over_tc, self.dt_reason or "the scene's dt"
        return PAPER_DT, f"dt = {PAPER_DT} t_c, the papers' choice (Wada et al. 2007, sec. 4)"

    def energy_bound(self) -> dict:
        """What the energy-error bound of ``jkrdt.timestep`` depends on besides dt and
        v_col."""
        return dict(model=self.model, n_total=self.n_tar + self.n_pro,
                    damped=self.material.tvis > 0)

    def predicted_error(self) -> float:
        """The bound on max |dE| / E_imp at this scene's dt (``jkrdt.timestep``)."""
        return timestep.predicted_error(self.time_step()[0], self.v_col / self.scales.v0,
                                        **self.energy_bound())

    def with_dt_for(self, tolerance: float) -> "Scene":
        """This scene with dt chosen for a max |dE| / E_imp of ``tolerance``
        (``jkrdt.timestep.choose``, which raises ValueError for a tolerance outside (0, 1))."""
        dt, reason = timestep.choose(tolerance, self.v_col, self.scales.v0,
                                     **self.energy_bound())
        return dataclasses.replace(self, dt_over_tc=dt, dt_reason=reason)

    def skin_for(self, dt_over_tc: float) -> float:
        """The neighbor skin (m): the scene's own, else SKIN_MIN or, for grains that move
        farther in a step (large grains, fast collisions), SKIN_STEPS steps at 2 v_col."""
        if self.skin is not None:
            return self.skin
        return max(SKIN_MIN, SKIN_STEPS * 2.0 * self.v_col * dt_over_tc * self.scales.t_c)

    def aggregates(self, rng=None) -> tuple[np.ndarray, np.ndarray]:
        """Target and projectile built by ``rng`` (default: a generator seeded by the
        scene's seed, so the same for every v_col and B_off)."""
        rng = np.random.default_rng(self.seed) if rng is None else rng
        build = BUILDERS[self.kind]
        delta = BONDS[self.bond] * self.scales.delta0
        return tuple(build(n, self.radius, delta, rng, dim=self.dim)
                     for n in (self.n_tar, self.n_pro))

    def collide(self, aggregates=None, rng=None) -> collision.Collision:
        """The two aggregates set up to collide, rotated at random by ``rng``. Without
        ``aggregates`` they are built from the seed and the same generator rotates
        them; given ones are rotated by ``rng`` (default: seeded by [seed, 1])."""
        if aggregates is None:
            rng = np.random.default_rng(self.seed)
            aggregates = self.aggregates(rng)
        elif rng is None:
            rng = np.random.default_rng([self.seed or 0, 1])
        if tuple(map(len, aggregates)) != (self.n_tar, self.n_pro):
            raise ValueError("the aggregates do not have the scene's n_tar and n_pro grains")
        return collision.set_up(*aggregates, self.radius, v_col=self.v_col, b_off=self.b_off,
                                rng=rng, delta_c=self.scales.delta_c, gap=self.gap,
                                dim=self.dim)
