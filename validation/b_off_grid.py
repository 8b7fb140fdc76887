"""Does the grid of offsets move <f_gro>? The paper's B_off^2 step of 1/12 against four.

The 3D BPCA paper ran B_off^2 from 0 to 1 in steps of 1/12 (its Appendix B, Fig. B.1) and
averaged f_gro over them by eq. (1), <A> = integral of A d(B_off^2). This project's
studies run B_off^2 = 0, 3/12, 6/12, 9/12 and average by ``b_off_average`` (the trapezoid
rule in B_off^2, the last value held to 1), which gives the head-on collision a weight of
1/8 where the paper's step gives it 1/24. Where f_gro falls from about 1 head-on to below
0 within a few twelfths, that weight can decide the sign of <f_gro>: the damped frictional
model at 2 x 5000 grains and 100 m/s has f_gro 0.97 head-on and -0.16, -0.07, -0.02 at
the other three offsets (``vfra_size``), so +0.12 of its <f_gro> of +0.06 is the head-on
run's. This study runs one collision per twelfth, B_off^2 = k/12, k = 0 ... 12, one seed
(the same two aggregates at every offset), and reads <f_gro> twice from the same runs:
over all 13 offsets, and over the four that the other studies use. At 15.8 m/s, far below
v_fra, the frictional models' four offsets all stick at 2 x 1000 (<f_gro> +1.00 undamped,
where the paper has 0.8-0.9): only offsets beyond 9/12 can tell the two averages apart
there; at 63.1 m/s the damped frictional model's <f_gro> is +0.035 at 2 x 1000 (paper's
v_fra 50 m/s).

Writes RESULTS (default validation/b_off_grid/): runs.csv, summary.json and fig_b_off_grid
(f_gro against B_off^2 per model and speed, with both averages).

    ./run validate b_off_grid                 # 2 models x 2 speeds x 13 offsets, 2 x 1000
    ./run validate b_off_grid --quick         # 2 x 24 grains, 7 offsets (tests)
"""

from __future__ import annotations

import sys
from pathlib import Path

from bpca3d_models import model_spec
from common import (campaign_paths, campaign_study_parser, run_campaigns, save, study_paths,
                    write_summary)
from jkrdt.analysis.summary import b_off_average, b_off_groups
from jkrdt.analysis.tables import write_csv
from jkrdt.stopping import COMPLETE
from vfra_size import SMALLER_PLAN, TOLERANCE, model_home, outcome_rows

#: the paper's offsets (Appendix B) and the four of the other studies (bpca3d_models)
TWELFTHS = [k / 12 for k in range(13)]
FOUR = SMALLER_PLAN["b_off2"]
FULL = dict(n=1000, v_col=[15.8, 63.1], b_off2=TWELFTHS, seeds=[1],
            models=["frictional, T_vis 6 ps", "frictional"])
QUICK = dict(n=24, v_col=[15.8], b_off2=[k / 12 for k in (0, 1, 2, 3, 6, 9, 12)], seeds=[1],
             models=["frictional"])


def spec(plan: dict, model: str, v_col: float) -> dict:
    return model_spec(model, plan["n"], v_col=[v_col], b_off2=plan["b_off2"],
                      seeds=plan["seeds"], dt="auto", tolerance=TOLERANCE)


def one_of_four(b_off2: float) -> bool:
    """Whether ``b_off2`` is one of the four offsets of the other studies."""
    return any(abs(b_off2 - x) < 1e-6 for x in FOUR)


def growth(run: dict) -> float:
    """f_gro of one run, the value eq. (1) averages here."""
    return run["growth_efficiency"]


def averages(rows: list[dict]) -> dict:
    """f_gro per B_off^2 (seeds averaged, ``b_off_groups``) of one model and speed, and
    <f_gro> of eq. (1) (``b_off_average`` of those) over every offset run and over the four
    of the other studies alone."""
    b2, f_gro = b_off_groups(rows, growth)
    b2_four, f_gro_four = b_off_groups([r for r in rows if one_of_four(r["B_off"] ** 2)],
                                       growth)
    return dict(b_off2=b2.tolist(), f_gro=f_gro.tolist(),
                mean_f_gro_all=float(b_off_average(b2, f_gro)),
                mean_f_gro_four=(float(b_off_average(b2_four, f_gro_four))
                                 if len(b2_four) == len(FOUR) else None))


def figure(results_by: dict, results: Path) -> list[Path]:
    """fig_b_off_grid: f_gro against B_off^2, a panel per model, a line per speed, with the
    two averages of eq. (1) in the legend and the four offsets of the other studies marked."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    models = sorted({m for m, _ in results_by})
    fig, axes = plt.subplots(1, len(models), figsize=(5.5 * len(models), 4.2), squeeze=False,
                             sharey=True, constrained_layout=True)
    for ax, model in zip(axes[0], models):
        for k, ((m, v), a) in enumerate(sorted(results_by.items())):
            if m != model:
                continue
            four = a["mean_f_gro_four"]
            label = (f"{v:g} m/s: <f_gro> {a['mean_f_gro_all']:+.3f} (every 1/12)"
                     + (f", {four:+.3f} (the four)" if four is not None else ""))
            ax.plot(a["b_off2"], a["f_gro"], "o-", color=f"C{k}", ms=4, label=label)
            at = [j for j, b in enumerate(a["b_off2"]) if one_of_four(b)]
            ax.plot([a["b_off2"][j] for j in at], [a["f_gro"][j] for j in at], "s", ms=9,
                    mfc="none", color=f"C{k}")
        ax.axhline(0, color="0.7", lw=0.8)
        ax.set_xticks([k / 12 for k in range(0, 13, 3)], ["0", "3/12", "6/12", "9/12", "1"])
        ax.set_xlabel("B_off^2 (squares: the four offsets of the other studies)")
        ax.set_title(model, fontsize=9)
        ax.legend(fontsize=7)
    axes[0][0].set_ylabel("f_gro = (N_lar - N_tar) / N_pro")
    fig.suptitle("Ice BPCAs, one seed: f_gro at every twelfth of B_off^2 (the paper's "
                 "Appendix B grid)", fontsize=10)
    return save(fig, results, "fig_b_off_grid")


def main(argv=None) -> int:
    args = campaign_study_parser(__doc__).parse_args(argv)
    plan = QUICK if args.quick else FULL
    runs, results = study_paths(args, "b_off_grid")
    rows = []
    # one campaign per model and speed (RUNS/n<N>/<model>/twelfths_v<speed>), the slower
    # speeds first
    for v in sorted(plan["v_col"]):
        for model in plan["models"]:
            home = model_home(runs, plan["n"], model)
            specs = {f"twelfths_v{v:g}": spec(plan, model, v)}
            run_campaigns(specs, home, args.np)
            rows += [r for where in campaign_paths(specs, home).values()
                     for r in outcome_rows(where, plan["n"], model)
                     if r["stop_reason"] in COMPLETE]
    write_csv(results / "runs.csv", rows)
    results_by = {(m, v): averages([r for r in rows if r["model"] == m and r["v_col"] == v])
                  for m in plan["models"] for v in plan["v_col"]
                  if any(r["model"] == m and r["v_col"] == v for r in rows)}
    figure(results_by, results)
    summary = dict(plan=plan, tolerance=TOLERANCE,
                   results={f"{m} at {v:g} m/s": a for (m, v), a in results_by.items()},
                   runs_finished=len(rows),
                   loop_minutes=sum(r["loop_seconds"] for r in rows) / 60,
                   energy_error_max=max((r["energy_error"] for r in rows), default=None))
    return write_summary(results, summary)


if __name__ == "__main__":
    sys.exit(main())
