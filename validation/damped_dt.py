"""Does ``--dt auto`` leave the damped models' outcomes unchanged? An ensemble at two steps.

``validation/vfra_size.py`` runs every collision at the dt that ``jkrdt setup --dt auto``
chooses for max |dE| / E_imp <= 1e-3, and the smaller sizes of ``bpca3d_models`` ran at
dt = 0.014 t_c. The trade study (benchmarks/tradeoff) showed the outcomes unchanged up to
0.2 t_c for the undamped models only; with eq. (A.5)'s damping a contact has a time scale
of its own, and --dt auto takes about twice 0.014 t_c at 63.1 m/s. Before the damped
models' v_fra at 2 x 5000 is read against 2 x 1000 this study asks whether dt alone moves
it: both damped models at 2 x 1000 grains, 63.1 m/s, the two offsets whose f_gro decides
<f_gro> there (B_off^2 = 3/12, 6/12), 6 seeds (FULL), once at dt = 0.014 t_c and once at
--dt auto (1e-3). Collisions are chaotic, so the two are compared as ensembles: per model
and offset, the means of f_gro and N_lar / N with their standard errors, and the
difference against twice its standard error.

Writes RESULTS (default validation/damped_dt/): runs.csv and summary.json.

    ./run validate damped_dt               # 2 models x 2 offsets x 6 seeds x 2 dt, 2 ranks
    ./run validate damped_dt --quick       # 2 x 24 grains, 3 seeds (tests)
"""

from __future__ import annotations

import sys

from bpca3d_models import DT, model_spec
from common import (campaign_paths, campaign_study_parser, mean_se, run_campaigns,
                    study_paths, within_scatter, write_summary)
from jkrdt.analysis.tables import write_csv
from jkrdt.stopping import COMPLETE
from vfra_size import TOLERANCE, model_home, outcome_rows

FULL = dict(n=1000, v_col=63.1, b_off2=[0.25, 0.5], seeds=[1, 2, 3, 4, 5, 6],
            models=["frictionless, T_vis 6 ps", "frictional, T_vis 6 ps"])
QUICK = dict(n=24, v_col=63.1, b_off2=[0.25], seeds=[1, 2, 3],
             models=["frictionless, T_vis 6 ps"])
STEPS = {"dt 0.014": dict(dt=DT), "dt auto": dict(dt="auto", tolerance=TOLERANCE)}


def spec(plan: dict, model: str, step: dict) -> dict:
    return model_spec(model, plan["n"], v_col=[plan["v_col"]], b_off2=plan["b_off2"],
                      seeds=plan["seeds"], **step)


def compare(rows: list[dict], model: str, b2: float) -> dict:
    """f_gro and N_lar / N of one model and offset at both steps, and whether they agree
    (``common.within_scatter``)."""
    out = {}
    for measure, value in (("f_gro", lambda r: r["growth_efficiency"]),
                           ("N_lar_over_N", lambda r: r["n_largest"] / r["n_total"])):
        at = {name: mean_se([value(r) for r in rows if r["model"] == model
                             and r["step"] == name and abs(r["B_off"] ** 2 - b2) < 1e-9])
              for name in STEPS}
        difference, se, agree = within_scatter(at["dt 0.014"], at["dt auto"])
        out[measure] = dict(at_0014=list(at["dt 0.014"]), at_auto=list(at["dt auto"]),
                            difference=difference, se=se, agree=agree)
    return out


def main(argv=None) -> int:
    p = campaign_study_parser(__doc__)
    p.add_argument("--models", nargs="+", default=None, metavar="MODEL",
                   help="run only these models (default: both); the summary takes every "
                        "finished run below RUNS")
    args = p.parse_args(argv)
    plan = QUICK if args.quick else FULL
    unknown = sorted(set(args.models or []) - set(plan["models"]))
    if unknown:
        p.error(f"unknown model {unknown[0]!r}: give one of {plan['models']}")
    runs, results = study_paths(args, "damped_dt")
    for model in args.models or plan["models"]:
        run_campaigns({name: spec(plan, model, step) for name, step in STEPS.items()},
                      model_home(runs, plan["n"], model), args.np)
    rows = []
    for model in plan["models"]:
        for name, where in campaign_paths(STEPS, model_home(runs, plan["n"], model)).items():
            rows += [dict(r, step=name) for r in outcome_rows(where, plan["n"], model)
                     if r["stop_reason"] in COMPLETE]
    write_csv(results / "runs.csv", rows)
    # a model is compared once each step has two runs or more at each offset
    done = [m for m in plan["models"] if all(
        sum(r["model"] == m and r["step"] == name and abs(r["B_off"] ** 2 - b2) < 1e-9
            for r in rows) >= 2 for name in STEPS for b2 in plan["b_off2"])]
    summary = dict(plan=plan, steps=STEPS, results={
        model: {f"{b2:.4f}": compare(rows, model, b2) for b2 in plan["b_off2"]}
        for model in done},
        runs={model: {name: sum(r["model"] == model and r["step"] == name for r in rows)
                      for name in STEPS} for model in done},
        loop_minutes={model: {name: sum(r["loop_seconds"] for r in rows if r["model"] == model
                                        and r["step"] == name) / 60 for name in STEPS}
                      for model in done},
        dt_auto_over_tc=sorted({r["dt_over_tc"] for r in rows if r["step"] == "dt auto"}),
        energy_error_max={name: max((r["energy_error"] for r in rows if r["step"] == name),
                                    default=None) for name in STEPS},
        runs_finished=len(rows))
    return write_summary(results, summary)


if __name__ == "__main__":
    sys.exit(main())
