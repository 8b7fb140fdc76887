"""The 3D BPCA paper at reduced N: the four particle-interaction models.

Two equal BPCAs of ice (0.1 micron, xi_crit = 8 Angstrom) collide at v_col on the paper's
logarithmic grid and B_off^2 in {0, 3/12, 6/12, 9/12} (the paper's Fig. 1 offsets), under
the four models of the paper: frictional (Wada et al. 2007) and frictionless, each with
T_vis = 0 and 6 ps (eq. A.5). Every run ends by the settle rule at dt = 0.014 t_c; runs
that hit the cap are counted and left out of the averages (as ``jkrdt summarise`` does).

Measured against the paper (its 10^5-grain values in brackets):

* <f_gro> against v_col per model (Fig. 2) and v_fra, where <f_gro> = 0 (frictional 60,
  frictional with damping 50, frictionless 30, frictionless with damping 45 m/s); the
  ordering: the frictionless model without damping lowest, the two frictional models
  close together;
* <N_cum(<= N)> at 20 and 39.8 m/s (Fig. 3): the frictionless model without damping makes
  orders of magnitude more small fragments;
* how v_fra moves between the sizes run (the committed results: 2 x 100 and 2 x 250 on the
  full grid with 2 seeds, 2 x 1000 on the grid around v_fra with 1 seed).

Writes ``RESULTS`` (default validation/bpca3d_models/): runs.csv, summary.json and the
figures fig2_growth and fig3_cumulative (PNG, PDF). Runs go to ``--runs`` (default
validation/runs/bpca3d_models, not committed); a second call resumes them.

    ./run validate bpca3d_models [--sizes 100 250]   # the study
    ./run validate bpca3d_models --sizes 100 250 1000 --large-seeds 1 2   # and 2 x 1000
    ./run validate bpca3d_models --quick             # 2 x 24 grains, 3 speeds (tests)
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from common import campaign_study_parser, run_campaigns, save, study_paths
from jkrdt.analysis.summary import b_off_mean, cumulative_on, summarise, threshold_velocity
from jkrdt.analysis.tables import write_csv
from jkrdt import rundir

#: the paper's four models: (model, T_vis) and its v_fra at 10^5 grains, m/s
MODELS = {"frictional": ("frictional", 0.0, 60.0),
          "frictional, T_vis 6 ps": ("frictional", 6e-12, 50.0),
          "frictionless": ("frictionless", 0.0, 30.0),
          "frictionless, T_vis 6 ps": ("frictionless", 6e-12, 45.0)}
#: the paper's grid is 10^(1 + 0.1 k) m/s; 20 and 39.8 m/s are its Fig. 3 speeds
FULL = dict(sizes=[100, 250], seeds=[1, 2], b_off2=[0.0, 0.25, 0.5, 0.75],
            v_col=[10.0, 15.8, 20.0, 25.1, 39.8, 63.1, 100.0])
QUICK = dict(sizes=[24], seeds=[1], b_off2=[0.0, 0.5], v_col=[10.0, 39.8, 100.0])
#: from this size on, the grid around the v_fra the smaller sizes found (15.8-100 m/s) and
#: the seeds of --large-seeds: a 2 x 1000 run costs 40 s to 5 min on one core
LARGE, LARGE_V_COL = 1000, [15.8, 20.0, 25.1, 39.8, 63.1, 100.0]
SMALL = (1, 4, 16)          # N of the N_cum(<= N) columns
#: the step of every run of this study (t_c)
DT = 0.014


def grid(n: int, plan: dict) -> dict:
    """The speeds, offsets and seeds run at 2 x ``n`` grains."""
    large = n >= LARGE and "large_seeds" in plan
    return dict(v_col=LARGE_V_COL if large else plan["v_col"], b_off2=plan["b_off2"],
                seeds=plan["large_seeds"] if large else plan["seeds"])


def model_spec(model: str, n: int, **rest) -> dict:
    """The campaign spec of one of the paper's four models for two ice BPCAs of ``n``
    grains; ``rest``: the speeds, offsets, seeds and the step."""
    kind, tvis, _ = MODELS[model]
    return dict(kind="bpca", dim=3, n_tar=n, n_pro=n, material="ice",
                material_overrides=dict(tvis=tvis), model=kind, **rest)


def spec(model: str, n: int, plan: dict) -> dict:
    return model_spec(model, n, **grid(n, plan), dt=DT)


def model_curve(where: Path, n_total: int) -> dict:
    """<f_gro>(v_col), v_fra and <N_cum> of one model's campaign (``jkrdt summarise``)."""
    summary = summarise(where, plot=False)
    table = sorted(summary["table"], key=lambda r: r["v_col"])
    outcomes = [json.loads(p.read_text()) for p in sorted(where.rglob(rundir.OUTCOME))]
    complete = [o for o in outcomes if o.get("stop_reason") in ("settled", "steps")]
    grid = np.arange(1, n_total + 1)
    cumulative = {}
    for v in sorted({o["v_col"] for o in complete}):
        cumulative[v] = b_off_mean([o for o in complete if o["v_col"] == v],
                                   lambda o: cumulative_on(grid, o["fragment_sizes"], o["N_cum"]))
    v_fra = threshold_velocity([r["v_col"] for r in table], [r["mean_f_gro"] for r in table])
    return dict(v_col=[r["v_col"] for r in table], mean_f_gro=[r["mean_f_gro"] for r in table],
                runs=[r["runs"] for r in table], capped=[r["capped"] for r in table],
                v_fra=v_fra, cumulative=cumulative,
                energy_error_max=max(o["energy_error"] for o in complete),
                stop_reasons={k: sum(o.get("stop_reason") == k for o in outcomes)
                              for k in sorted({o.get("stop_reason") for o in outcomes})},
                rows=outcomes)


def compare(curves: dict) -> dict:
    """The paper's statements, checked at each size."""
    out = {}
    for n, by_model in curves.items():
        v_fra = {m: c["v_fra"] for m, c in by_model.items()}
        known = {m: v for m, v in v_fra.items() if v is not None}
        small = {}
        for v in (20.0, 39.8):
            small[v] = {m: float(c["cumulative"][v][SMALL[-1] - 1])
                        for m, c in by_model.items() if v in c["cumulative"]}
        lowest = min(known, key=known.get) if known else None
        fric = [v_fra.get("frictional"), v_fra.get("frictional, T_vis 6 ps")]
        out[n] = dict(
            v_fra=v_fra, paper_v_fra={m: MODELS[m][2] for m in by_model},
            lowest_v_fra=lowest,
            frictionless_lowest=lowest == "frictionless",
            frictional_pair_relative_gap=(abs(fric[0] - fric[1]) / max(fric)
                                          if None not in fric else None),
            grains_in_fragments_of_at_most_16=small,
            energy_error_max=max(c["energy_error_max"] for c in by_model.values()),
            stop_reasons={m: c["stop_reasons"] for m, c in by_model.items()})
    sizes = sorted(curves)
    if len(sizes) > 1:
        out["v_fra_change_with_N"] = {
            m: [curves[n][m]["v_fra"] for n in sizes] for m in MODELS if m in curves[sizes[0]]}
    return out


def figures(curves: dict, results: Path) -> list[Path]:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter, ScalarFormatter

    colours = {"frictional": "0.45", "frictional, T_vis 6 ps": "0.45", "frictionless": "C3",
               "frictionless, T_vis 6 ps": "C3"}
    dashes = {m: "--" if "T_vis" in m else "-" for m in MODELS}
    widths = {n: 1 + k for k, n in enumerate(sorted(curves))}
    saved = []
    fig, ax = plt.subplots(figsize=(10, 5), constrained_layout=True)
    for n, by_model in sorted(curves.items()):
        for m, c in by_model.items():
            ax.semilogx(c["v_col"], c["mean_f_gro"], dashes[m], marker="o", ms=3,
                        color=colours[m], lw=widths[n], label=f"{m}, 2 x {n}"
                        + (f": v_fra {c['v_fra']:.3g} m/s" if c["v_fra"] else ": no v_fra"))
    for m, (_, _, paper) in MODELS.items():
        ax.plot([paper], [0], "v", color=colours[m], ms=9, mfc="none" if "T_vis" in m else
                colours[m], label=f"paper's v_fra, {m} ({paper:g} m/s)")
    ax.axhline(0, color="0.7", lw=0.8)
    ax.set_xticks([10, 20, 40, 60, 100])
    ax.xaxis.set_major_formatter(ScalarFormatter())
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("v_col (m/s)")
    ax.set_ylabel("<f_gro>")
    ax.set_title("3D BPCA paper Fig. 2 at reduced N (ice, B_off^2 0-9/12)", fontsize=9)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))    # off the curves
    saved += save(fig, results, "fig2_growth")
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.5), constrained_layout=True)
    for ax, v in zip(axes, (20.0, 39.8)):
        for n, by_model in sorted(curves.items()):
            for m, c in by_model.items():
                if v in c["cumulative"]:
                    cum = np.asarray(c["cumulative"][v])
                    grid = np.arange(1, len(cum) + 1)
                    ax.loglog(grid, np.where(cum > 0, cum, np.nan), dashes[m],
                              drawstyle="steps-post", color=colours[m], lw=widths[n],
                              label=f"{m}, 2 x {n}")
        ax.set_xlabel("N")
        ax.set_ylabel("<N_cum(<= N)>")
        ax.set_title(f"Fig. 3, v_col = {v:g} m/s", fontsize=9)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside right upper", fontsize=7)    # one, off the curves
    saved += save(fig, results, "fig3_cumulative")
    return saved


def main(argv=None) -> int:
    p = campaign_study_parser(__doc__)
    p.add_argument("--sizes", type=int, nargs="+", default=None,
                   help="grains per aggregate, one campaign set each (default: 100 250)")
    p.add_argument("--large-seeds", type=int, nargs="+", default=[1],
                   help=f"the seeds of sizes from {LARGE} on, run at v_col = "
                   f"{', '.join(f'{v:g}' for v in LARGE_V_COL)} m/s (default: %(default)s)")
    args = p.parse_args(argv)
    plan = dict(QUICK if args.quick else FULL)
    if args.sizes:
        plan["sizes"] = args.sizes
    if not args.quick:
        plan["large_seeds"] = args.large_seeds
    runs, results = study_paths(args, "bpca3d_models")
    t0 = time.time()
    curves = {}
    for n in plan["sizes"]:
        where = run_campaigns({m: spec(m, n, plan) for m in MODELS}, runs / f"n{n}", args.np)
        curves[n] = {m: model_curve(where[m], 2 * n) for m in MODELS}
    rows = [dict(size=n, model=m, **{k: o.get(k) for k in (
        "v_col", "B_off", "seed", "n_total", "n_largest", "n_fragments", "growth_efficiency",
        "stop_reason", "stop_step", "energy_error", "kinetic_left")})
        for n, by_model in curves.items() for m, c in by_model.items() for o in c["rows"]]
    write_csv(results / "runs.csv", rows)
    summary = dict(plan=plan, grids={str(n): grid(n, plan) for n in plan["sizes"]},
                   ranks=args.np, seconds_this_call=time.time() - t0,
                   load=os.getloadavg()[0], **{str(k): v for k, v in compare(curves).items()},
                   curves={str(n): {m: {k: c[k] for k in ("v_col", "mean_f_gro", "runs",
                                                         "capped", "v_fra")}
                                    for m, c in by_model.items()}
                           for n, by_model in curves.items()})
    (results / "summary.json").write_text(json.dumps(summary, indent=2, default=float) + "\n")
    figures(curves, results)
    print(json.dumps({k: v for k, v in summary.items() if k not in ("curves", "plan")},
                     indent=1, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
