"""A collision scene: what it is, how it is written into a directory and read back, and
the ``pair_coeff`` line of its material and model. Every other part (``jkrdt setup``,
``jkrdt run``, campaigns, ``Session``, the analysis) goes through this module.

A scene is the material and grain radius, the dimension, the model ('frictional':
Wada et al. 2007 with the material's xi_crit; 'frictionless': the 3D BPCA paper's
model without sliding, rolling and twisting), the aggregates' kind and sizes, v_col,
B_off, the seed and the time step. Its directory holds

    collision.data     the grains (target type 1, projectile type 2), LAMMPS data file
    collision.json     the scene's fields and its set-up (E_imp, b, gap, ...)
    in.collision.lmp   its variables, then ``inputs/collision.lmp``: the deck every
                       route runs (``cd DIR && lmp -in in.collision.lmp``)

E_imp = mu v_col^2 / 2 with mu = m N_tar N_pro / (N_tar + N_pro), equal grains of mass m.
"""

from __future__ import annotations

import dataclasses
import functools
import json
from pathlib import Path

import numpy as np

from . import collision
from . import timestep
from .aggregates import BUILDERS, check_fits
from .datafile import write_sphere_data
from .materials import Material, from_dict, scales
from .timestep import PAPER_DT

MODELS = ("frictional", "frictionless")
#: up to this many grains a scene finds neighbors without bins (``neighbor nsq``) and does
#: not sort its atoms: LAMMPS's bins and sort bins fill the whole box, which fragments
#: flying apart make huge (2 x 100 frictionless grains at 39.8 m/s: 83 s with bins,
#: 3.6 s without); for a compact scene of 1000 grains both cost the same
NSQ_MAX = 2000
DATA, META, DECK = "collision.data", "collision.json", "in.collision.lmp"
#: a run's record (inputs/collision.lmp writes them): the frames of atoms and of contacts
#: (compressed, every ``frames`` checks and at the end), the settle rule's table of the
#: fragments at every check, and the log with the energies at every check
ATOMS, CONTACTS, CHECKS, LOG = "atoms.dump.gz", "contacts.dump.gz", "checks.csv", "log.lammps"
#: the outputs a new run of a scene replaces; LAMMPS appends to none of them, but a run
#: that fails early would leave the last run's behind
RUN_OUTPUTS = (ATOMS, CONTACTS, CHECKS, LOG)
#: the end state (written at the end of a run: the restart file, and the grains with their
#: spins, compressed) and the restart files of a run under way, written alternately at
#: every check
FINAL_RESTART, FINAL_DUMP = "final.restart", "final.dump.gz"
ROLLING_RESTARTS = ("restart.a", "restart.b")
#: what a scene directory holds once set up, run and analysed (all that a fresh scene clears)
#: what jkrdt analyse writes into a run directory
ANALYSIS_OUTPUTS = ("frames.csv", "outcome.json", "outcome.png", "outcome.pdf", "energy.png",
                    "energy.pdf", "timeline.png", "timeline.pdf")
SCENE_FILES = (DATA, META, DECK, *RUN_OUTPUTS, *ANALYSIS_OUTPUTS, *ROLLING_RESTARTS,
               FINAL_RESTART, FINAL_DUMP)


def pair_coeff(mat: Material, model: str = "frictional") -> str:
    """The words of ``pair_coeff * *`` for ``mat`` under ``model`` (SI units)."""
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}: use 'frictional' or 'frictionless'")
    words = [f"gamma {mat.gamma!r}", f"E {mat.E!r}", f"nu {mat.nu!r}"]
    if mat.G is not None:
        words.append(f"G {mat.G!r}")
    if mat.tvis > 0:
        words.append(f"tvis {mat.tvis!r}")
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
        pair_coeff(self.material, self.model)          # the model fits the material

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

    def time_variables(self, dt_over_tc: float | None = None) -> dict:
        """The deck's dt (s), dt_over_tc and dt_note for ``dt_over_tc`` (see time_step)."""
        ratio, why = self.time_step(dt_over_tc)
        return dict(dt=ratio * self.scales.t_c, dt_over_tc=ratio,
                    dt_note=why.replace('"', "'"), skin=self.skin_for(ratio))

    def skin_for(self, dt_over_tc: float) -> float:
        """The neighbor skin (m): the scene's own, else SKIN_MIN or, for grains that move
        farther in a step (large grains, fast collisions), SKIN_STEPS steps at 2 v_col."""
        if self.skin is not None:
            return self.skin
        return max(SKIN_MIN, SKIN_STEPS * 2.0 * self.v_col * dt_over_tc * self.scales.t_c)

    def deck_variables(self) -> dict:
        """The variables of ``inputs/collision.lmp`` that make it run this scene."""
        few = self.n_tar + self.n_pro <= NSQ_MAX
        return dict(file=DATA, dim=self.dim, coeffs=self.pair_coeff, **self.time_variables(),
                    **(dict(neighbor="nsq", sort="0 0.0") if few else {}))

    def aggregates(self, rng=None) -> tuple[np.ndarray, np.ndarray]:
        """Target and projectile built by ``rng`` (default: a generator seeded by the
        scene's seed, so the same for every v_col and B_off)."""
        rng = np.random.default_rng(self.seed) if rng is None else rng
        build = BUILDERS[self.kind]
        return tuple(build(n, self.radius, self.scales.delta0, rng, dim=self.dim)
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
                                rng=rng, delta_c=self.scales.delta_c, dim=self.dim)

    def metadata(self) -> dict:
        """``collision.json`` without the set-up's geometry."""
        meta = dict(N_tar=self.n_tar, N_pro=self.n_pro, v_col=self.v_col, B_off=self.b_off,
                    seed=self.seed, material=dataclasses.asdict(self.material),
                    radius=self.radius, dimension=self.dim, E_imp=self.E_imp, kind=self.kind,
                    model=self.model)
        if self.dt_over_tc is not None:
            meta.update(dt_over_tc=self.dt_over_tc, dt_reason=self.dt_reason)
        meta.update(skin=self.skin_for(self.time_step()[0]), skin_given=self.skin is not None)
        return meta


def from_metadata(meta: dict) -> Scene:
    """The scene of a ``collision.json``."""
    return Scene(material=from_dict(meta["material"]), n_tar=meta["N_tar"],
                 n_pro=meta["N_pro"], v_col=meta["v_col"], b_off=meta["B_off"],
                 seed=meta.get("seed"), kind=meta.get("kind") or "bpca",
                 dim=meta["dimension"], radius=meta["radius"],
                 model=meta.get("model") or "frictional", dt_over_tc=meta.get("dt_over_tc"),
                 dt_reason=meta.get("dt_reason"),
                 skin=meta["skin"] if meta.get("skin_given") else None)


def read_metadata(directory) -> dict:
    path = Path(directory) / META
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: {directory} is not a scene; write one "
                                "with 'jkrdt setup' (or jkrdt.scene.write)")
    return json.loads(path.read_text())


def read(directory) -> Scene:
    """The scene written into ``directory``."""
    return from_metadata(read_metadata(directory))


def find_template(name: str = "collision.lmp") -> Path:
    """A deck of ``inputs/``: the copy installed in the package, else the checkout's."""
    here = Path(__file__).resolve().parent
    for base in [here, Path.cwd(), *here.parents]:
        deck = base / "inputs" / name
        if deck.exists():
            return deck
    raise FileNotFoundError(f"inputs/{name} not found: reinstall with 'pip install .' "
                            "or run from the repository root")


def deck(directory) -> Path:
    """The scene's own deck in ``directory``; raises with the fix if it is missing."""
    path = Path(directory) / DECK
    if not path.exists():
        raise FileNotFoundError(f"{path} does not exist: write the scene with 'jkrdt setup', "
                                f"or its deck with jkrdt.scene.write_deck('{directory}')")
    return path


def write_deck(directory, scene: Scene | None = None) -> Path:
    """``in.collision.lmp``: the scene's variables, then ``inputs/collision.lmp`` verbatim
    (a variable's first definition wins, so ``-var NAME VALUE`` still overrides)."""
    directory = Path(directory)
    scene = read(directory) if scene is None else scene
    lines = ["# jkr/dt: the scene in this directory (written by jkr/dt's scene module); run",
             "#   lmp -in in.collision.lmp     or     mpirun -np 2 lmp -in in.collision.lmp",
             "# here. Any variable below can be overridden with -var NAME VALUE.", ""]
    lines += [f'variable {name:<10} index "{value}"'
              for name, value in scene.deck_variables().items()]
    deck = directory / DECK
    tmp = deck.with_name(DECK + ".tmp")
    tmp.write_text("\n".join(lines) + "\n\n" + find_template().read_text())
    tmp.replace(deck)
    return deck


def write(directory, scene: Scene, placed: collision.Collision | None = None,
          **extra) -> Path:
    """Write the scene into ``directory``: its grains (``placed``, default
    ``scene.collide()``), ``collision.json`` (with ``extra`` fields) and its deck.
    Returns the directory."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    placed = scene.collide() if placed is None else placed
    write_sphere_data(directory / DATA, placed.x, scene.radius, scene.material.density,
                      v=placed.v, types=placed.body, margin=20 * scene.radius)
    meta = dict(scene.metadata(), **placed.meta, **extra)
    tmp = directory / (META + ".tmp")
    tmp.write_text(json.dumps(meta, indent=2, default=float))
    tmp.replace(directory / META)
    write_deck(directory, scene)
    return directory
