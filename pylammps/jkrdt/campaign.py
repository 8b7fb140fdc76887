"""Collision campaigns: a grid of v_col x B_off^2 x seeds, one run directory each,
run side by side across MPI ranks, resumable.

A spec (JSON) names the grid and the scene:

    {"kind": "bpca", "dim": 3, "n_tar": 128, "n_pro": 128, "material": "ice",
     "material_overrides": {"tvis": 6e-12}, "radius": 1e-7, "model": "frictional",
     "v_col": [10, 20, 40], "b_off2": [0, 0.25, 0.5, 0.75], "seeds": [1],
     "dt": 0.014, "settle": {"check_tc": 50, "window": 5, "tolerance": 0.01,
                             "counts": 1e-4, "cap_tc": 40000}, "bond": null, "gap": null}

n_tar, n_pro, v_col and b_off2 are required; ``"v_col": "paper"`` and ``"b_off2": "paper"``
are the 3D BPCA paper's grids (``jkrdt.protocol``: 10^(0.1 i) m/s for i = 10 ... 20, and
B_off^2 = k/12 for k = 0 ... 11, the grazing 12/12 taken as no collision); the other keys default to the values above
(material_overrides {}, settle {} = the settle rule's defaults), and any Material field
can be overridden in material_overrides. "bond" and "gap" are the set-up's choices of
``jkrdt.scene.Scene`` (null: bonds at delta_0, a gap of delta_c / 2). "dt" is in units of
t_c, or "auto": each speed's dt then comes from "tolerance" (max |dE| / E_imp, default 1e-4) as ``jkrdt setup --dt auto
--tolerance`` chooses it (``jkrdt.timestep``).

Each run ends when its collision has settled (``jkrdt.stopping``; "settle" may be
left out for the defaults, or given in part), or, with ``"settle": false``, after
``"steps"`` steps, dumped every ``"every"`` steps. A run that fails is recorded with
``"stop_reason": "error"`` in its outcome.json and is not tried again unless asked
(``retry_failed``).

Each run goes to ``CAMPAIGN/v<v_col>/b2_<B_off^2>/seed<seed>`` as a scene directory
(``jkrdt.rundir``). Target and projectile are built once per seed and shared by all
v_col and B_off, as in the 3D BPCA paper.

Under ``mpirun -np N jkrdt campaign ... --ranks-per-run K`` the ranks form N/K groups;
each group runs whole collisions on its own communicator, taking the next unclaimed run
when it is free. A run is claimed by a lock on ``RUN/.claim`` held while it goes, which
the system releases when its holder dies: two campaigns on one directory never run the
same collision, and a killed campaign's runs are free again.

A campaign directory belongs to one spec: ``CAMPAIGN/campaign.json`` records the spec its
runs were made with (defaults filled in, the settle rule in full) and the versions of
jkr/dt that ran them. A campaign started on it with another spec is refused with the
difference named, unless ``fresh`` (``--fresh``) deletes its runs first. A failed run
stays failed until ``retry_failed`` (``--retry-failed``) runs it again from the start.

A run is finished when its ``outcome.json`` exists (``jkrdt.rundir``, which also says
how a cut-off run is continued); that file is written last, atomically, and is never
replaced. A run that was cut off resumes from its newer whole restart file, its record cut
back to that step and appended to; the settle rule's window comes back with the restart
file, so the run ends as the uninterrupted one would have. SIGINT, SIGTERM and SIGHUP end
``jkrdt campaign`` at once, its run under way left cut off for the next campaign.
"""

from __future__ import annotations

import dataclasses
import json
import shutil
import time
from pathlib import Path

import numpy as np

from . import __version__
from . import protocol, rundir
from .aggregates import BUILDERS
from .materials import material
from .scene import BONDS, Scene
from .stopping import BEFORE, SettleRule
from .timestep import AUTO_TOLERANCE, DT_STABLE

DEFAULTS = dict(kind="bpca", dim=3, material="ice", material_overrides={}, radius=1.0e-7,
                model="frictional", seeds=[1], dt=0.014, tolerance=None, settle={},
                steps=None, every=None, bond=None, gap=None)
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
              "a non-empty list of speeds > 0 in m/s, e.g. [10, 20], or \"paper\""),
    "b_off2": (lambda x: isinstance(x, list) and x and all(_number(b) for b in x),
               "a non-empty list of B_off^2 values in [0, 1], e.g. [0, 0.5, 1], or \"paper\""),
    "seeds": (lambda x: isinstance(x, list) and x and all(_whole(k) for k in x),
              "a non-empty list of whole numbers, e.g. [1, 2]"),
    "kind": (lambda x: x in BUILDERS, f"one of {sorted(BUILDERS)}"),
    "dim": (lambda x: x in (2, 3) and _whole(x), "2 or 3"),
    "radius": (lambda x: _number(x) and x > 0, "a grain radius > 0 in m"),
    "model": (lambda x: x in ("frictional", "frictionless"), "'frictional' or 'frictionless'"),
    "material_overrides": (lambda x: isinstance(x, dict), "an object of Material fields"),
    "dt": (lambda x: x == "auto" or (_number(x) and 0 < x <= DT_STABLE),
           f"a time step in (0, {DT_STABLE}] in units of t_c, or \"auto\""),
    "tolerance": (lambda x: x is None or (_number(x) and 0 < x < 1),
                  "a relative energy error in (0, 1) that dt \"auto\" is chosen for"),
    "steps": (lambda x: x is None or (_whole(x) and x >= 1), "a whole number of steps >= 1"),
    "every": (lambda x: x is None or (_whole(x) and x >= 1), "a whole number of steps >= 1"),
    "bond": (lambda x: x is None or x in BONDS, f"null or one of {sorted(BONDS)}"),
    "gap": (lambda x: x is None or (_number(x) and x >= 0),
            "null (delta_c / 2) or the aggregates' initial gap >= 0 in m"),
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
    try:
        given = json.loads(Path(path).read_text())
    except json.JSONDecodeError as err:
        raise ValueError(f"{path} is not valid JSON: {err}; fix the spec there") from None
    if not isinstance(given, dict):
        raise ValueError(f"{path}: a campaign spec is a JSON object of keys, e.g. "
                         '{"n_tar": 128, "n_pro": 128, "v_col": [20], "b_off2": [0]}')
    unknown = sorted(set(given) - set(DEFAULTS) - set(REQUIRED))
    if unknown:
        raise ValueError(f"{path}: unknown keys {unknown}; known: "
                         f"{sorted(set(DEFAULTS) | set(REQUIRED))}")
    spec = dict(DEFAULTS, **given)
    missing = [k for k in REQUIRED if k not in spec]
    if missing:
        raise ValueError(f"{path}: the campaign spec lacks {missing}")
    for key, grid in (("v_col", protocol.V_COL), ("b_off2", protocol.B_OFF2)):
        if isinstance(spec[key], str):
            if spec[key] != protocol.PAPER:
                raise ValueError(f"{path}: \"{key}\" is a list of numbers or \"paper\" (the "
                                 f"3D BPCA paper's grid), not {spec[key]!r}")
            spec[key] = list(grid)
    check_types(path, spec)
    if spec["dt"] == "auto" and spec["tolerance"] is None:
        spec["tolerance"] = AUTO_TOLERANCE
    if spec["dt"] != "auto" and spec["tolerance"] is not None:
        raise ValueError(f"{path}: \"tolerance\" goes with \"dt\": \"auto\" (the energy "
                         "error dt is chosen for); give \"dt\": \"auto\", or leave it out")
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
    for v in spec["v_col"]:             # the scenes' own checks, before any run starts
        try:
            scene_of(spec, v, spec["b_off2"][0], spec["seeds"][0])
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from None
    return spec


#: in the campaign directory: the spec its runs were made with and the versions that ran them
SPEC_RECORD = "campaign.json"


def spec_record(spec: dict) -> dict:
    """What determines a campaign's runs, as JSON: the spec with its defaults filled in
    and the settle rule in full (so that {} and the defaults written out are one spec)."""
    record = dict(spec)
    record["settle"] = (dataclasses.asdict(spec["settle"]) if spec["settle"] is not None
                        else False)
    return json.loads(json.dumps(record))


def as_numbers(value):
    """``value`` with every number a float, so that 20 and 20.0 are one speed."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, list):
        return [as_numbers(v) for v in value]
    return {k: as_numbers(v) for k, v in value.items()}


def drop_runs(campaign: Path) -> None:
    """Delete the run directories of ``campaign`` (its v<v_col>/ folders), nothing else."""
    for speed in campaign.glob("v*"):
        if speed.is_dir() and any(speed.glob("b2_*/seed*")):
            shutil.rmtree(speed)


def own(campaign: Path, spec: dict, fresh: bool = False) -> None:
    """Make ``campaign`` the directory of ``spec``: record it there, or raise naming how the
    spec it holds differs; ``fresh`` deletes the runs it holds first."""
    path = campaign / SPEC_RECORD
    want = spec_record(spec)
    versions = [__version__]
    if path.exists() and fresh:
        drop_runs(campaign)
        path.unlink()
    elif path.exists():
        had = json.loads(path.read_text())
        if isinstance(had["spec"].get("settle"), dict):     # a rule of fewer fields: theirs
            had["spec"]["settle"] = dict(BEFORE, **had["spec"]["settle"])
        differ = [k for k in sorted(set(had["spec"]) | set(want))
                  if as_numbers(had["spec"].get(k)) != as_numbers(want.get(k))]
        if differ:
            said = "; ".join(f'"{k}" was {had["spec"].get(k)!r}, now {want.get(k)!r}'
                             for k in differ[:3])
            raise ValueError(f"{campaign} holds the runs of another spec ({said}): give "
                             "another directory, or --fresh to delete its runs and start "
                             "afresh")
        versions = sorted(set(had.get("versions", [])) | {__version__})
    elif any(campaign.glob(f"v*/b2_*/seed*/{rundir.OUTCOME}")) and not fresh:
        raise ValueError(f"{campaign} holds runs but no {SPEC_RECORD}, so their spec is "
                         "unknown: give another directory, or --fresh to delete its runs and "
                         "start afresh")
    elif fresh:
        drop_runs(campaign)
    campaign.mkdir(parents=True, exist_ok=True)
    rundir.write_json(path, dict(spec=want, versions=versions))


def retry(todo) -> int:
    """Clear the runs of ``todo`` that failed, so that they run again from the start;
    returns how many."""
    cleared = 0
    for *_, directory in todo:
        if rundir.failed(directory):
            rundir.clear(directory)
            cleared += 1
    return cleared


def run_directory(campaign, v: float, b2: float, seed) -> Path:
    return Path(campaign) / f"v{v:g}" / f"b2_{b2:.4f}" / f"seed{seed}"


def plan(spec: dict, campaign) -> list[tuple[float, float, int, Path]]:
    return [(v, b2, seed, run_directory(campaign, v, b2, seed))
            for seed in spec["seeds"] for v in spec["v_col"] for b2 in spec["b_off2"]]


def left(spec_path, campaign) -> str:
    """What a stopped campaign leaves, in a few lines: the runs finished (and failed), those
    cut off (to be resumed), and how many have not started."""
    runs = [d for *_, d in plan(read_spec(spec_path), campaign)]
    ended = {d: rundir.finished(d) for d in runs}          # each outcome.json read once
    done = [d for d in runs if ended[d]]
    failed = [d for d in done if rundir.failed(d)]
    cut = [d for d in runs if not ended[d] and (d / rundir.LOG).exists()]
    lines = [f"{len(done)} of {len(runs)} runs finished"
             + (f" ({len(failed)} failed)" if failed else "")
             + f", {len(cut)} cut off, {len(runs) - len(done) - len(cut)} not started"]
    lines += [f"  cut off, resumes from its last restart file: {d}" for d in cut]
    return "\n".join(lines)


def scene_of(spec: dict, v: float, b2: float, seed: int) -> Scene:
    """The scene of one run of the grid."""
    auto = spec["dt"] == "auto"
    scene = Scene(material=material(spec["material"], **spec["material_overrides"]),
                  n_tar=spec["n_tar"], n_pro=spec["n_pro"], v_col=v, b_off=float(np.sqrt(b2)),
                  seed=seed, kind=spec["kind"], dim=spec["dim"], radius=spec["radius"],
                  model=spec["model"], dt_over_tc=None if auto else spec["dt"],
                  bond=spec["bond"] or "equilibrium", gap=spec["gap"],
                  dt_reason=None if auto else f"dt = {spec['dt']:g} t_c, the campaign's")
    return scene.with_dt_for(spec["tolerance"]) if auto else scene


def last_step(spec: dict, scene: Scene) -> int:
    """The step a run of ``spec`` ends at the latest: its cap, or its fixed steps."""
    if spec["settle"] is None:
        return spec["steps"]
    return spec["settle"].cap_steps(scene.time_step()[0])


def prepare(directory: Path, spec: dict, scene: Scene, aggregates: dict):
    """Make ``directory`` ready to run (on the group's leader): "ended" if its run ended
    and only its analysis is missing; (restart file, step) to resume from, the outputs
    cut back to that step; or None after writing the scene afresh."""
    ended = (directory / rundir.FINAL_RESTART).exists()
    if ended and (directory / rundir.META).exists():
        status = rundir.run_status(directory)
        if status.problem is None and status.stop_reason != "error":
            return "ended"
    point = rundir.resume_point(directory, last_step(spec, scene))
    if point is not None:
        rundir.cut_back(directory, point[1])
        return point
    rundir.clear(directory)
    if scene.seed not in aggregates:
        aggregates[scene.seed] = scene.aggregates()
    rundir.write(directory, scene, scene.collide(aggregates[scene.seed]))
    return None


#: a campaign shows a run's settle checks at most this often (s): a line a minute for each
#: long run, none for runs of seconds
LINE_EVERY_S = 60.0


def run_one(spec: dict, directory: Path, resume, comm, name: str | None = None) -> str | None:
    """Run one collision on ``comm``, from ``resume`` = (restart file, its step) if given;
    returns None, or the LAMMPS error that ended it. ``name``: show its settle checks
    (at most one a ``LINE_EVERY_S``), each line opening with it."""
    from .session import Session

    restart, start = resume if resume is not None else (None, 0)
    remaining = None
    if resume is not None and spec["settle"] is not None:      # the uninterrupted run's cap
        remaining = dict(steps=last_step(spec, rundir.read(directory)) - start)
    try:
        with Session(directory, directory, every=spec["every"] or 1, comm=comm,
                     settle=spec["settle"], restart=restart, append=resume is not None,
                     variables=remaining, claim=False) as run:
            if spec["settle"] is None:
                run.run(spec["steps"] - start, chunk=spec["every"], progress=False)
            else:
                run.run_until_settled(progress=False, lines=None if name is None else
                                      dict(prefix=f"{name}: ", every_s=LINE_EVERY_S,
                                           bar=False))
            run.finish()
    except Exception as err:            # a LAMMPS error: recorded, the campaign goes on
        return str(err).strip().splitlines()[0]
    return None


def finish(directory: Path, failed: str | None) -> str:
    """Write the run's outcome.json, its analysis or its failure; returns a summary line."""
    from jkrdt.analysis.run import analyse_run    # here: MDAnalysis slows every jkrdt start

    if failed is None:
        try:
            out = analyse_run(directory)
            return (f"{out['stop_reason']} at step {out['stop_step']}, N_lar {out['n_largest']}, "
                    f"f_gro {out['growth_efficiency']:+.3f}")
        except ValueError as err:        # the run's outputs do not add up: recorded
            failed = f"analysis: {err}"
    rundir.record_failure(directory, failed)
    return f"FAILED: {failed} (jkrdt campaign ... --retry-failed runs it again)"


def run_campaign(spec_path, campaign, progress: bool = True, ranks_per_run: int = 1,
                 comm=None, fresh: bool = False, retry_failed: bool = False) -> dict:
    """Run every unfinished run of the campaign (see the module text); returns the number
    of runs, those finished before it started ("skipped"), those it ran ("ran") and the
    runs that failed ("failed": none when every run of the grid is complete).
    Under MPI the ranks of ``comm`` (default COMM_WORLD) run in groups of
    ``ranks_per_run``; every rank returns the same counts."""
    from mpi4py import MPI

    world = comm if comm is not None else MPI.COMM_WORLD
    spec = read_spec(spec_path)
    if not (isinstance(ranks_per_run, int) and 1 <= ranks_per_run <= world.size
            and world.size % ranks_per_run == 0):
        raise ValueError(f"--ranks-per-run {ranks_per_run} must divide the {world.size} "
                         "MPI rank(s) into equal groups")
    group = world.Split(color=world.rank // ranks_per_run, key=world.rank)
    leader = group.rank == 0
    campaign = Path(campaign)
    todo = plan(spec, campaign)
    refused = None
    if world.rank == 0:
        try:
            own(campaign, spec, fresh)
            if retry_failed:
                retry(todo)
        except ValueError as err:
            refused = str(err)
    refused = world.bcast(refused)
    if refused is not None:
        raise ValueError(refused)
    skipped = sum(rundir.finished(d) for *_, d in todo)
    world.Barrier()              # every rank has counted before any run finishes
    aggregates, ran = {}, 0
    for v, b2, seed, directory in todo:
        held = None
        if leader and not rundir.finished(directory):
            held = rundir.claim(directory)
        if not group.bcast(held is not None):
            continue
        t0 = time.time()
        resume = prepare(directory, spec, scene_of(spec, v, b2, seed), aggregates) if leader \
            else None
        resume = group.bcast(resume)
        name = f"[ranks {world.rank}-{world.rank + group.size - 1}] v {v:g} B_off^2 {b2:g} " \
               f"seed {seed}"
        failed = None if resume == "ended" else run_one(spec, directory, resume, group,
                                                        name if progress else None)
        if leader:
            said = finish(directory, failed)
            held.close()
            ran += 1
            how = ("" if resume is None else " (its run had ended; analysed)"
                   if resume == "ended" else f" (resumed at step {resume[1]})")
            if progress:
                print(f"{name}{how}: {said}, {time.time() - t0:.1f} s", flush=True)
        group.Barrier()
    group.Free()
    ran = world.allreduce(ran if leader else 0)
    failed = [str(d) for *_, d in todo if rundir.failed(d)]
    return dict(runs=len(todo), skipped=skipped, ran=ran, failed=failed)
