"""Collision campaigns: a grid of v_col x B_off^2 x seeds, one run directory each,
resumable.

A spec (JSON) names the grid and the scene:

    {"kind": "bpca", "dim": 3, "n_tar": 128, "n_pro": 128, "material": "ice",
     "material_overrides": {"tvis": 6e-12}, "radius": 1e-7, "model": "frictional",
     "v_col": [10, 20, 40], "b_off2": [0, 0.25, 0.5, 0.75], "seeds": [1],
     "dt": 0.014, "settle": {"check_tc": 50, "window": 5, "tolerance": 0.01,
                             "cap_tc": 40000}}

n_tar, n_pro, v_col and b_off2 are required; the other keys default to the values above
(material_overrides {}, settle {} = the settle rule's defaults), and any Material field
can be overridden in material_overrides.

Each run ends when its collision has settled (``jkrdt.stopping``; "settle" may be
left out for the defaults, or given in part), or, with ``"settle": false``, after
``"steps"`` steps, dumped every ``"every"`` steps. A run that fails is recorded with
``"stop_reason": "error"`` in its outcome.json and is not tried again.

Each run goes to ``CAMPAIGN/v<v_col>/b2_<B_off^2>/seed<seed>``. A run is finished when
its ``outcome.json`` exists; that file is written last, atomically, so an interrupted
campaign started again skips every finished run and redoes only the run that was cut
off (its restart files stay for a manual continuation). Target and projectile are
built once per seed and shared by all v_col and B_off, as in the 3D BPCA paper.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from . import collision
from .aggregates import bcca, bpca
from .materials import material, scales
from .stopping import SettleRule

BUILDERS = {"bpca": bpca, "bcca": bcca}
DEFAULTS = dict(kind="bpca", dim=3, material="ice", material_overrides={}, radius=1.0e-7,
                model="frictional", seeds=[1], dt=0.014, settle={}, steps=None, every=None)
REQUIRED = ["n_tar", "n_pro", "v_col", "b_off2"]


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _whole(x) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


#: each key's test and what it must be, for the errors of check_types
CHECKS = {
    "n_tar": (lambda x: _whole(x) and x >= 1, "a whole number of grains >= 1"),
    "n_pro": (lambda x: _whole(x) and x >= 1, "a whole number of grains >= 1"),
    "v_col": (lambda x: isinstance(x, list) and x and all(_number(v) and v > 0 for v in x),
              "a non-empty list of speeds > 0 in m/s, e.g. [10, 20]"),
    "b_off2": (lambda x: isinstance(x, list) and x and all(_number(b) for b in x),
               "a non-empty list of B_off^2 values in [0, 1], e.g. [0, 0.5, 1]"),
    "seeds": (lambda x: isinstance(x, list) and x and all(_whole(k) for k in x),
              "a non-empty list of whole numbers, e.g. [1, 2]"),
    "kind": (lambda x: x in BUILDERS, f"one of {sorted(BUILDERS)}"),
    "dim": (lambda x: x in (2, 3) and _whole(x), "2 or 3"),
    "radius": (lambda x: _number(x) and x > 0, "a grain radius > 0 in m"),
    "model": (lambda x: x in ("frictional", "frictionless"), "'frictional' or 'frictionless'"),
    "material_overrides": (lambda x: isinstance(x, dict), "an object of Material fields"),
    "dt": (lambda x: _number(x) and x > 0, "a time step > 0 in units of t_c"),
    "steps": (lambda x: x is None or (_whole(x) and x >= 1), "a whole number of steps >= 1"),
    "every": (lambda x: x is None or (_whole(x) and x >= 1), "a whole number of steps >= 1"),
    "settle": (lambda x: isinstance(x, (bool, dict)), "true, false or an object of SettleRule "
               "fields"),
}


def check_types(path, spec: dict) -> None:
    """Every key of ``spec`` of the type and range it must have, or a ValueError naming it."""
    for key, (ok, what) in CHECKS.items():
        if not ok(spec[key]):
            raise ValueError(f"{path}: \"{key}\" must be {what} (got {spec[key]!r})")
    try:
        material(spec["material"], **spec["material_overrides"])
    except (TypeError, ValueError) as err:
        raise ValueError(f"{path}: \"material\"/\"material_overrides\": {err}") from None


def read_spec(path) -> dict:
    """The spec at ``path`` with defaults filled in; ``spec["settle"]`` becomes a
    ``SettleRule`` or None (fixed steps)."""
    given = json.loads(Path(path).read_text())
    unknown = sorted(set(given) - set(DEFAULTS) - set(REQUIRED))
    if unknown:
        raise ValueError(f"{path}: unknown keys {unknown}; known: "
                         f"{sorted(set(DEFAULTS) | set(REQUIRED))}")
    spec = dict(DEFAULTS, **given)
    missing = [k for k in REQUIRED if k not in spec]
    if missing:
        raise ValueError(f"{path}: the campaign spec lacks {missing}")
    check_types(path, spec)
    if any(not 0 <= b <= 1 for b in spec["b_off2"]):
        raise ValueError(f"{path}: b_off2 values are B_off^2 and must lie in [0, 1]")
    if spec["settle"] is False:
        if not (isinstance(spec["steps"], int) and spec["steps"] > 0):
            raise ValueError(f"{path}: with \"settle\": false give \"steps\" (> 0)")
        if spec["every"] is None:
            spec["every"] = max(1, spec["steps"] // 20)
        if spec["steps"] % spec["every"]:
            raise ValueError(f"{path}: steps must be a multiple of every, so that the last "
                             "frame is the end of the run")
        spec["settle"] = None
    else:
        if spec["steps"] is not None or spec["every"] is not None:
            raise ValueError(f"{path}: \"steps\" and \"every\" go with \"settle\": false; a "
                             "settling run is capped by settle.cap_tc and dumped at its checks")
        settle = {} if spec["settle"] is True else spec["settle"]
        try:
            spec["settle"] = SettleRule(**settle)
        except TypeError:
            raise ValueError(f"{path}: settle takes {sorted(SettleRule.__dataclass_fields__)} "
                             f"(got {sorted(settle)})") from None
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from None
    return spec


def record_failure(directory: Path, v: float, b2: float, seed, error: str) -> None:
    """outcome.json of a run that failed: its parameters and the error, no outcome."""
    from jkrdt.analysis.tables import write_json

    meta = json.loads((directory / "collision.json").read_text())
    mat = meta["material"]
    write_json(directory / "outcome.json",
               dict(run=str(directory), v_col=v, B_off=float(np.sqrt(b2)), seed=seed,
                    model=meta.get("model"), material=mat["name"], xi_crit=mat["xi_crit"],
                    tvis=mat["tvis"], N_tar=meta["N_tar"], N_pro=meta["N_pro"],
                    stop_reason="error", settled=False, problem=error))


def run_directory(campaign, v: float, b2: float, seed) -> Path:
    return Path(campaign) / f"v{v:g}" / f"b2_{b2:.4f}" / f"seed{seed}"


def plan(spec: dict, campaign) -> list[tuple[float, float, int, Path]]:
    return [(v, b2, seed, run_directory(campaign, v, b2, seed))
            for seed in spec["seeds"] for v in spec["v_col"] for b2 in spec["b_off2"]]


def run_campaign(spec_path, campaign, progress: bool = True) -> dict:
    """Run every unfinished run of the campaign; returns counts of done and skipped runs.
    Works under ``mpiexec -n K``: each run uses all ranks, rank 0 writes the files."""
    from mpi4py import MPI
    from tqdm import tqdm

    from jkrdt.analysis.run import analyse_run

    from .session import Session, write_scene_deck

    comm = MPI.COMM_WORLD
    spec = read_spec(spec_path)
    campaign = Path(campaign)
    mat = material(spec["material"], **spec["material_overrides"])
    s = scales(mat, spec["radius"])
    todo = plan(spec, campaign)
    skipped = sum((d / "outcome.json").exists() for *_, d in todo)
    aggregates = {}
    bar = tqdm(todo, unit="run", disable=not progress or comm.rank != 0)
    for v, b2, seed, directory in bar:
        if (directory / "outcome.json").exists():
            continue
        bar.set_description(f"v {v:g} B_off^2 {b2:g} seed {seed}")
        if comm.rank == 0:
            if seed not in aggregates:
                rng = np.random.default_rng(seed)
                build = BUILDERS[spec["kind"]]
                aggregates[seed] = (build(spec["n_tar"], spec["radius"], s.delta0, rng,
                                          dim=spec["dim"]),
                                    build(spec["n_pro"], spec["radius"], s.delta0, rng,
                                          dim=spec["dim"]))
            tar, pro = aggregates[seed]
            c = collision.set_up(tar, pro, spec["radius"], v_col=v, b_off=float(np.sqrt(b2)),
                                 rng=np.random.default_rng([seed, 1]), material=mat,
                                 dim=spec["dim"], seed=seed)
            c.meta.update(kind=spec["kind"], model=spec["model"])
            collision.write(c, mat, directory)
            write_scene_deck(directory)
        comm.Barrier()
        failed = None
        try:
            with Session(directory, directory, dt=spec["dt"], every=spec["every"] or 1,
                         comm=comm, settle=spec["settle"]) as run:
                if spec["settle"] is None:
                    run.run(spec["steps"], chunk=spec["every"], progress=False)
                else:
                    run.run_until_settled(progress=False)
                run.write_restart()
        except Exception as err:            # a LAMMPS error: recorded, the campaign goes on
            failed = str(err).strip().splitlines()[0]
        if comm.rank == 0:
            if failed is None:
                analyse_run(directory)
            else:
                record_failure(directory, v, b2, seed, failed)
        comm.Barrier()
    bar.close()
    return dict(runs=len(todo), skipped=skipped, ran=len(todo) - skipped)
