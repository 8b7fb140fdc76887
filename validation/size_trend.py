"""Where does the head-on collisions' turn from shattering to sticking with size come from?

Issue 46, item 5. Undamped frictionless collisions at 39.8 m/s on the paper's offsets give
f_gro about -0.96 head-on at 2 x 1000, about 0 at 2 x 5000 and +0.69 at 2 x 50000, and the
offsets next to head-on seemed to turn with it (B_off^2 1/12: -0.47 at 2 x 5000, +0.81 at
2 x 50000 where the settle rule ended it, -0.27 read at the fixed end, ``readings``); the
offsets from 4/12 on hardly move (``validation/paper_protocol``). So the candidates are
tested where the turn is: B_off^2 = 0 ... 3/12, one at a time, each against the same scenes
(seeds) run the way the paper-size runs were (``base``: dt by ``--dt auto`` for max |dE| /
E_imp <= 1e-3, bonds at the JKR equilibrium delta_0, a gap of delta_c / 2, the settle rule):

  dt 0.014    the papers' time step instead of --dt auto (about 0.027 t_c at 2 x 1000)
  touching    the aggregates' bonds just inside contact instead of at delta_0: each pulls
              with about 0.9 F_c, so the aggregates start with internal energy, as they would
              if built touching and never relaxed
  gap 1 um    the aggregates start 10 grain radii apart instead of delta_c / 2

and the undamped frictional model at 63.1 m/s at base and dt 0.014 only: its v_fra rose
from 54 m/s at N_tot 2000 (``bpca3d_models``, dt 0.014 t_c) to 82 at 10^4 (``vfra_size``,
--dt auto), a change of size and of time step at once, and its near-head-on collisions
turn as the frictionless ones do (63.1 m/s head-on: +0.53 at 2 x 1000, +0.8 at 2 x 5000);

and, from the base runs' own settle checks, the end of the run: f_gro at the paper's
snapshot times (0.4 ... 1.6 us) against the settle rule's end.

The measure is f_near: f_gro averaged over B_off^2 = 0, 1/12, 2/12, 3/12 with the paper's
eq. (1) weights on its grid (1/2, 1, 1, 1), per seed; its part of <f_gro> is 3.5/12 of it.
Collisions are chaotic, so each candidate is compared with base as ensembles (mean and
standard error over seeds; ``common.within_scatter``), never run against run. The size
trend itself is read from the same offsets of ``validation/paper_protocol``'s records
(2 x 5000 seeds 1, 2; 2 x 50000 seed 1), each where its outcome is decided
(``readings.read``, with ``fixed_end``'s continuations).

The dissipation that makes the difference is read from the records of the frictionless
base runs and of the paper protocol's: E_dis(t) / E_imp against time in aggregate crossing
times 2 r_c / v_col, and at the end, with N_con, N_cut and single grains ejected per grain.

Writes RESULTS (default validation/size_trend/): runs.csv, summary.json, fig_size_trend.png,
fig_dissipation_size.png and records/<question>/<arm>/ (every run's small record).

    ./run validate size_trend               # (4 + 2 arms) x 4 offsets x 4 seeds, 2 x 1000
    ./run validate size_trend --summary-only
    ./run validate size_trend --quick       # 2 x 24 grains (tests)
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from bpca3d_models import model_spec
from common import (HERE, campaign_study_parser, mean_se, run_campaigns, save, study_paths,
                    within_scatter, write_summary)
from jkrdt import rundir
from jkrdt.analysis.tables import read_csv, write_csv
from jkrdt.stopping import COMPLETE
from paper_protocol import PAPER_CAP_TC, SNAPSHOTS_US, f_gro_at
from readings import read
from vfra_size import TOLERANCE

FULL = dict(n=1000, b_off2=[0.0, 1 / 12, 2 / 12, 3 / 12], seeds=[1, 2, 3, 4])
QUICK = dict(n=24, b_off2=[0.0, 1 / 12], seeds=[1, 2])
#: the paper's eq. (1) weights of these offsets on its grid (trapezoid, B_off^2 = k/12)
WEIGHT = {0: 0.5, 1: 1.0, 2: 1.0, 3: 1.0}
AUTO = dict(dt="auto", tolerance=TOLERANCE)
ARMS = {"base": AUTO, "dt 0.014": dict(dt=0.014), "touching": dict(AUTO, bond="touching"),
        "gap 1 um": dict(AUTO, gap=1.0e-6)}
#: the models and speeds asked, each with the arms it runs: the frictionless head-on turn
#: (all candidates), and the undamped frictional model near its v_fra, whose size trend
#: (v_fra 54 m/s at N_tot 2000 with dt 0.014 t_c, 82 at 10^4 with --dt auto) crossed a
#: change of the time step
QUESTIONS = {"frictionless 39.8": dict(model="frictionless", v_col=39.8, arms=list(ARMS)),
             "frictional 63.1": dict(model="frictional", v_col=63.1,
                                     arms=["base", "dt 0.014"])}
#: the question whose base runs are read against the paper protocol's at larger sizes
TREND = "frictionless 39.8"
#: where the paper-size and 2 x 5000 runs of the same protocol keep their records, and
#: where their continuations to the fixed end keep theirs (``fixed_end``)
PROTOCOL_RECORDS = HERE / "paper_protocol" / "records"
CONTINUED = HERE / "fixed_end" / "records"


def twelfth(b2: float) -> int:
    return int(round(b2 * 12))


def f_near(by_offset: dict[int, float]) -> float:
    """f_gro averaged over the offsets given (B_off^2 <= 3/12, twelfths) with the paper's
    grid weights; NaN if one lies outside them."""
    ks = [k for k in WEIGHT if k in by_offset]
    if len(ks) < len(by_offset) or not ks:
        return float("nan")
    return sum(WEIGHT[k] * by_offset[k] for k in ks) / sum(WEIGHT[k] for k in ks)


def load(records: Path) -> list[dict]:
    """One row per finished run below ``records`` (RECORDS/<question>/<arm>/...)."""
    rows = []
    for path in sorted(records.rglob(rundir.OUTCOME)):
        o = json.loads(path.read_text())
        if o.get("stop_reason") not in COMPLETE:
            continue
        meta = json.loads((path.parent / rundir.META).read_text())
        at = f_gro_at(path.parent, o["N_tar"], o["N_pro"])
        question, arm = path.relative_to(records).parts[:2]
        rows.append(dict(question=question, arm=arm, N_tar=o["N_tar"],
                         b2_twelfths=twelfth(o["B_off"] ** 2), seed=o["seed"],
                         f_gro=o["growth_efficiency"], dt_over_tc=meta.get("dt_over_tc"),
                         time_end_over_tc=o.get("time_end_over_tc"),
                         energy_error=o.get("energy_error"),
                         **{f"f_gro_at_{t:g}_us": at[f"{t:g}"] for t in SNAPSHOTS_US}))
    return rows


def per_seed(rows: list[dict], key: str = "f_gro") -> dict[int, float]:
    """f_near of each seed whose offsets all ran."""
    seeds = sorted({r["seed"] for r in rows})
    out = {}
    for s in seeds:
        got = {r["b2_twelfths"]: r[key] for r in rows if r["seed"] == s and r[key] is not None}
        if set(got) >= {twelfth(b) for b in PLAN["b_off2"]}:
            out[s] = f_near({k: v for k, v in got.items() if k in WEIGHT})
    return out


def arm_summary(rows: list[dict], key: str = "f_gro") -> dict:
    by_seed = per_seed(rows, key)
    mean, se = mean_se(list(by_seed.values())) if by_seed else (float("nan"), float("nan"))
    per_offset = {}
    for k in sorted({r["b2_twelfths"] for r in rows}):
        values = [r[key] for r in rows if r["b2_twelfths"] == k and r[key] is not None]
        per_offset[f"{k}/12"] = list(mean_se(values)) + [len(values)]
    return dict(f_near=[mean, se], seeds=len(by_seed), per_seed=by_seed, per_offset=per_offset,
                share_of_mean_f_gro=mean * 3.5 / 12)


def size_rows(runs: list[dict]) -> dict:
    """f_near of the paper-protocol question b (39.8 m/s, frictionless) per size, from its
    runs among ``dissipation_runs``, each read where its outcome is decided (``readings``;
    an open offset is listed in ``open`` and leaves f_near unknown), and as the settle rule
    ended them (``per_offset_settle_end``)."""
    out = {}
    for n in sorted({r["N_tar"] for r in runs if r["source"] == "paper_protocol"}):
        rows = [r for r in runs if r["source"] == "paper_protocol" and r["N_tar"] == n]
        offsets = sorted({r["b2_twelfths"] for r in rows})
        mean = lambda key, k: float(np.mean([r[key] for r in rows if r["b2_twelfths"] == k]))  # noqa: E731
        open_ = [k for k in offsets if any(r["f_gro_read"] is None for r in rows
                                            if r["b2_twelfths"] == k)]
        by_offset = {k: mean("f_gro_read", k) for k in offsets if k not in open_}
        out[n] = dict(per_offset={f"{k}/12": v for k, v in by_offset.items()},
                      open=[f"{k}/12" for k in open_],
                      f_near=f_near(by_offset) if set(by_offset) == set(WEIGHT) else None,
                      per_offset_settle_end={f"{k}/12": mean("f_gro", k) for k in offsets},
                      seeds=sorted({r["seed"] for r in rows}))
    return out


def dissipation_runs(records: Path, protocol_records: Path) -> list[dict]:
    """Each base run here and each question-b run of the paper protocol at B_off^2 <= 3/12:
    its size, offset, seed, f_gro, the energy dissipated (/ E_imp), N_con and N_cut per
    grain, single grains ejected per grain, and its aggregates' r_c = sqrt(5/3) r_g (from
    the first frame) with their filling factor N r_1^3 / r_c^3 and crossing time 2 r_c / v."""
    paths = [("size_trend", p) for p in sorted((records / folder(TREND) / folder("base"))
                                               .rglob(rundir.OUTCOME))]
    for k in WEIGHT:
        paths += [("paper_protocol", p) for p in sorted(protocol_records.glob(
            f"n*_b_b2_{k / 12:.4f}/v39.8/*/seed*/{rundir.OUTCOME}"))]
    out = []
    for source, path in paths:
        o = json.loads(path.read_text())
        if o.get("stop_reason") not in COMPLETE or twelfth(o["B_off"] ** 2) not in WEIGHT:
            continue
        reading = read(o, path.parent, CONTINUED / path.parent.relative_to(protocol_records),
                       PAPER_CAP_TC) if source == "paper_protocol" else {}
        frames = read_csv(path.parent / rundir.FRAMES)
        r_c = np.sqrt(5 / 3) * frames[0]["gyration_radius_largest"]
        n = o["n_total"]
        out.append(dict(source=source, N_tar=o["N_tar"], b2_twelfths=twelfth(o["B_off"] ** 2), seed=o["seed"],
                        f_gro=o["growth_efficiency"], E_dis=o["dissipated_fraction"],
                        f_gro_read=reading.get("f_gro"), read_at=reading.get("read_at"),
                        kinetic_left=o["kinetic_left"], N_con=o["N_con"] / n,
                        N_cut=o["N_cut"] / n, singles=o["diagnostics"]["N_cum_1"] / n,
                        r_c_over_r1=r_c / o["radius"],
                        filling=o["N_tar"] * (o["radius"] / r_c) ** 3,
                        t_cross=2 * r_c / o["v_col"],
                        t=[f["time"] for f in frames], E_dis_t=[f["dissipated"] / o["E_imp"]
                                                                 for f in frames]))
    return out


def dissipation_table(runs: list[dict]) -> dict:
    """Per size and offset, the seeds' means of the final measures."""
    table = {}
    for n in sorted({r["N_tar"] for r in runs}):
        for k in sorted(WEIGHT):
            got = [r for r in runs if r["N_tar"] == n and r["b2_twelfths"] == k]
            if got:
                table.setdefault(str(n), {})[f"{k}/12"] = dict(
                    seeds=len(got), **{m: float(np.mean([r[m] for r in got])) for m in (
                        "f_gro", "E_dis", "kinetic_left", "N_con", "N_cut", "singles",
                        "r_c_over_r1", "filling", "t_cross")})
    return table


def dissipation_figure(runs: list[dict], results: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    sizes = sorted({r["N_tar"] for r in runs})
    colour = dict(zip(sizes, ["tab:blue", "tab:orange", "tab:red", "tab:green"]))
    for r in runs:
        if r["b2_twelfths"] in (0, 1):
            a.plot(np.array(r["t"]) / r["t_cross"], r["E_dis_t"], color=colour[r["N_tar"]],
                   ls="-" if r["b2_twelfths"] == 0 else "--", lw=1)
    for n in sizes:
        a.plot([], [], color=colour[n], label=f"2 x {n}")
    a.plot([], [], "k-", label="head-on")
    a.plot([], [], "k--", label="B_off^2 1/12")
    a.set_xlabel("t / (2 r_c / v_col): aggregate crossing times")
    a.set_ylabel("E_dis(t) / E_imp")
    a.set_xlim(0, 8)
    a.legend(fontsize=7)
    a.set_title("energy dissipated, frictionless, undamped, 39.8 m/s")
    for k, marker in zip(sorted(WEIGHT), "osD^"):
        got = [r for r in runs if r["b2_twelfths"] == k]
        x = [r["N_tar"] ** (-1 / 3) for r in got]
        b.plot(x, [r["E_dis"] for r in got], marker, color="tab:red", alpha=0.7,
               label=f"E_dis / E_imp, {k}/12")
        b.plot(x, [r["f_gro"] for r in got], marker, color="tab:blue", mfc="none",
               label=f"f_gro, {k}/12")
    b.axhline(0, color="0.6", lw=0.8)
    b.set_xlabel("N_tar^(-1/3) (surface share of an aggregate; 2 x 50000 at left)")
    b.set_xlim(left=0)
    b.legend(fontsize=6, ncol=2)
    b.set_title("at the end of each run")
    fig.tight_layout()
    return save(fig, results, "fig_dissipation_size")


def figure(summary: dict, results: Path) -> list[Path]:
    """f_gro per offset of the trend's arms and of the larger sizes; every question's
    candidates against its base as f_near with its standard error."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11.5, 5.4))
    n = summary["plan"]["n"]
    trend = summary["asked"][TREND]["arms"]
    for i, (name, s) in enumerate(trend.items()):
        ks = [int(k.split("/")[0]) for k in s["per_offset"]]
        m = [v[0] for v in s["per_offset"].values()]
        e = [v[1] if np.isfinite(v[1]) else 0 for v in s["per_offset"].values()]
        a.errorbar(np.array(ks) + 0.06 * (i - 1.5), m, yerr=e, marker="o", capsize=3,
                   label=f"2 x {n}: {name}")
    for size, s in summary["sizes"].items():
        ks = [int(k.split("/")[0]) for k in s["per_offset"]]
        a.plot(ks, list(s["per_offset"].values()), "k--" if size == "5000" else "k-",
               marker="s", label=f"2 x {size}: paper protocol, seeds {s['seeds']}, read "
                                 "where decided" + (f" ({', '.join(s['open'])} open)"
                                                    if s["open"] else ""))
        moved = [(int(k.split("/")[0]), v) for k, v in s["per_offset_settle_end"].items()
                 if s["per_offset"].get(k) != v]
        if moved:
            a.plot(*zip(*moved), "x", color="0.45", ms=7,
                   label=f"2 x {size}: where the settle rule (shape not watched) ended it")
    a.axhline(0, color="0.6", lw=0.8)
    a.set_xlabel("B_off^2 (twelfths)")
    a.set_ylabel("f_gro")
    a.set_title(f"{TREND} m/s, undamped: f_gro by offset and size")
    a.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    names, vals = [], []
    for q, compared in summary["results"].items():
        for name, c in compared.items():
            names.append(f"{q}: {name}")
            vals.append((c["difference"], c["se"]))
    base = summary["asked"][TREND]["arms"].get("base")
    for size, s in summary["sizes"].items():          # size itself, against the same base
        if s["f_near"] is not None and base:
            names.append(f"{TREND}: 2 x {size} (seeds {s['seeds']})")
            vals.append((s["f_near"] - base["f_near"][0], base["f_near"][1]))
    y = np.arange(len(names))
    colours = ["k" if "2 x" in name else "tab:blue" for name in names]
    for k in range(len(names)):
        b.errorbar(vals[k][0], y[k], xerr=vals[k][1] if np.isfinite(vals[k][1]) else 0,
                   fmt="o", capsize=3, color=colours[k])
    b.set_yticks(y, names, fontsize=7)
    b.axvline(0, color="0.6", lw=0.8)
    b.set_xlabel("f_near (B_off^2 <= 3/12, eq. 1 weights) minus base's, +- se")
    b.set_title(f"candidates against base (2 x {n}); size in black")
    fig.tight_layout()
    return save(fig, results, "fig_size_trend")


def question_summary(rows: list[dict]) -> dict:
    """One question's arms, base's f_near at the snapshot times, and each against base."""
    arms = {name: arm_summary([r for r in rows if r["arm"] == folder(name)])
            for name in ARMS if any(r["arm"] == folder(name) for r in rows)}
    base_rows = [r for r in rows if r["arm"] == folder("base")]
    end = {f"{t:g}": arm_summary(base_rows, f"f_gro_at_{t:g}_us") for t in SNAPSHOTS_US}
    compared = {}
    if "base" in arms:
        for name, s in list(arms.items()) + [(f"base at {k} us", v) for k, v in end.items()]:
            if name == "base" or s["seeds"] < 2:
                continue
            d, se, agree = within_scatter(tuple(arms["base"]["f_near"]), tuple(s["f_near"]))
            compared[name] = dict(difference=d, se=se, agree=agree,
                                  mean_f_gro_difference=d * 3.5 / 12)
    return dict(arms=arms, end_of_run=end, compared=compared)


def summarise(records: Path, results: Path, plot: bool = True) -> dict:
    rows = load(records)
    write_csv(results / "runs.csv", rows)
    asked = {q: question_summary([r for r in rows if r["question"] == folder(q)])
             for q in QUESTIONS if any(r["question"] == folder(q) for r in rows)}
    dissipation = dissipation_runs(records, PROTOCOL_RECORDS)
    summary = dict(plan=PLAN, questions=QUESTIONS, arms_spec=ARMS, weights=WEIGHT,
                   results={q: a["compared"] for q, a in asked.items()}, asked=asked,
                   dissipation_by_size=dissipation_table(dissipation),
                   sizes={str(n): v for n, v in size_rows(dissipation).items()},
                   runs_finished=len(rows))
    if plot and "base" in asked.get(TREND, {}).get("arms", {}):
        figure(summary, results)
        dissipation_figure(dissipation, results)
    return summary


PLAN = FULL


def folder(name: str) -> str:
    """The folder of a question or an arm ("dt 0.014" -> dt_0.014)."""
    return name.replace(" ", "_")


def main(argv=None) -> int:
    global PLAN
    p = campaign_study_parser(__doc__)
    p.add_argument("--questions", nargs="+", default=list(QUESTIONS), choices=list(QUESTIONS),
                   help="run only these (default: all, in this order)")
    p.add_argument("--summary-only", action="store_true",
                   help="only remake the results from the records kept")
    args = p.parse_args(argv)
    PLAN = QUICK if args.quick else FULL
    runs, results = study_paths(args, "size_trend")
    if not args.summary_only:
        for q in args.questions:
            asked = QUESTIONS[q]
            specs = {folder(arm): model_spec(asked["model"], PLAN["n"], v_col=[asked["v_col"]],
                                             b_off2=PLAN["b_off2"], seeds=PLAN["seeds"],
                                             **ARMS[arm])
                     for arm in asked["arms"]}
            run_campaigns(specs, runs / folder(q), args.np)
    return write_summary(results, summarise(results / "records", results))


if __name__ == "__main__":
    sys.exit(main())
