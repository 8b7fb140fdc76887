"""Where does the head-on collisions' turn from shattering to sticking with size come from?

Issue 46, item 5. Undamped frictionless collisions at 39.8 m/s on the paper's offsets give
f_gro about -0.96 head-on at 2 x 1000, about 0 at 2 x 5000 and +0.69 at 2 x 50000, and the
offsets next to head-on turn with it (B_off^2 1/12: -0.47 at 2 x 5000, +0.81 at 2 x 50000);
the offsets from 4/12 on hardly move (``validation/paper_protocol``). So the candidates are
tested where the turn is: B_off^2 = 0 ... 3/12, one at a time, each against the same scenes
(seeds) run the way the paper-size runs were (``base``: dt by ``--dt auto`` for max |dE| /
E_imp <= 1e-3, bonds at the JKR equilibrium delta_0, a gap of delta_c / 2, the settle rule):

  dt 0.014    the papers' time step instead of --dt auto (about 0.027 t_c at 2 x 1000)
  touching    the aggregates' bonds just inside contact instead of at delta_0: each pulls
              with about 0.9 F_c, so the aggregates start with internal energy, as they would
              if built touching and never relaxed
  gap 1 um    the aggregates start 10 grain radii apart instead of delta_c / 2

and, from the base runs' own settle checks, the end of the run: f_gro at the paper's
snapshot times (0.4 ... 1.6 us) against the settle rule's end.

The measure is f_near: f_gro averaged over B_off^2 = 0, 1/12, 2/12, 3/12 with the paper's
eq. (1) weights on its grid (1/2, 1, 1, 1), per seed; its part of <f_gro> is 3.5/12 of it.
Collisions are chaotic, so each candidate is compared with base as ensembles (mean and
standard error over seeds; ``common.within_scatter``), never run against run. The size
trend itself is read from the same offsets of ``validation/paper_protocol``'s records
(2 x 5000 seeds 1, 2; 2 x 50000 seed 1).

Writes RESULTS (default validation/size_trend/): runs.csv, summary.json, fig_size_trend.png
and records/ (every run's small record).

    ./run validate size_trend               # 4 arms x 4 offsets x 4 seeds at 2 x 1000
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
from jkrdt.analysis.tables import write_csv
from jkrdt.stopping import COMPLETE
from paper_protocol import SNAPSHOTS_US, f_gro_at
from vfra_size import TOLERANCE

MODEL = "frictionless"
FULL = dict(n=1000, v_col=39.8, b_off2=[0.0, 1 / 12, 2 / 12, 3 / 12], seeds=[1, 2, 3, 4])
QUICK = dict(n=24, v_col=39.8, b_off2=[0.0, 1 / 12], seeds=[1, 2])
#: the paper's eq. (1) weights of these offsets on its grid (trapezoid, B_off^2 = k/12)
WEIGHT = {0: 0.5, 1: 1.0, 2: 1.0, 3: 1.0}
AUTO = dict(dt="auto", tolerance=TOLERANCE)
ARMS = {"base": AUTO, "dt 0.014": dict(dt=0.014), "touching": dict(AUTO, bond="touching"),
        "gap 1 um": dict(AUTO, gap=1.0e-6)}
#: where the paper-size and 2 x 5000 runs of the same protocol keep their records
PROTOCOL_RECORDS = HERE / "paper_protocol" / "records"


def twelfth(b2: float) -> int:
    return int(round(b2 * 12))


def f_near(by_offset: dict[int, float]) -> float:
    """f_gro over B_off^2 <= 3/12 with the paper's grid weights (NaN if an offset is missing)."""
    ks = [k for k in WEIGHT if k in by_offset]
    if len(ks) < len(by_offset) or not ks:
        return float("nan")
    return sum(WEIGHT[k] * by_offset[k] for k in ks) / sum(WEIGHT[k] for k in ks)


def load(records: Path) -> list[dict]:
    """One row per finished run below ``records`` (arm = its campaign's folder)."""
    rows = []
    for path in sorted(records.rglob(rundir.OUTCOME)):
        o = json.loads(path.read_text())
        if o.get("stop_reason") not in COMPLETE:
            continue
        meta = json.loads((path.parent / rundir.META).read_text())
        at = f_gro_at(path.parent, o["N_tar"], o["N_pro"])
        rows.append(dict(arm=path.relative_to(records).parts[0], N_tar=o["N_tar"],
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


def size_rows(records: Path) -> dict:
    """f_near of the paper-protocol question b (39.8 m/s, frictionless) per size."""
    out = {}
    if not records.exists():
        return out
    for n in (5000, 50000):
        rows = []
        for k in WEIGHT:
            for path in records.glob(f"n{n}_b_b2_{k / 12:.4f}/v39.8/*/seed*/{rundir.OUTCOME}"):
                o = json.loads(path.read_text())
                rows.append(dict(b2_twelfths=k, seed=o["seed"], f_gro=o["growth_efficiency"]))
        if rows:
            offsets = {r["b2_twelfths"] for r in rows}
            by_offset = {k: float(np.mean([r["f_gro"] for r in rows if r["b2_twelfths"] == k]))
                         for k in sorted(offsets)}
            out[n] = dict(per_offset={f"{k}/12": v for k, v in by_offset.items()},
                          f_near=f_near(by_offset) if offsets == set(WEIGHT) else None,
                          seeds=sorted({r["seed"] for r in rows}))
    return out


def figure(summary: dict, results: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    arms = list(summary["arms"])
    for i, name in enumerate(arms):
        s = summary["arms"][name]
        ks = [int(k.split("/")[0]) for k in s["per_offset"]]
        m = [v[0] for v in s["per_offset"].values()]
        e = [v[1] if np.isfinite(v[1]) else 0 for v in s["per_offset"].values()]
        a.errorbar(np.array(ks) + 0.06 * (i - 1.5), m, yerr=e, marker="o", capsize=3,
                   label=f"2 x {summary['plan']['n']}: {name}")
    for n, s in summary["sizes"].items():
        ks = [int(k.split("/")[0]) for k in s["per_offset"]]
        a.plot(ks, list(s["per_offset"].values()), "k--" if n == "5000" else "k-",
               marker="s", label=f"2 x {n}: paper protocol, seeds {s['seeds']}")
    a.axhline(0, color="0.6", lw=0.8)
    a.set_xlabel("B_off^2 (twelfths)")
    a.set_ylabel("f_gro")
    a.set_title(f"frictionless, undamped, {summary['plan']['v_col']} m/s")
    a.legend(fontsize=7)
    names = arms + [f"base at {t:g} us" for t in SNAPSHOTS_US]
    vals = [summary["arms"][n]["f_near"] for n in arms] + \
           [summary["end_of_run"][f"{t:g}"]["f_near"] for t in SNAPSHOTS_US]
    y = np.arange(len(names))
    b.errorbar([v[0] for v in vals], y, xerr=[v[1] if np.isfinite(v[1]) else 0 for v in vals],
               fmt="o", capsize=3)
    b.set_yticks(y, names)
    b.axvline(summary["arms"]["base"]["f_near"][0], color="0.6", lw=0.8)
    b.set_xlabel("f_near: f_gro over B_off^2 <= 3/12 (eq. 1 weights), mean +- se over seeds")
    b.set_title(f"candidates at 2 x {summary['plan']['n']}, against base")
    fig.tight_layout()
    return save(fig, results, "fig_size_trend")


def summarise(records: Path, results: Path, plot: bool = True) -> dict:
    rows = load(records)
    write_csv(results / "runs.csv", rows)
    arms = {name: arm_summary([r for r in rows if r["arm"] == folder])
            for name, folder in ARM_FOLDERS.items()
            if any(r["arm"] == folder for r in rows)}
    base_rows = [r for r in rows if r["arm"] == ARM_FOLDERS["base"]]
    end = {f"{t:g}": arm_summary(base_rows, f"f_gro_at_{t:g}_us") for t in SNAPSHOTS_US}
    compared = {}
    if "base" in arms:
        for name, s in list(arms.items()) + [(f"base at {k} us", v) for k, v in end.items()]:
            if name == "base" or s["seeds"] < 2:
                continue
            d, se, agree = within_scatter(tuple(arms["base"]["f_near"]), tuple(s["f_near"]))
            compared[name] = dict(difference=d, se=se, agree=agree,
                                  mean_f_gro_difference=d * 3.5 / 12)
    summary = dict(plan=PLAN, arms_spec=ARMS, weights=WEIGHT, results=compared, arms=arms,
                   end_of_run=end, sizes={str(n): v for n, v in size_rows(PROTOCOL_RECORDS
                                                                           ).items()},
                   runs_finished=len(rows))
    if plot and "base" in arms:
        figure(summary, results)
    return summary


PLAN = FULL
ARM_FOLDERS = {name: name.replace(" ", "_") for name in ARMS}


def main(argv=None) -> int:
    global PLAN
    p = campaign_study_parser(__doc__)
    p.add_argument("--arms", nargs="+", default=list(ARMS), choices=list(ARMS),
                   help="run only these arms (default: all, base first)")
    p.add_argument("--summary-only", action="store_true",
                   help="only remake the results from the records kept")
    args = p.parse_args(argv)
    PLAN = QUICK if args.quick else FULL
    runs, results = study_paths(args, "size_trend")
    if not args.summary_only:
        specs = {ARM_FOLDERS[name]: model_spec(MODEL, PLAN["n"], v_col=[PLAN["v_col"]],
                                               b_off2=PLAN["b_off2"], seeds=PLAN["seeds"],
                                               **ARMS[name])
                 for name in args.arms}
        run_campaigns(specs, runs, args.np)
    return write_summary(results, summarise(results / "records", results))


if __name__ == "__main__":
    sys.exit(main())
