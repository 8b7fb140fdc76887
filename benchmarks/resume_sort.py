"""A resumed run is the run at the paper's size, and what sorting at the restart steps costs
(issue 48).

Part 1, exact at 2 x 50000: the paper's scene (frictionless ice BPCAs, 39.8 m/s, B_off^2
1/12, seed 1) run on 2 and on 4 ranks (the deck's fix balance rcb on) by
``tests/resume_exact.py`` for CHUNKS x EVERY steps with a
restart file every EVERY steps, then continued from each restart point but the last to the
same end: the largest difference of any grain's position, velocity or spin against the
uninterrupted run, with the deck's sort at the restart steps (its default) and with
LAMMPS's every 1000 steps (the deck's default before issue 48).

Part 3, what putting the atoms in ID order costs (the plugin's pass at a run's set-up and
at each restart step, ``plugin/jkr_dt_order.h``): the 2 x 25000 scene run by ``jkrdt run
--np 2`` for ``--order-tc`` t_c, the deck's closing line (the contact store's count of
the passes and their wall time on rank 0) against LAMMPS's loop time, in the same run.

Part 2, the cost at 2 x 25000: the same kind of scene run side by side, one check interval
(50 t_c) at a time in turns (A B A B, ``side_by_side.alternate``), sorting every 1000 steps
against sorting at the checks (every 50 t_c, about 2000 steps); us per atom-step per chunk
and their ratio, with the load average.

    python benchmarks/resume_sort.py                 # both parts, a few minutes on 2 cores
    python benchmarks/resume_sort.py --part 2 --until-tc 500
    python benchmarks/resume_sort.py --part 3                # about a minute

Writes JSON (default benchmarks/resume/resume_sort.json).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from side_by_side import alternate

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BIN = Path(sys.executable).parent
# ranks that sleep while they wait: more ranks than cores would otherwise poll (bench_scale)
SLEEPING_RANKS = dict(MPIR_CVAR_CH4_PROGRESS_THROTTLE="true",
                      MPIR_CVAR_CH4_PROGRESS_THROTTLE_NO_PROGRESS_COUNT="1")


def scene_at(where: Path, n: int, b_off2: float) -> Path:
    from jkrdt import rundir
    from jkrdt.materials import ICE
    from jkrdt.scene import Scene

    t0 = time.time()
    scene = Scene(ICE, n, n, v_col=39.8, b_off=float(np.sqrt(b_off2)), seed=1,
                  model="frictionless").with_dt_for(1e-3)
    rundir.write(where, scene)
    print(f"2 x {n}: set up in {time.time() - t0:.0f} s", flush=True)
    return where


def exact(scene: Path, work: Path, every: int, chunks: int, ranks: int, **variables) -> dict:
    out = work / ("_".join(f"{k}{v}" for k, v in variables.items()) or "default")
    out.mkdir(parents=True)
    t0 = time.time()
    subprocess.run([str(BIN / "mpirun"), "-np", str(ranks), sys.executable,
                    str(ROOT / "tests" / "resume_exact.py"), str(scene), str(out), str(every),
                    str(chunks), *(f"{k}={v}" for k, v in variables.items())],
                   check=True, capture_output=True, env=dict(os.environ, **SLEEPING_RANKS))
    ends = dict(np.load(out / "ends.npz"))
    straight = ends.pop("straight")
    return dict(variables=variables, wall_s=time.time() - t0,
                max_difference={name: float(np.abs(end - straight).max())
                                for name, end in ends.items()},
                bit_for_bit=all(np.array_equal(end, straight) for end in ends.values()))


def order_cost(scene: Path, until_tc: float) -> dict:
    """Part 3: the ordering pass's wall time against the loop's, in one run on 2 ranks."""
    import re

    load = os.getloadavg()[0]
    subprocess.run([str(BIN / "jkrdt"), "run", str(scene), "--np", "2", "--cap",
                    str(until_tc), "--quiet"], check=True, capture_output=True)
    log = (scene / "log.lammps").read_text()
    steps, seconds = re.search(r"atoms put in ID order at (\d+) steps in (\S+) s", log).groups()
    loop = float(re.findall(r"Loop time of (\S+) on 2 procs", log)[-1])
    meta = json.loads((scene / "collision.json").read_text())
    return dict(n_total=meta["N_tar"] + meta["N_pro"], until_tc=until_tc, ranks=2,
                order_steps=int(steps), order_seconds=float(seconds), loop_seconds=loop,
                order_share_of_loop=float(seconds) / loop,
                load_average=[load, os.getloadavg()[0]])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--part", type=int, choices=(1, 2, 3), default=None)
    ap.add_argument("--order-tc", type=float, default=400.0, help="part 3's run, t_c")
    ap.add_argument("--n", type=int, default=50000, help="grains per aggregate, part 1")
    ap.add_argument("--every", type=int, default=200)
    ap.add_argument("--chunks", type=int, default=3)
    ap.add_argument("--ranks", type=int, nargs="+", default=[2, 4], help="part 1")
    ap.add_argument("--n-cost", type=int, default=25000, help="grains per aggregate, part 2")
    ap.add_argument("--until-tc", type=float, default=1000.0)
    ap.add_argument("--out", type=Path, default=HERE / "resume" / "resume_sort.json")
    args = ap.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="resume_sort_"))
    result = json.loads(args.out.read_text()) if args.out.exists() else {}
    if args.part in (None, 1):
        scene = scene_at(work / "exact_scene", args.n, 1 / 12)
        result["exact"] = dict(n_total=2 * args.n, every=args.every, chunks=args.chunks,
                               runs=[dict(ranks=r, **exact(scene, work / f"np{r}", args.every,
                                                           args.chunks, r, **variables))
                                     for r in args.ranks
                                     for variables in ({}, dict(sort=1000))])
        print(json.dumps(result["exact"], indent=1), flush=True)
    if args.part in (None, 2):
        scene = scene_at(work / "cost_scene", args.n_cost, 1 / 12)
        variants = {"sort every 1000 steps": dict(sort="1000"),
                    "sort at the checks": {}}
        ran = alternate(scene, variants, args.until_tc, float("inf"))
        costs = {d: [r["us_per_atom_step"] for r in rows] for d, rows in ran["series"].items()}
        k = min(len(c) for c in costs.values())
        a, b = (np.array(costs[d][:k]) for d in variants)
        result["cost"] = dict(n_total=2 * args.n_cost, until_tc=args.until_tc,
                              load_average=ran["load_average"], summary=ran["summary"],
                              ratio_at_checks_over_1000=dict(
                                  median=float(np.median(b / a)),
                                  mean_total=float(b.sum() / a.sum())),
                              series=ran["series"])
        print(json.dumps(result["cost"]["ratio_at_checks_over_1000"]), flush=True)
    if args.part in (None, 3):
        result["order"] = order_cost(scene_at(work / "order_scene", args.n_cost, 1 / 12),
                                     args.order_tc)
        print(json.dumps(result["order"]), flush=True)
    result["cpu_count"] = os.cpu_count()
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1) + "\n")


if __name__ == "__main__":
    main()
