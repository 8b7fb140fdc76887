"""Collision campaigns: a grid of v_col x B_off^2 x seeds, one run directory each,
resumable.

A spec (JSON) names the grid and the scene:

    {"kind": "bpca", "dim": 3, "n_tar": 128, "n_pro": 128, "material": "ice",
     "material_overrides": {"tvis": 6e-12}, "radius": 1e-7, "model": "frictional",
     "v_col": [10, 20, 40], "b_off2": [0, 0.25, 0.5, 0.75], "seeds": [1],
     "steps": 20000, "dt": 0.014, "every": 1000}

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

BUILDERS = {"bpca": bpca, "bcca": bcca}
DEFAULTS = dict(kind="bpca", dim=3, material="ice", material_overrides={}, radius=1.0e-7,
                model="frictional", seeds=[1], dt=0.014, every=1000)
REQUIRED = ["n_tar", "n_pro", "v_col", "b_off2", "steps"]


def read_spec(path) -> dict:
    given = json.loads(Path(path).read_text())
    unknown = sorted(set(given) - set(DEFAULTS) - set(REQUIRED))
    if unknown:
        raise ValueError(f"{path}: unknown keys {unknown}; known: "
                         f"{sorted(set(DEFAULTS) | set(REQUIRED))}")
    spec = dict(DEFAULTS, **given)
    missing = [k for k in REQUIRED if k not in spec]
    if missing:
        raise ValueError(f"{path}: the campaign spec lacks {missing}")
    if any(not 0 <= b <= 1 for b in spec["b_off2"]):
        raise ValueError(f"{path}: b_off2 values are B_off^2 and must lie in [0, 1]")
    if spec["steps"] % spec["every"]:
        raise ValueError(f"{path}: steps must be a multiple of every, so that the last "
                         "frame is the end of the run")
    return spec


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
        with Session(directory, directory, dt=spec["dt"], every=spec["every"], comm=comm) as run:
            run.run(spec["steps"], chunk=spec["every"], progress=False)
            run.write_restart()
        if comm.rank == 0:
            analyse_run(directory)
        comm.Barrier()
    bar.close()
    return dict(runs=len(todo), skipped=skipped, ran=len(todo) - skipped)
