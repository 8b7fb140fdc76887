"""The 3D BPCA paper's four models at ten times the size: v_fra against N.

``validation/bpca3d_models.py`` placed each model's fragmentation threshold v_fra at
2 x 100, 2 x 250 and 2 x 1000 ice grains (its committed summary.json). This study adds
larger sizes (default 2 x 5000) on a grid of the paper's speeds, 10^(1 + 0.1 k) m/s, that
brackets each model's v_fra as the smaller sizes place it (GRIDS), at B_off^2 = 0, 3/12,
6/12, 9/12:

  phase 1   seed 1 at every speed of the model's grid;
  phase 2   seed 2 at the two speeds of the grid on either side of phase 1's v_fra.

Each model's phases are campaigns of their own (``RUNS/n<N>/<model>/seed<k>``), run one
after the other, damped models first (their gap to the paper is the open question), and
a second call resumes them. Every run ends by the settle rule, its dt chosen by
``--dt auto`` for max |dE| / E_imp <= 1e-3 (TOLERANCE): the trade study
(benchmarks/tradeoff) found no outcome moving beyond its scatter up to 0.2 t_c, where the
worst run's error was 6.5e-3.

Writes RESULTS (default validation/vfra_size/): runs.csv (every run, with its loop time)
and summary.json (per size and model: <f_gro> against v_col, v_fra with its bracket, the
compute spent).

    ./run validate vfra_size                    # 2 x 5000, 2 ranks: 100 runs, hours of both cores
    ./run validate vfra_size --sizes 10000
    ./run validate vfra_size --quick            # 2 x 24 grains, two models (tests)
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from bpca3d_models import MODELS
from common import campaign_study_parser, loop_seconds, run_campaigns, study_paths
from jkrdt import rundir
from jkrdt.analysis.summary import b_off_average, summarise, threshold_velocity
from jkrdt.analysis.tables import write_csv

#: max |dE| / E_imp that each run's dt is chosen for
TOLERANCE = 1e-3
B_OFF2 = [0.0, 0.25, 0.5, 0.75]
#: each model's speeds (the paper's grid) around its v_fra at 2 x 1000 grains (frictional
#: 54, damped frictional 82, frictionless 22, damped frictionless above 100 m/s) and the
#: paper's at 10^5 (60, 50, 30, 45), in the order the models are run
GRIDS = {"frictionless, T_vis 6 ps": [50.1, 63.1, 79.4, 100.0, 125.9],
         "frictional, T_vis 6 ps": [50.1, 63.1, 79.4, 100.0],
         "frictional": [39.8, 50.1, 63.1, 79.4],
         "frictionless": [15.8, 20.0, 25.1, 31.6]}
QUICK = dict(sizes=[24], grids={"frictional": [10.0, 39.8, 100.0],
                                "frictionless": [10.0, 39.8, 100.0]}, b_off2=[0.0, 0.5])
FULL = dict(sizes=[5000], grids=GRIDS, b_off2=B_OFF2)
SEEDS = (1, 2)              # phase 1, phase 2


def spec(model: str, n: int, speeds: list[float], b_off2: list[float], seed: int) -> dict:
    kind, tvis, _ = MODELS[model]
    return dict(kind="bpca", dim=3, n_tar=n, n_pro=n, material="ice",
                material_overrides=dict(tvis=tvis), model=kind, v_col=speeds, b_off2=b_off2,
                seeds=[seed], dt="auto", tolerance=TOLERANCE)


def nearest_two(c: dict) -> list[float]:
    """The two speeds of curve ``c`` nearest its v_fra: the grid speeds on either side of
    it (the two slowest if the model fragments at every speed of the grid, the two fastest
    if at none)."""
    if c["bracket"] is not None:
        return c["bracket"]
    v, f = c["v_col"], c["mean_f_gro"]
    return v[:2] if f[0] <= 0 else v[-2:]


def curve(where: Path) -> dict:
    """<f_gro>(v_col) and v_fra of the runs below ``where`` (``jkrdt summarise``: the seeds
    averaged per B_off^2, then the B_off-weighted average), with v_fra's bracket."""
    summary = summarise(where, plot=False)
    table = sorted(summary["table"], key=lambda r: r["v_col"])
    v = [r["v_col"] for r in table]
    f = [r["mean_f_gro"] for r in table]
    v_fra = threshold_velocity(v, f)
    bracket = next(([v[k], v[k + 1]] for k in range(len(v) - 1) if f[k] > 0 >= f[k + 1]),
                   None)
    return dict(v_col=v, mean_f_gro=f, runs=[r["runs"] for r in table], v_fra=v_fra,
                bracket=bracket)


def seed_spread(rows: list[dict]) -> list[float]:
    """v_fra of each seed's own curve, at the speeds that seed ran (the spread of v_fra
    from the seeds)."""
    out = []
    for seed in sorted({r["seed"] for r in rows}):
        mine = [r for r in rows if r["seed"] == seed]
        ran = sorted({r["v_col"] for r in mine})
        if len(ran) < 2:
            continue
        f = []
        for v in ran:
            at = [r for r in mine if r["v_col"] == v]
            f.append(b_weighted([(round(r["B_off"] ** 2, 12), r["growth_efficiency"])
                                 for r in at]))
        found = threshold_velocity(ran, f)
        if found is not None:
            out.append(found)
    return out


def b_weighted(points: list[tuple[float, float]]) -> float:
    """The B_off-weighted average of (B_off^2, value) points, the seeds of one B_off^2
    averaged first (eq. 1 of the 3D paper, ``summary.b_off_average``)."""
    b2 = sorted({p[0] for p in points})
    return float(b_off_average(b2, np.array([np.mean([x for b, x in points if b == c])
                                             for c in b2])))


def run_model(model: str, n: int, plan: dict, runs: Path, ranks: int) -> Path:
    """Both phases of one model at 2 x ``n`` grains; returns the model's directory."""
    grid = plan["grids"][model]
    home = runs / f"n{n}" / model.replace(", ", "_").replace(" ", "_")
    run_campaigns({f"seed{SEEDS[0]}": spec(model, n, grid, plan["b_off2"], SEEDS[0])},
                  home, ranks)
    second = nearest_two(curve(home / f"seed{SEEDS[0]}"))
    run_campaigns({f"seed{SEEDS[1]}": spec(model, n, second, plan["b_off2"], SEEDS[1])},
                  home, ranks)
    return home


def main(argv=None) -> int:
    p = campaign_study_parser(__doc__)
    p.add_argument("--sizes", type=int, nargs="+", default=None,
                   help="grains per aggregate (default: 5000)")
    args = p.parse_args(argv)
    plan = dict(QUICK if args.quick else FULL)
    if args.sizes:
        plan["sizes"] = args.sizes
    runs, results = study_paths(args, "vfra_size")
    t0 = time.time()
    rows, sizes = [], {}
    for n in plan["sizes"]:
        sizes[str(n)] = {}
        for model in plan["grids"]:
            home = run_model(model, n, plan, runs, args.np)
            outcomes = [json.loads(o.read_text()) for o in sorted(home.rglob(rundir.OUTCOME))]
            mine = [dict(size=n, model=model, loop_seconds=loop_seconds(Path(o["run"])),
                         **{k: o.get(k) for k in (
                             "v_col", "B_off", "seed", "n_total", "n_largest", "n_fragments",
                             "growth_efficiency", "stop_reason", "stop_step",
                             "time_end_over_tc", "energy_error", "kinetic_left")})
                    for o in outcomes]
            rows += mine
            c = curve(home)
            c.update(seeds_v_fra=seed_spread(mine),
                     seed_2_at=nearest_two(curve(home / f"seed{SEEDS[0]}")),
                     paper_v_fra=MODELS[model][2],
                     stop_reasons={k: sum(r["stop_reason"] == k for r in mine)
                                   for k in sorted({r["stop_reason"] for r in mine})},
                     energy_error_max=max(r["energy_error"] for r in mine),
                     core_hours=sum(r["loop_seconds"] for r in mine) / 3600)
            sizes[str(n)][model] = c
            write_csv(results / "runs.csv", rows)          # as each model finishes
    summary = dict(plan=plan, tolerance=TOLERANCE, ranks=args.np,
                   seconds_this_call=time.time() - t0, load=os.getloadavg()[0], sizes=sizes)
    (results / "summary.json").write_text(json.dumps(summary, indent=2, default=float) + "\n")
    print(json.dumps(sizes, indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
