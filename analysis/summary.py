"""Campaign statistics over runs analysed by ``analysis.run`` (one outcome.json each).

    <A> = int_0^1 dB_off 2 B_off A = int_0^1 A d(B_off^2)      (3D BPCA paper, eq. 1)

is integrated with the trapezoid rule over the grid of B_off^2 values the campaign ran
(the paper's grid is 0, 1/12, ..., 1, on which the rule is exact for A linear in
B_off^2); A is held at its end values outside the grid. v_fra is where <f_gro>
crosses 0, interpolated linearly in log v_col between the grid velocities.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import numpy as np

from jkrdt import rundir
from jkrdt.rundir import write_json
from jkrdt.stopping import COMPLETE

from . import plots
from .tables import write_csv

SCALARS = ["model", "material", "xi_crit", "tvis", "kind", "dimension", "N_tar", "N_pro",
           "v_col", "B_off", "seed", "radius", "E_imp", "n_k", "E_imp_over_nk_Eroll",
           "E_imp_over_nk_Ebreak", "step", "n_total", "n_largest", "n_second", "n_fragments",
           "growth_efficiency", "gyration_radius_largest", "contacts_per_particle",
           "dissipated_fraction", "energy_error", "energy_warning", "stop_reason", "stop_step",
           "kinetic_left", "problem", "run"]


def b_off_average(b_off2, values) -> np.ndarray:
    """<A> of eq. (1) from values of A (along axis 0) at the given B_off^2."""
    b2 = np.asarray(b_off2, dtype=float)
    a = np.asarray(values, dtype=float)
    if b2.ndim != 1 or len(b2) != len(a) or len(b2) == 0:
        raise ValueError("one value of A per B_off^2 is needed")
    if b2.min() < 0 or b2.max() > 1:
        raise ValueError("B_off^2 must lie in [0, 1]")
    if len(np.unique(b2)) != len(b2):
        raise ValueError("repeated B_off^2 values: average the runs of one B_off^2 first")
    order = np.argsort(b2)
    b2, a = b2[order], a[order]
    grid = np.concatenate([[0.0], b2, [1.0]])
    a = np.concatenate([a[:1], a, a[-1:]])
    widths = np.diff(grid).reshape(-1, *([1] * (a.ndim - 1)))
    return (0.5 * widths * (a[1:] + a[:-1])).sum(axis=0)


def b_off_groups(runs, value) -> tuple[np.ndarray, np.ndarray]:
    """The B_off^2 values of ``runs`` (ascending) and value(run) averaged over the runs
    (seeds) of each."""
    by_b2 = defaultdict(list)
    for o in runs:
        by_b2[round(o["B_off"] ** 2, 12)].append(value(o))
    b2 = np.array(sorted(by_b2))
    return b2, np.array([np.mean(by_b2[b], axis=0) for b in b2])


def b_off_mean(runs, value) -> np.ndarray:
    """<A> of eq. (1) over ``runs`` (outcomes at one v_col): A = value(run) averaged over
    the runs (seeds) of each B_off^2 first (``b_off_groups``), then over B_off^2 by
    ``b_off_average``."""
    return b_off_average(*b_off_groups(runs, value))


def threshold_velocity(v_col, mean_f_gro) -> float | None:
    """The first v_col at which <f_gro> falls from > 0 to <= 0 (log-linear interpolation)."""
    v = np.asarray(v_col, dtype=float)
    f = np.asarray(mean_f_gro, dtype=float)
    order = np.argsort(v)
    v, f = v[order], f[order]
    for k in range(len(v) - 1):
        if f[k] > 0 >= f[k + 1]:
            w = f[k] / (f[k] - f[k + 1])
            return float(np.exp(np.log(v[k]) + w * (np.log(v[k + 1]) - np.log(v[k]))))
    return None


def cumulative_on(n_grid: np.ndarray, sizes, n_cum) -> np.ndarray:
    """N_cum(<= N) of one run on ``n_grid`` (a step function of N)."""
    sizes = np.asarray(sizes)
    n_cum = np.asarray(n_cum)
    at = np.searchsorted(sizes, n_grid, side="right") - 1
    return np.where(at >= 0, n_cum[np.maximum(at, 0)], 0.0)


def label(run: dict) -> str:
    tvis = run.get("tvis") or 0.0
    return f"{run.get('material')} {run.get('model')}, T_vis = {tvis * 1e12:g} ps"


def load_outcomes(campaign) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted(Path(campaign).rglob(rundir.OUTCOME))]


def summarise(campaign, plot: bool = True, include_cap: bool = False) -> dict:
    """Collect every run under ``campaign`` into runs.csv, and write summary.csv (one row
    per model and v_col: <f_gro>, <N_lar/N_total>, ...), summary.json (with v_fra) and
    the campaign plots.

    Only complete runs (settled, or of a fixed number of steps) enter the averages; runs
    that hit the settle cap enter with ``include_cap``, failed runs never. Each row of
    the table counts the runs left out, and summary.json lists them."""
    campaign = Path(campaign)
    every = load_outcomes(campaign)
    if not every:
        raise ValueError(f"{campaign}: no outcome.json below it; run 'jkrdt analyse' on its runs")
    rows = [{k: o.get(k, "steps" if k == "stop_reason" else None) for k in SCALARS}
            for o in every]
    write_csv(campaign / "runs.csv", rows)
    allowed = set(COMPLETE) | ({"cap"} if include_cap else set())
    outcomes, left_out = [], []
    capped, dropped = defaultdict(int), defaultdict(int)
    for o in every:
        reason, key = o.get("stop_reason", "steps"), (label(o), o["v_col"])
        capped[key] += reason == "cap"
        if reason in allowed:
            outcomes.append(o)
        else:
            dropped[key] += 1
            left_out.append(dict(run=o["run"], stop_reason=o.get("stop_reason"),
                                 problem=o.get("problem")))
    if not outcomes:
        raise ValueError(f"{campaign}: none of its {len(every)} runs is complete "
                         f"({sorted({d['stop_reason'] for d in left_out})}); see runs.csv")
    rows = [{k: o.get(k) for k in SCALARS} for o in outcomes]

    groups = defaultdict(list)
    for o in outcomes:
        groups[(label(o), o["v_col"])].append(o)
    table, curves, cumulative = [], defaultdict(lambda: ([], [])), {}
    counts = defaultdict(list)
    for (name, v), runs in sorted(groups.items()):
        n_grid = np.arange(1, runs[0]["n_total"] + 1)
        mean_f = float(b_off_mean(runs, lambda o: o["growth_efficiency"]))
        table.append(dict(model=name, v_col=v, runs=len(runs), left_out=dropped[(name, v)],
                          capped=capped[(name, v)],
                          B_off2_values=len({round(o["B_off"] ** 2, 12) for o in runs}),
                          mean_f_gro=mean_f,
                          mean_N_lar_over_N_total=float(b_off_mean(
                              runs, lambda o: o["n_largest"] / o["n_total"])),
                          E_imp_over_nk_Ebreak=runs[0]["E_imp_over_nk_Ebreak"]))
        curves[name][0].append(v)
        curves[name][1].append(mean_f)
        counts[name].append(len(runs))
        cumulative[f"{name}, {v:g} m/s"] = (n_grid, b_off_mean(
            runs, lambda o: cumulative_on(n_grid, o["fragment_sizes"], o["N_cum"])))
    thresholds = {name: threshold_velocity(v, f) for name, (v, f) in curves.items()}
    write_csv(campaign / "summary.csv", table)
    summary = dict(runs=len(outcomes), left_out=left_out, include_cap=include_cap, table=table,
                   v_fra=thresholds)
    if plot:
        pictures = plots.growth_efficiency(campaign / "growth_efficiency", dict(curves), thresholds,
                                          dict(counts))
        pictures += plots.cumulative(campaign / "cumulative", cumulative)
        pictures += plots.disruption(campaign / "disruption", rows)
        if all(r["E_imp_over_nk_Eroll"] for r in rows):
            pictures += plots.compression(campaign / "compression", rows)
        summary["pictures"] = [str(p) for p in pictures]
    write_json(campaign / "summary.json", summary)
    return summary
