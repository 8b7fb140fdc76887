"""Departure (fix jkr/dt/settle depart yes) against runs that keep every fragment flying.

Two equal ice BPCAs collide head-on at 20, 39.8 and 100 m/s under the frictional and the
frictionless model, 8 seeds each, twice: with departures, and with every fragment kept
moving (``depart shadow``: every fragment flies on as before departures, and the log names
when the rule would have let each fragment go). Collisions are chaotic, so the two are
compared as ensembles: for each model and speed, the seeds' mean and standard error of
f_gro, N_lar / N and N_cum(<= 1, 4, 16) / N, and whether the two means lie within two
combined standard errors. The shadow runs also measure how often the rule would have been
wrong: a fragment the rule let go that was not the same fragment (same smallest atom ID,
same size) at the end of the run, having merged or broken up since.

Writes ``RESULTS`` (default validation/departure/): runs.csv and summary.json. Runs go to
``--runs`` (default validation/runs/departure, not committed); a second call resumes them.
``--models`` runs some models only; the rows of a model not run whose runs directory is
absent (another machine ran it) are carried over from the committed runs.csv.

    ./run validate departure                  # 2 x 1000, 8 seeds (96 runs)
    ./run validate departure --quick          # 2 x 50, 1 speed, 4 seeds (tests)
    ./run validate departure --summarise      # the runs finished so far, running nothing
    ./run validate departure --models frictionless   # one model; the other's rows kept
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
from pathlib import Path

import numpy as np

from common import (campaign_paths, loop_seconds, mean_se, read_committed, run_campaigns,
                    within_scatter)
from jkrdt.analysis import dumps, fragments
from jkrdt.analysis.tables import write_csv
from jkrdt import rundir
from jkrdt.rundir import CONTACTS, LOG, META

HERE = Path(__file__).resolve().parent
FULL = dict(n=1000, seeds=list(range(1, 9)), v_col=[20.0, 39.8, 100.0],
            models=["frictional", "frictionless"])
QUICK = dict(n=50, seeds=[1, 2, 3, 4], v_col=[39.8], models=["frictionless"])
VARIANTS = ("yes", "shadow")
SMALL = (1, 4, 16)
WOULD = re.compile(r"would depart step (\d+) label (\d+) size (\d+)")


def spec(model: str, depart: str, plan: dict) -> dict:
    return dict(kind="bpca", dim=3, n_tar=plan["n"], n_pro=plan["n"], material="ice",
                model=model, v_col=plan["v_col"], b_off2=[0.0], seeds=plan["seeds"],
                dt=0.014, settle=dict(depart=depart))


def wrong_departures(run: Path) -> tuple[int, int]:
    """(fragments the rule would have let go, of them not whole at the end) of a shadow run."""
    would = [tuple(map(int, m.groups())) for m in WOULD.finditer((run / LOG).read_text())]
    meta = json.loads((run / META).read_text())
    ids = np.arange(1, meta["N_tar"] + meta["N_pro"] + 1)
    pairs = dumps.last_local_snapshot(run / CONTACTS)[:, :2].astype(np.int64)
    labels = fragments.from_contacts(ids, pairs)
    sizes = np.bincount(labels)
    smallest = np.full(labels.max() + 1, ids.max() + 1)
    np.minimum.at(smallest, labels, ids)
    wrong = sum(1 for _, label, size in would
                if smallest[labels[label - 1]] != label or sizes[labels[label - 1]] != size)
    return len(would), wrong


def rows_of(where: Path, model: str, depart: str) -> list[dict]:
    rows = []
    for path in sorted(where.rglob(rundir.OUTCOME)):
        o = json.loads(path.read_text())
        if o.get("stop_reason") not in ("settled", "steps"):
            continue
        n = o["n_total"]
        sizes = np.asarray(o["fragment_sizes"])
        row = dict(model=model, depart=depart, v_col=o["v_col"], seed=o["seed"],
                   f_gro=o["growth_efficiency"], N_lar_over_N=o["n_largest"] / n,
                   **{f"N_cum_le_{k}_over_N": float(sizes[sizes <= k].sum()) / n for k in SMALL},
                   fragments=o["n_fragments"], stop_step=o["stop_step"],
                   energy_error=o["energy_error"], loop_seconds=loop_seconds(path.parent))
        if depart == "shadow":
            row["would_depart"], row["wrong"] = wrong_departures(path.parent)
        rows.append(row)
    return rows


COUNTS = ("seed", "fragments", "stop_step", "would_depart", "wrong")
MEASURES = ["f_gro", "N_lar_over_N"] + [f"N_cum_le_{k}_over_N" for k in SMALL]


def compare(rows: list[dict]) -> dict:
    """Per model and speed: each measure's mean and standard error with and without
    departures, and whether they agree within two combined standard errors."""
    out = {}
    for model in sorted({r["model"] for r in rows}):
        for v in sorted({r["v_col"] for r in rows}):
            key = f"{model} {v:g} m/s"
            pick = {d: [r for r in rows if r["model"] == model and r["v_col"] == v
                        and r["depart"] == d] for d in VARIANTS}
            if not all(pick.values()):
                continue
            entry = dict(runs={d: len(pick[d]) for d in VARIANTS})
            for m in MEASURES:
                at = {d: mean_se([r[m] for r in pick[d]]) for d in VARIANTS}
                stats = {d: dict(mean=mean, se=se) for d, (mean, se) in at.items()}
                stats["agree"] = within_scatter(at["yes"], at["shadow"])[2]
                entry[m] = stats
            entry["loop_seconds"] = {d: float(np.mean([r["loop_seconds"] for r in pick[d]]))
                                     for d in VARIANTS}
            out[key] = entry
    shadow = [r for r in rows if r["depart"] == "shadow"]
    out["rule"] = dict(would_depart=int(sum(r["would_depart"] for r in shadow)),
                       wrong=int(sum(r["wrong"] for r in shadow)), runs=len(shadow))
    out["energy_error_max"] = {d: max((r["energy_error"] for r in rows if r["depart"] == d),
                                      default=None) for d in VARIANTS}
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="2 x 50 grains, 4 seeds (tests)")
    ap.add_argument("--ranks", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--runs", type=Path, default=HERE / "runs" / "departure")
    ap.add_argument("--results", type=Path, default=HERE / "departure")
    ap.add_argument("--summarise", action="store_true",
                    help="summarise the runs finished so far, run nothing (a study in progress)")
    ap.add_argument("--models", nargs="+", choices=FULL["models"],
                    help="run these models only (default: all of the plan's)")
    args = ap.parse_args(argv)
    plan = dict(QUICK if args.quick else FULL)
    run_models = [m for m in plan["models"] if not args.models or m in args.models]
    specs = {f"{m} depart {d}": spec(m, d, plan) for m in plan["models"] for d in VARIANTS}
    where = campaign_paths(specs, args.runs)
    if not args.summarise:
        run_campaigns({k: v for k, v in specs.items() if k.split()[0] in run_models},
                      args.runs, args.ranks)
    carried = read_committed(args.results, COUNTS)
    rows = []
    for name, path in where.items():
        model, _, depart = name.split()
        if path.exists():
            rows += rows_of(path, model, depart)
        elif model not in run_models:
            rows += [r for r in carried if r["model"] == model and r["depart"] == depart]
    planned = len(specs) * len(plan["v_col"]) * len(plan["seeds"])
    summary = dict(plan=plan, runs_planned=planned, runs_finished=len(rows),
                   comparison=compare(rows))
    args.results.mkdir(parents=True, exist_ok=True)
    write_csv(args.results / "runs.csv", rows)
    (args.results / "summary.json").write_text(json.dumps(summary, indent=1))
    print(json.dumps(summary["comparison"], indent=1))
    return summary


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    main()
